#!/usr/bin/env python3
"""Draco-compressed meshes (`KHR_draco_mesh_compression`, Blender's "Compression" export
option) against Cycles and against the same scenes exported uncompressed, for the tests
`blender_draco_meshes_agree_with_cycles` and `blender_draco_vertex_colors_agree_with_cycles`
(crates/alhazen-import/tests/gltf.rs).

Two scenes of the other scripts, built by their own `build()` and exported with Blender's
default Draco settings (compression level 6; positions quantised to 14 bits, normals to 10,
texture coordinates to 12, colours to 10):

* `materials-draco.glb`: gltf_vs_cycles.py's floor, red cube and smooth gold sphere (positions,
  normals, texture coordinates, indices) under its point light; Cycles' image of that scene is
  `materials-cycles.exr`, written by gltf_vs_cycles.py;
* `vertex-colors-draco.glb`: vertex_colors_vs_cycles.py's painted mirror panel (its colours
  through Draco too); Cycles' image is `vertex-colors-cycles.exr`.

    python3 bench/blender/draco_vs_cycles.py OUT_DIR [--cycles SPP]

`--cycles SPP` renders both scenes with Cycles as well (OUT_DIR/*-draco-cycles.exr), to check
that the committed references of the uncompressed scenes are images of the same scenes.
Needs `pip install bpy`.
"""
import argparse, os, sys

import bpy  # noqa: F401

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_vs_cycles  # noqa: E402
import vertex_colors_vs_cycles  # noqa: E402

DRACO = dict(export_draco_mesh_compression_enable=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--cycles", type=int, default=0, metavar="SPP")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    scenes = [
        ("materials-draco", gltf_vs_cycles.build, (160, 120), 8),
        ("vertex-colors-draco", vertex_colors_vs_cycles.build, (64, 64), 1),
    ]
    for stem, build, size, bounces in scenes:
        scene = build()
        if a.cycles:
            gltf_vs_cycles.export_and_render(scene, out, stem, size, a.cycles, bounces, **DRACO)
        else:
            os.makedirs(out, exist_ok=True)
            scene.render.resolution_x, scene.render.resolution_y = size
            bpy.ops.export_scene.gltf(filepath=os.path.join(out, f"{stem}.glb"), export_format="GLB",
                                      export_cameras=True, export_lights=True, export_yup=True, **DRACO)
        print(f"wrote {os.path.join(out, stem)}.glb", file=sys.stderr)


if __name__ == "__main__":
    main()
