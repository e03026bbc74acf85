#!/usr/bin/env python3
"""Glass where a map says: a slab (2 × 0.1 × 2) of an orange Principled BSDF (roughness 0.2) whose
Transmission Weight is the red channel of a 64 × 64 map — vertical stripes of 1 and 0.25 — in
front of a grey cube, under a white world, through Blender's glTF exporter (which writes the map
as `KHR_materials_transmission`'s `transmissionTexture`) against Cycles, for the test
`blender_transmission_map_agrees_with_cycles` (crates/alhazen-import/tests/gltf.rs).

    python3 bench/blender/transmission_map_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/transmission-map.glb, OUT_DIR/stripes.png and
OUT_DIR/transmission-map-cycles.exr (64 × 64, CPU, 2 threads, box filter of one pixel, eight
bounces). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, image_node, material, saved_image, white_world  # noqa: E402


def build(out):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("white")
    scene.world.use_nodes = True
    stripe = lambda x, y: (1.0, 1.0, 1.0, 1.0) if (x // 16) % 2 == 0 else (0.25, 0.25, 0.25, 1.0)  # noqa: E731
    img = saved_image("stripes", 64, stripe, os.path.join(out, "stripes.png"))
    img.colorspace_settings.name = "Non-Color"
    m = material("striped glass", (0.8, 0.3, 0.1), 0.0, 0.2)
    tex, p = image_node(m, img)
    split = m.node_tree.nodes.new("ShaderNodeSeparateColor")
    m.node_tree.links.new(tex.outputs["Color"], split.inputs["Color"])
    m.node_tree.links.new(split.outputs["Red"], p.inputs["Transmission Weight"])
    p.inputs["IOR"].default_value = 1.5
    # A slab 0.1 thick (a closed solid: light enters and leaves, as through a window pane):
    # a 2 × 2 plane facing the camera, solidified, its faces keeping the plane's UVs.
    bpy.ops.mesh.primitive_plane_add(size=2, location=(0.0, 0.0, 0.0), rotation=(math.radians(90), 0, 0))
    slab = bpy.context.object
    slab.data.materials.append(m)
    solid = slab.modifiers.new("solidify", "SOLIDIFY")
    solid.thickness = 0.1
    bpy.ops.object.modifier_apply(modifier=solid.name)
    front_camera(scene, 25)
    bpy.ops.mesh.primitive_cube_add(size=1.2, location=(0.3, 2.0, -0.2))
    bpy.context.object.data.materials.append(material("grey", (0.2, 0.2, 0.2), 0.0, 0.8))
    white_world(scene)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    export_and_render(build(out), out, "transmission-map", (64, 64), a.spp, bounces=8)


if __name__ == "__main__":
    main()
