#!/usr/bin/env python3
"""Posed meshes: a red cylinder skinned to a two-bone armature whose upper bone is bent 50°
sideways, and a blue cube whose shape key ("tall": the top raised by 0.8) is at 0.7, on a grey
floor under a sun, through Blender's glTF exporter (the pose as the joints' rest:
`export_rest_position_armature=False`; the shape key as a morph target with its weight) against
Cycles, for the test `blender_posed_meshes_agree_with_cycles` (crates/alhazen-import/tests/gltf.rs).

    python3 bench/blender/pose_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/posed.glb and OUT_DIR/posed-cycles.exr (96 × 64, CPU, 2 threads, box filter of
one pixel, four bounces). Needs `pip install bpy`.
"""
import math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import floor_under_sun, main_of, material  # noqa: E402


def bent_cylinder():
    """A cylinder from z = 0 to 2 skinned (automatic weights) to two bones, the upper bent."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=0.25, depth=2.0, location=(0, 0, 1.0))
    cylinder = bpy.context.object
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.subdivide(number_cuts=8)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.object.shade_smooth()
    cylinder.data.materials.append(material("red", (0.8, 0.1, 0.05), 0.0, 0.5))
    bpy.ops.object.armature_add(enter_editmode=True, location=(0, 0, 0))
    armature = bpy.context.object
    lower = armature.data.edit_bones[0]
    lower.head, lower.tail = (0, 0, 0), (0, 0, 1)
    upper = armature.data.edit_bones.new("upper")
    upper.head, upper.tail, upper.parent, upper.use_connect = (0, 0, 1), (0, 0, 2), lower, True
    bpy.ops.object.mode_set(mode="OBJECT")
    cylinder.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    bone = armature.pose.bones["upper"]
    bone.rotation_mode = "XYZ"
    bone.rotation_euler = (0, 0, math.radians(50))


def tall_cube():
    """A cube whose shape key raises its top by 0.8, at 0.7."""
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(1.2, 0, 0.3))
    cube = bpy.context.object
    cube.data.materials.append(material("blue", (0.05, 0.2, 0.8), 0.0, 0.5))
    cube.shape_key_add(name="Basis")
    tall = cube.shape_key_add(name="tall")
    for v in tall.data:
        if v.co.z > 0:
            v.co.z += 0.8
    tall.value = 0.7


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bent_cylinder()
    tall_cube()
    floor_under_sun(scene, (0.5, -6, 1.5), 85, 40)
    return scene


if __name__ == "__main__":
    main_of("posed", build, export_rest_position_armature=False)
