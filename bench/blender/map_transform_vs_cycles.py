#!/usr/bin/env python3
"""A metallic–roughness map placed by a Mapping node — scaled, turned and moved, as Blender users
tile a whole PBR texture set — through Blender's glTF exporter (which writes the node as the
`metallicRoughnessTexture`'s `KHR_texture_transform`) against Cycles, for the test
`blender_map_transform_agrees_with_cycles` (crates/alhazen-import/tests/gltf.rs).

A smooth panel (roughness 0) of a copper base colour faces the camera, lit by a sun 30° off its
normal in a black world; its metalness is read from the blue channel of a smoothly repeating
image of waves (along u, and along the diagonal), through a Mapping node of location
(0.15, 0.3), rotation 30° and scale (1.5, 0.75). Where it is metal, the panel mirrors the black
world (the sun's reflection misses the camera); where it is dielectric, its diffuse layer shows
the sun's light. Without the placement the waves of metal land elsewhere.

    python3 bench/blender/map_transform_vs_cycles.py OUT_DIR [--spp 256] [--normal]

`--normal` places a normal map instead (files normal-transform.*): a smooth grey dielectric
panel whose Normal Map node (tangent space, strength 1) reads a smoothly repeating image of
bumps through the same Mapping node, exported as the `normalTexture`'s transform. Cycles reads
the texels at the mapped coordinates and takes their vectors in the frame of the UV map's
tangent (the Mapping node turns where the map is read, not the vectors), as alhazen does.

Writes OUT_DIR/map-transform.glb and OUT_DIR/map-transform-cycles.exr (64 × 64, CPU, 2 threads,
box filter of one pixel, two bounces). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, facing_panel, image_node, mapped, material, saved_image, sun  # noqa: E402


def waves(x, y):
    """Texel (x, y) of a 32 × 32 map that repeats smoothly: roughness 0 (green), metalness
    (blue) in waves along u and along the diagonal."""
    t = 2 * math.pi / 32
    return (0.0, 0.0, 0.5 + 0.25 * math.sin(t * x) + 0.25 * math.cos(t * (x + 2 * y)), 1.0)


def build(out):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    img = saved_image("waves", 32, waves, os.path.join(out, "map-waves.png"))
    img.colorspace_settings.name = "Non-Color"
    m = material("copper", (0.95, 0.64, 0.54), 1.0, 1.0)
    tex, p = image_node(m, img)
    split = m.node_tree.nodes.new("ShaderNodeSeparateColor")
    m.node_tree.links.new(tex.outputs["Color"], split.inputs["Color"])
    m.node_tree.links.new(split.outputs["Green"], p.inputs["Roughness"])
    m.node_tree.links.new(split.outputs["Blue"], p.inputs["Metallic"])
    mapped(m, tex)
    facing_panel(scene, m)
    # A sun 30° above the camera's axis: the dielectric's diffuse shows it, the smooth metal
    # reflects it away from the camera and shows the black world.
    sun((60, 0, 0))
    return scene


def bumps(x, y):
    """Texel (x, y) of a 32 × 32 tangent-space normal map that repeats smoothly: the normal of
    the height field h = 0.12 (sin(2πx/32) + cos(2π(x + 2y)/32)) in texels' units of 1/32,
    encoded as (n + 1)/2."""
    t = 2 * math.pi / 32
    # ∂h/∂u and ∂h/∂v with u = x/32, v = y/32.
    du = 0.12 * 32 * t * (math.cos(t * x) - math.sin(t * (x + 2 * y)))
    dv = 0.12 * 32 * t * (-2 * math.sin(t * (x + 2 * y)))
    n = (-du, -dv, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return (*(0.5 + 0.5 * c / length for c in n), 1.0)


def build_normal(out):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    img = saved_image("bumps", 32, bumps, os.path.join(out, "normal-bumps.png"))
    img.colorspace_settings.name = "Non-Color"
    m = material("grey", (0.7, 0.7, 0.7), 0.0, 0.0)
    tex, p = image_node(m, img)
    normal_map = m.node_tree.nodes.new("ShaderNodeNormalMap")
    m.node_tree.links.new(tex.outputs["Color"], normal_map.inputs["Color"])
    m.node_tree.links.new(normal_map.outputs["Normal"], p.inputs["Normal"])
    mapped(m, tex)
    facing_panel(scene, m)
    sun((60, 0, 20))
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--normal", action="store_true")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build_normal(out) if a.normal else build(out)
    stem = "normal-transform" if a.normal else "map-transform"
    export_and_render(scene, out, stem, (64, 64), a.spp, bounces=2)


if __name__ == "__main__":
    main()
