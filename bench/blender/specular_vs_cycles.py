#!/usr/bin/env python3
"""A Principled BSDF's Specular IOR Level — 0 for a matte surface without reflections, 1 for one
reflecting twice the light of its index — through Blender's glTF exporter (which writes it as
`KHR_materials_specular`: level 0 as `specularFactor` 0, level 1 as `specularColorFactor` 2)
against Cycles, for the test `blender_specular_level_agrees_with_cycles`
(crates/alhazen-import/tests/gltf.rs).

A grey dielectric panel (base colour 0.5, roughness 0.4) faces the camera, lit by a sun from
near the camera's direction, so its highlight spreads over the panel.

    python3 bench/blender/specular_vs_cycles.py OUT_DIR [--spp 1024] [--level 0]

Writes OUT_DIR/specular-LEVEL.glb and OUT_DIR/specular-LEVEL-cycles.exr (64 × 64, CPU, 2
threads, box filter of one pixel, two bounces; LEVEL as given, e.g. specular-0, specular-1).
Needs `pip install bpy`.
"""
import argparse, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, facing_panel, material, sun  # noqa: E402


def build(level):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    m = material("grey", (0.5, 0.5, 0.5), 0.0, 0.4)
    m.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = level
    facing_panel(scene, m)
    sun((82, 0, 6))
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--level", type=float, default=0.0)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build(a.level)
    stem = f"specular-{a.level:g}"
    export_and_render(scene, out, stem, (64, 64), a.spp, bounces=2)


if __name__ == "__main__":
    main()
