#!/usr/bin/env python3
"""Rough metals as Blender renders them: the Principled BSDF's default Multiscatter GGX gives back
the light that meets several facets, which single-scattering microfacets (pbrt's, Mitsuba's,
alhazen's before session 48) lose — up to half of it on the roughest. Three gold spheres of
roughness 0.3, 0.6 and 0.9 under a uniform white world, through Blender's glTF exporter, against
Cycles, for the test `blender_rough_metals_agree_with_cycles` (crates/alhazen-import/tests/gltf.rs).

    python3 bench/blender/multiscatter_vs_cycles.py OUT_DIR [--spp 1024] [--single]

Writes OUT_DIR/rough-metals.glb and OUT_DIR/rough-metals-cycles.exr (96 × 32, CPU, 2 threads,
box filter of one pixel, eight bounces); `--single` renders Cycles' single-scattering GGX
instead (rough-metals-single-cycles.exr), which alhazen's metals without the lobe of several
facets match. The .glb has no world: alhazen lights a glTF without lights by a uniform white
sky, the world given to Cycles here. Needs `pip install bpy`.
"""
import argparse, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, material, white_world  # noqa: E402


def build(distribution):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for k, rough in enumerate([0.3, 0.6, 0.9]):
        m = material(f"gold {rough}", (1.0, 0.78, 0.34), 1.0, rough)
        m.node_tree.nodes["Principled BSDF"].distribution = distribution
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, segments=48, ring_count=24, location=(k - 1.0, 0.0, 0.0))
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(m)
    front_camera(scene, 40)
    white_world(scene)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--single", action="store_true")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build("GGX" if a.single else "MULTI_GGX")
    stem = "rough-metals-single" if a.single else "rough-metals"
    export_and_render(scene, out, stem, (96, 32), a.spp, bounces=8, glb=not a.single)


if __name__ == "__main__":
    main()
