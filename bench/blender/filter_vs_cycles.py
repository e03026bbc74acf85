#!/usr/bin/env python3
"""Blender Cycles' default pixel filter against alhazen's: three emitting panels seen against
black (a tilted square, a bar about a pixel wide, a spot of two pixels) — sharp edges, so the
filter decides every pixel near them — built with Blender's Python module, exported with its
glTF exporter and rendered by Cycles through its Blackman–Harris filter of width 1.5 (the
default of a new Blender scene), for the test `blender_pixel_filter_agrees_with_cycles`
(crates/alhazen-import/tests/gltf.rs), which renders the .glb with `filter = "blackman-harris"`.

    python3 bench/blender/filter_vs_cycles.py OUT_DIR [--spp 16384]

Writes OUT_DIR/filter.glb and OUT_DIR/filter-cycles.exr (CPU, 2 threads, no denoiser, no
adaptive sampling, no bounces: the panels alone). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render_emission, front_camera  # noqa: E402


def panel(name, size, angle, at, color, strength):
    """A `size` rectangle in the plane y = 0 facing the camera (−y), turned `angle` degrees
    about y, glowing `color` × `strength`."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    p.inputs["Emission Color"].default_value = (*color, 1.0)
    p.inputs["Emission Strength"].default_value = strength
    bpy.ops.mesh.primitive_plane_add(size=1, location=(at[0], 0.0, at[1]),
                                     rotation=(math.radians(90), math.radians(angle), 0))
    bpy.context.object.scale = (size[0], size[1], 1.0)
    bpy.context.object.data.materials.append(m)


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    panel("square", (0.5, 0.5), 25, (-0.4, 0.1), (1.0, 0.5, 0.25), 4.0)
    panel("bar", (0.04, 0.5), 10, (0.45, 0.0), (1.0 / 3, 1.0, 1.0 / 6), 3.0)
    panel("spot", (0.08, 0.08), 0, (0.2, -0.45), (1.0, 1.0, 1.0), 8.0)
    front_camera(scene, 30)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=16384)
    a = ap.parse_args()
    export_and_render_emission(build(), os.path.abspath(a.out), "filter", (64, 48), a.spp,
                               pixel_filter=("BLACKMAN_HARRIS", 1.5))


if __name__ == "__main__":
    main()
