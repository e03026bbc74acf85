#!/usr/bin/env python3
"""A Blender scene lit by an HDRI world, against Cycles: what `alhazen render FILE.glb
--environment MAP --environment-rotate 90` is for. A glTF file carries no world, so a Blender
user hands alhazen the exported file and the map the world used.

The map (64 × 32, OpenEXR, written by this script) tells every direction apart: a dim blue sky
over a brown ground, with four coloured lamps around the horizon — red towards Blender's +x (the
map's centre), white towards +y, blue towards −x, green towards −y — and a small bright warm sun
high towards +x. A mirror ball, a white diffuse ball and a grey rough metal ball stand in it,
seen from the front (−y, as `front_camera`), with the map behind them. Cycles reads the map
with its default interpolation (Linear: bilinear between texel centres), as alhazen does.

    python3 bench/blender/environment_vs_cycles.py OUT_DIR [--spp 1024]

Blender saves the float map sRGB-encoded (a texel of 0.25 is stored as 0.537); Cycles reads the
file back as linear, as alhazen does, so both render the same stored values.

Writes OUT_DIR/environment.glb, OUT_DIR/environment-sky.exr and OUT_DIR/environment-cycles.exr
(96 × 64, CPU, 2 threads, box filter of one pixel, eight bounces), for the test
`blender_environment_agrees_with_cycles`. Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, material  # noqa: E402

W, H = 64, 32


def radiance(x, y):
    """The map's texel (x, y), rows from the bottom (Blender's order): at u = (x + ½)/W of the
    way round as Cycles maps it (u = ½ towards +x, ¼ towards +y), the elevation from −90° at
    the bottom row to 90° at the top."""
    elevation = ((y + 0.5) / H - 0.5) * 180.0
    u = (x + 0.5) / W
    if elevation > 55.0 and abs(u - 0.5) < 0.04:
        return (60.0, 50.0, 30.0)  # the sun, towards +x, high
    if abs(elevation) < 12.0:
        for centre, colour in ((0.5, (6.0, 0.3, 0.2)), (0.75, (0.2, 5.0, 0.3)), (0.0, (0.3, 0.4, 6.0)),
                               (1.0, (0.3, 0.4, 6.0)), (0.25, (4.0, 4.0, 4.0))):
            if abs(u - centre) < 0.05:
                return colour
    if elevation >= 0.0:
        return (0.25, 0.35, 0.6)
    return (0.25, 0.18, 0.1)


def sky(path):
    img = bpy.data.images.new("sky", W, H, alpha=False, float_buffer=True)
    pixels = []
    for y in range(H):
        for x in range(W):
            pixels += [*radiance(x, y), 1.0]
    img.pixels = pixels
    img.filepath_raw = path
    img.file_format = "OPEN_EXR"
    img.save()
    return img


def build(sky_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for x, m in ((-1.1, material("mirror", (0.95, 0.95, 0.95), 1.0, 0.0)),
                 (0.0, material("white", (0.8, 0.8, 0.8), 0.0, 1.0)),
                 (1.1, material("rough-metal", (0.9, 0.8, 0.6), 1.0, 0.35))):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.5, location=(x, 0, 0))
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(m)
    front_camera(scene, 45.0)
    world = bpy.data.worlds.new("hdri")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = sky(sky_path)
    env.image.colorspace_settings.name = "Linear Rec.709"
    env.interpolation = "Linear"
    links.new(env.outputs["Color"], nodes["Background"].inputs["Color"])
    nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build(os.path.join(out, "environment-sky.exr"))
    export_and_render(scene, out, "environment", (96, 64), a.spp, bounces=8)


if __name__ == "__main__":
    main()
