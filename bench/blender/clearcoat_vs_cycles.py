#!/usr/bin/env python3
"""A clear coat — a Principled BSDF's Coat (weight 1, roughness 0.1, IOR 1.5) over a red
dielectric of roughness 0.5 — through Blender's glTF exporter (which writes it as
`KHR_materials_clearcoat`) against Cycles, for the test `blender_clearcoat_agrees_with_cycles`
(crates/alhazen-import/tests/gltf.rs).

The panel faces the camera in a black world, lit by a sun from near the camera's direction:
the coat's sharp highlight over the base's broad one and its colour.

    python3 bench/blender/clearcoat_vs_cycles.py OUT_DIR [--spp 1024] [--weight 1 | --maps]

Writes OUT_DIR/clearcoat-WEIGHT.glb and OUT_DIR/clearcoat-WEIGHT-cycles.exr (64 × 64, CPU,
2 threads, box filter of one pixel, two bounces). `--maps` reads the coat's weight and
roughness from one map instead (`clearcoatTexture`, `clearcoatRoughnessTexture`: stripes of
weight 1 and 0.2, roughness 0.1 above and 0.6 below) and names the files clearcoat-maps (test
`blender_clearcoat_maps_agree_with_cycles`). Needs `pip install bpy`.
"""
import argparse, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, facing_panel, image_node, material, saved_image, sun  # noqa: E402


def build(weight, maps=None):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    m = material("coated red", (0.6, 0.05, 0.04), 0.0, 0.5)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Coat Weight"].default_value = weight
    p.inputs["Coat Roughness"].default_value = 0.1
    p.inputs["Coat IOR"].default_value = 1.5
    if maps:
        coat_maps(m, maps)
    facing_panel(scene, m)
    sun((80, 0, 8))
    return scene


def coat_maps(m, path):
    """Coat Weight from the red channel and Coat Roughness from the green of one 64 × 64 map
    (non-colour) saved at `path`: weight 1 and 0.2 in vertical stripes 16 texels wide,
    roughness 0.1 on the upper half and 0.6 on the lower."""
    def texel(x, y):
        return (1.0 if (x // 16) % 2 == 0 else 0.2, 0.1 if y >= 32 else 0.6, 0.0, 1.0)
    img = saved_image("coat", 64, texel, path)
    img.colorspace_settings.name = "Non-Color"
    tex, p = image_node(m, img)
    split = m.node_tree.nodes.new("ShaderNodeSeparateColor")
    m.node_tree.links.new(tex.outputs["Color"], split.inputs["Color"])
    m.node_tree.links.new(split.outputs["Red"], p.inputs["Coat Weight"])
    m.node_tree.links.new(split.outputs["Green"], p.inputs["Coat Roughness"])
    p.inputs["Coat Weight"].default_value = 1.0
    p.inputs["Coat Roughness"].default_value = 1.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--weight", type=float, default=1.0)
    ap.add_argument("--maps", action="store_true", help="the coat's weight and roughness from a map (clearcoat-maps)")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build(a.weight, os.path.join(out, "coat.png") if a.maps else None)
    stem = "clearcoat-maps" if a.maps else f"clearcoat-{a.weight:g}"
    export_and_render(scene, out, stem, (64, 64), a.spp, bounces=2)


if __name__ == "__main__":
    main()
