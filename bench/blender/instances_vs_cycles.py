#!/usr/bin/env python3
"""GPU instances: seven linked copies of one cone (moved, turned and scaled apart) under an
empty, on a grey floor under a sun, through Blender's glTF exporter with its GPU Instances
option (which writes them as one node with `EXT_mesh_gpu_instancing`) against Cycles, for the
test `blender_gpu_instances_agree_with_cycles` (crates/alhazen-import/tests/gltf.rs).

    python3 bench/blender/instances_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/instances.glb and OUT_DIR/instances-cycles.exr (96 × 64, CPU, 2 threads, box
filter of one pixel, four bounces). Needs `pip install bpy`.
"""
import math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import floor_under_sun, main_of, material  # noqa: E402


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.object.empty_add(location=(0, 0, 0))
    grove = bpy.context.object
    bpy.ops.mesh.primitive_cone_add(vertices=12, radius1=0.3, depth=1.0, location=(0, 0, 0.5))
    cone = bpy.context.object
    cone.data.materials.append(material("green", (0.1, 0.5, 0.15), 0.0, 0.6))
    cone.parent = grove
    for k in range(1, 7):
        copy = cone.copy()  # a linked duplicate: the same mesh data
        scene.collection.objects.link(copy)
        copy.location = (-1.8 + 0.6 * k, 0.5 * (k % 3), 0.5 * (0.6 + 0.15 * k))
        copy.rotation_euler = (math.radians(10 * (k % 2)), 0, math.radians(25 * k))
        copy.scale = (0.6 + 0.15 * k,) * 3
        copy.parent = grove
    floor_under_sun(scene, (0, -6, 2.0), 78, 45)
    return scene


if __name__ == "__main__":
    main_of("instances", build, export_gpu_instances=True)
