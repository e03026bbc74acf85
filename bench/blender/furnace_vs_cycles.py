#!/usr/bin/env python3
"""A white furnace through Blender's glTF exporter, against Cycles: a sphere of a pale Principled
dielectric (base colour `--base`, roughness `--roughness`, no metal) alone under a uniform white
world of strength 1, seen whole, for the test `blender_furnace_agrees_with_cycles`
(crates/alhazen-import/tests/gltf.rs).

A base colour of 1 under a white sky reflects at most what it receives: a layering that
conserves energy shows the sphere no brighter than the sky at any angle. Cycles' Principled
BSDF weighs its diffuse base by what the specular layer leaves at the viewing angle (`1 − E(μo)`,
albedo scaling); a constant weight `1 − F(0)` sends back more than arrives at grazing angles,
which shows as a bright rim.

    python3 bench/blender/furnace_vs_cycles.py OUT_DIR [--spp 4096] [--base 1] [--roughness 0.15]

Writes OUT_DIR/furnace.glb and OUT_DIR/furnace-cycles.exr (64 × 64, CPU, 2 threads, box filter of
one pixel, eight bounces). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, material, white_world  # noqa: E402


def build(base, roughness):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=1, location=(0, 0, 0))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(material("pale", (base, base, base), 0.0, roughness))
    front_camera(scene, 2 * math.degrees(math.atan(1.1 / 4.0)))
    white_world(scene)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--base", type=float, default=1.0)
    ap.add_argument("--roughness", type=float, default=0.15)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    scene = build(a.base, a.roughness)
    export_and_render(scene, out, "furnace", (64, 64), a.spp, bounces=8)


if __name__ == "__main__":
    main()
