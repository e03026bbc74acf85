#!/usr/bin/env python3
"""A texture placed by a Mapping node — scaled, turned and moved, as Blender users place wood
grain and tiles — through Blender's glTF exporter (which writes it as `KHR_texture_transform`
scale, rotation and offset) against Cycles: an emitting panel facing the camera whose Emission
Color is a smoothly repeating image of waves (red along u, green along v, blue along the
diagonal), for the test
`blender_texture_transform_agrees_with_cycles` (crates/alhazen-import/tests/gltf.rs).

    python3 bench/blender/texture_transform_vs_cycles.py OUT_DIR [--spp 1024] [--extension EXTEND|MIRROR]

`--extension` sets the image node's extension (Blender's Extend and Mirror, exported as the
sampler's CLAMP_TO_EDGE and MIRRORED_REPEAT: the wrap modes, test
`blender_wrap_modes_agree_with_cycles`) and names the files texture-extend / texture-mirror.

Writes OUT_DIR/texture-transform.glb and OUT_DIR/texture-transform-cycles.exr (64 × 64, CPU,
2 threads, box filter of one pixel, no bounces: the panel's emission alone). Needs
`pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render_emission, facing_panel, image_node, mapped, material, saved_image  # noqa: E402


def waves(x, y):
    """Texel (x, y) of a 32 × 32 image that repeats smoothly: red waves along u, green along v,
    blue along the diagonal — each direction its own colour, so a turn or a shift shows, and
    neighbouring texels close, so Cycles' interpolation of 8-bit sRGB texels before decoding
    them (where alhazen decodes, then interpolates) differs from ours by little."""
    t = 2 * math.pi / 32
    return (0.5 + 0.4 * math.sin(t * x), 0.5 + 0.4 * math.sin(t * y + 1.0), 0.5 + 0.4 * math.cos(t * (x + y)), 1.0)


def build(out, extension="REPEAT"):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    img = saved_image("waves", 32, waves, os.path.join(out, "waves.png"))
    m = material("panel", (0.0, 0.0, 0.0), 0.0, 1.0)
    tex, p = image_node(m, img)
    tex.extension = extension
    mapped(m, tex)
    m.node_tree.links.new(tex.outputs["Color"], p.inputs["Emission Color"])
    p.inputs["Emission Strength"].default_value = 1.0
    facing_panel(scene, m)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--extension", choices=["REPEAT", "EXTEND", "MIRROR"], default="REPEAT")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    stem = "texture-transform" if a.extension == "REPEAT" else f"texture-{a.extension.lower()}"
    export_and_render_emission(build(out, a.extension), out, stem, (64, 64), a.spp)


if __name__ == "__main__":
    main()
