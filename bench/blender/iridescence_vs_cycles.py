#!/usr/bin/env python3
"""Thin films: three spheres of a Principled BSDF with Thin Film Thickness and Thin Film IOR set
(Blender 4.2+), under a uniform white world, against Cycles (BENCHMARKS.md, session 52):

1. a near-black dielectric (base 0.02, IOR 1.5, roughness 0.15) under a soap-like film, 300 nm of index 1.33;
2. a pale metal (base 0.8, roughness 0.2) under a tempered-steel film, 250 nm of index 1.5;
3. a dark blue dielectric (base (0.05, 0.05, 0.2), roughness 0.15) under 550 nm of index 1.8.

Blender's glTF exporter does not write `KHR_materials_iridescence` (Blender 5.0), so this script
exports the scene (`OUT_DIR/iridescence.glb`, without the films) and then writes the films into
the file's materials itself, as a tool that exports them would: `iridescenceFactor` 1,
`iridescenceIOR` and `iridescenceThicknessMaximum` the node's values.

Cycles computes its films by Belcour and Barla's model with the exact (polarised) Fresnel
equations at both interfaces; glTF's, which alhazen renders, uses Schlick's approximation at
both and the metal's index found from its colour: the hues are expected to match, their
strengths only roughly.

    python3 bench/blender/iridescence_vs_cycles.py OUT_DIR [--spp 1024] [--glass]

Writes OUT_DIR/iridescence.glb and OUT_DIR/iridescence-cycles.exr (96 × 32, CPU, 2 threads, box
filter of one pixel, four bounces). `--glass` gives clear glass spheres the films instead, before
a dark backdrop (files iridescence-glass, eight bounces). Needs `pip install bpy`.
"""
import argparse, json, math, os, struct, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, front_camera, material, white_world  # noqa: E402

# (name, base colour, metallic, roughness, film thickness in nm, film index)
SPHERES = [
    ("soap", (0.02, 0.02, 0.02), 0.0, 0.15, 300.0, 1.33),
    ("steel", (0.8, 0.8, 0.8), 1.0, 0.2, 250.0, 1.5),
    ("blue", (0.05, 0.05, 0.2), 0.0, 0.15, 550.0, 1.8),
]


# Soap bubbles and coated lenses (`--glass`): clear glass spheres (IOR 1.5, smooth) under
# films of 300 nm of 1.33, 500 nm of 1.33 and 400 nm of 1.8, before a dark backdrop.
GLASS = [
    ("bubble 300", (1.0, 1.0, 1.0), 0.0, 0.0, 300.0, 1.33),
    ("bubble 500", (1.0, 1.0, 1.0), 0.0, 0.0, 500.0, 1.33),
    ("lens 400", (1.0, 1.0, 1.0), 0.0, 0.0, 400.0, 1.8),
]


def build(glass=False):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("white")
    scene.world.use_nodes = True
    for k, (name, color, metallic, rough, thickness, ior) in enumerate(GLASS if glass else SPHERES):
        m = material(name, color, metallic, rough)
        p = m.node_tree.nodes["Principled BSDF"]
        p.inputs["Thin Film Thickness"].default_value = thickness
        p.inputs["Thin Film IOR"].default_value = ior
        if glass:
            p.inputs["Transmission Weight"].default_value = 1.0
            p.inputs["IOR"].default_value = 1.5
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, segments=48, ring_count=24, location=(k - 1.0, 0.0, 0.0))
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(m)
    if glass:
        bpy.ops.mesh.primitive_plane_add(size=8, location=(0.0, 2.0, 0.0), rotation=(math.radians(90), 0, 0))
        bpy.context.object.data.materials.append(material("backdrop", (0.05, 0.05, 0.05), 0.0, 1.0))
    front_camera(scene, 40)
    white_world(scene)
    return scene


def add_films(path):
    """Writes each sphere's film into the .glb's material of its name."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version, _ = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    doc = json.loads(data[20:20 + json_len])
    rest = data[20 + json_len:]
    films = {name: (thickness, ior) for name, _, _, _, thickness, ior in SPHERES + GLASS}
    for m in doc["materials"]:
        if m["name"] not in films:
            continue
        thickness, ior = films[m["name"]]
        m.setdefault("extensions", {})["KHR_materials_iridescence"] = {
            "iridescenceFactor": 1.0,
            "iridescenceIOR": ior,
            "iridescenceThicknessMaximum": thickness,
        }
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_materials_iridescence" not in used:
        used.append("KHR_materials_iridescence")
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + len(rest))
    out += struct.pack("<I4s", len(text), b"JSON") + text + rest
    with open(path, "wb") as f:
        f.write(out)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--glass", action="store_true", help="films on clear glass spheres (iridescence-glass)")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    stem = "iridescence-glass" if a.glass else "iridescence"
    export_and_render(build(a.glass), out, stem, (96, 32), a.spp, bounces=8 if a.glass else 4)
    add_films(os.path.join(out, f"{stem}.glb"))
