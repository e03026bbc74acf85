#!/usr/bin/env python3
"""Velvet: three spheres of a dark red Principled BSDF with Sheen Weight 1, Sheen Tint white and
Sheen Roughness 0.3, 0.5 and 0.8, lit by a sun from the side, at a grazing angle to much of each sphere,
through Blender's glTF exporter (which writes `KHR_materials_sheen`) against Cycles
(BENCHMARKS.md, session 50).

Cycles' sheen is a different model (Zeltner et al.'s microfibres, fitted by linearly transformed
cosines); glTF's, which alhazen renders, is Estevez and Kulla's "Charlie" sheen, whose rims are
brighter where the fibres are smooth: the two are compared, not expected to agree.

    python3 bench/blender/sheen_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/sheen.glb and OUT_DIR/sheen-cycles.exr (96 × 32, CPU, 2 threads, box filter of
one pixel, four bounces). Needs `pip install bpy`.
"""
import os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import front_camera, main_of, material, sun  # noqa: E402


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for k, rough in enumerate([0.3, 0.5, 0.8]):
        m = material(f"velvet {rough}", (0.25, 0.02, 0.03), 0.0, 0.8)
        p = m.node_tree.nodes["Principled BSDF"]
        p.inputs["Sheen Weight"].default_value = 1.0
        p.inputs["Sheen Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
        p.inputs["Sheen Roughness"].default_value = rough
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, segments=48, ring_count=24, location=(k - 1.0, 0.0, 0.0))
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(m)
    front_camera(scene, 40)
    sun((70, 0, 40), energy=4.0)
    return scene


if __name__ == "__main__":
    main_of("sheen", build, size=(96, 32))
