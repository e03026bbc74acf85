#!/usr/bin/env python3
"""A clear coat — a Principled BSDF's Coat (weight 1, roughness 0.1, IOR 1.5) over a red
dielectric of roughness 0.5 — through Blender's glTF exporter (which writes it as
`KHR_materials_clearcoat`) against Cycles, for the test `blender_clearcoat_agrees_with_cycles`
(crates/alhazen-import/tests/gltf.rs).

The panel faces the camera in a black world, lit by a sun from near the camera's direction:
the coat's sharp highlight over the base's broad one and its colour.

    python3 bench/blender/clearcoat_vs_cycles.py OUT_DIR [--spp 1024] [--weight 1]

Writes OUT_DIR/clearcoat-WEIGHT.glb and OUT_DIR/clearcoat-WEIGHT-cycles.exr (64 × 64, CPU,
2 threads, box filter of one pixel, two bounces). Needs `pip install bpy`.
"""
import argparse, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, facing_panel, material, sun  # noqa: E402


def build(weight):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    m = material("coated red", (0.6, 0.05, 0.04), 0.0, 0.5)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Coat Weight"].default_value = weight
    p.inputs["Coat Roughness"].default_value = 0.1
    p.inputs["Coat IOR"].default_value = 1.5
    facing_panel(scene, m)
    sun((80, 0, 8))
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--weight", type=float, default=1.0)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build(a.weight)
    export_and_render(scene, out, f"clearcoat-{a.weight:g}", (64, 64), a.spp, bounces=2)


if __name__ == "__main__":
    main()
