#!/usr/bin/env python3
"""Vertex colours — a mesh painted in Blender's Vertex Paint mode, a Color Attribute node
feeding the Principled BSDF's Base Color — through Blender's glTF exporter (which writes the
attribute as `COLOR_0`, which glTF multiplies into the base colour) against Cycles, for the test
`blender_vertex_colors_agree_with_cycles` (crates/alhazen-import/tests/gltf.rs).

The panel is a smooth mirror (metallic 1, roughness 0) facing the camera under a uniform white
world: at normal incidence both renderers' metals reflect exactly their base colour, so the
image is the interpolated vertex colours themselves, free of the two renderers' different
dielectric layers. The panel is a 12 × 12 grid of triangles (triangulated here, so that both
renderers split each quad along the same diagonal) whose colours vary smoothly from vertex to
vertex (red along x, green along z, blue along the diagonal), linear float colours.

    python3 bench/blender/vertex_colors_vs_cycles.py OUT_DIR [--spp 256] [--byte]

`--byte` paints an 8-bit colour attribute instead (Blender stores it as sRGB codes; its
exporter writes COLOR_0 linear either way) and names the files vertex-colors-byte.

Writes OUT_DIR/vertex-colors.glb and OUT_DIR/vertex-colors-cycles.exr (64 × 64, CPU, 2
threads, box filter of one pixel, one bounce). The .glb has no world: alhazen lights a glTF
without lights by a uniform white sky, the world given to Cycles here. Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy
import bmesh

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, material, white_world  # noqa: E402

CUTS = 12


def paint(x, z):
    """The colour at panel point (x, z) in [−1, 1]²."""
    return (0.5 + 0.4 * math.sin(2.0 * x), 0.5 + 0.4 * math.sin(1.7 * z + 0.5), 0.5 + 0.4 * math.cos(1.3 * (x + z)), 1.0)


def painted_panel(kind="FLOAT_COLOR"):
    """A 2 × 2 grid of CUTS × CUTS quads in the plane y = 0 facing −y, triangulated, its
    vertices painted by `paint` into a float colour attribute."""
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=CUTS, y_segments=CUTS, size=1.0)
    bmesh.ops.triangulate(bm, faces=bm.faces[:], quad_method="FIXED", ngon_method="BEAUTY")
    mesh = bpy.data.meshes.new("painted")
    bm.to_mesh(mesh)
    bm.free()
    attr = mesh.color_attributes.new("Col", kind, "POINT")
    for v, c in zip(mesh.vertices, attr.data):
        c.color = paint(v.co.x, v.co.y)
    mesh.color_attributes.active_color = attr
    obj = bpy.data.objects.new("painted", mesh)
    bpy.context.scene.collection.objects.link(obj)
    # The grid lies in z = 0 facing +z: stood up to face the camera at y = −4.
    obj.rotation_euler = (math.radians(90), 0.0, 0.0)
    return obj


def build(kind="FLOAT_COLOR"):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    m = material("painted mirror", (1.0, 1.0, 1.0), 1.0, 0.0)
    p = m.node_tree.nodes["Principled BSDF"]
    attribute = m.node_tree.nodes.new("ShaderNodeVertexColor")
    attribute.layer_name = "Col"
    m.node_tree.links.new(attribute.outputs["Color"], p.inputs["Base Color"])
    painted_panel(kind).data.materials.append(m)
    front_camera(scene, 25)
    white_world(scene)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--byte", action="store_true")
    a = ap.parse_args()
    stem = "vertex-colors-byte" if a.byte else "vertex-colors"
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene = build("BYTE_COLOR" if a.byte else "FLOAT_COLOR")
    export_and_render(scene, out, stem, (64, 64), a.spp, bounces=1)


if __name__ == "__main__":
    main()
