#!/usr/bin/env python3
"""A thin translucent panel against Cycles' Translucent BSDF, for the test
`blender_translucent_panel_agrees_with_cycles` (crates/alhazen-import/tests/gltf.rs).

A 2 × 2 panel faces the camera, lit from behind by a sun (and, weaker, from the front by
another). Cycles shades it with a Mix Shader of a Diffuse BSDF (the base colour) and a
Translucent BSDF (the colour passed through) by the share `--share`: Lambert on the lit side
and on the other. Blender's glTF exporter writes neither the mix nor the Translucent BSDF, so
the panel is exported as a Principled BSDF of that base colour without specular reflection
(Specular IOR Level 0, exported as `KHR_materials_specular`'s factor 0), and the exported file
is then given `KHR_materials_diffuse_transmission` of the same share and colour — the same
surface in glTF's terms: `(1 − share)·base` reflected, `share·colour` passed through.

    python3 bench/blender/translucent_vs_cycles.py OUT_DIR [--spp 1024] [--share 0.4]

Writes OUT_DIR/translucent.glb and OUT_DIR/translucent-cycles.exr (64 × 64, CPU, 2 threads,
box filter of one pixel, two bounces). Needs `pip install bpy`.
"""
import argparse, json, os, struct, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import export_and_render, facing_panel, material, render, sun  # noqa: E402

BASE = (0.2, 0.6, 0.1)
THROUGH = (0.9, 0.5, 0.1)


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    m = material("leaf", BASE, 0.0, 0.5)
    m.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = 0.0
    facing_panel(scene, m)
    sun((-70, 0, 15), energy=3.0)
    sun((75, 0, -20), energy=1.0)
    return scene, m


def translucent(m, share):
    """Material `m`'s output replaced by Cycles' mix of a Diffuse BSDF of the base colour and a
    Translucent BSDF of the colour passed through, by `share`."""
    nodes, links = m.node_tree.nodes, m.node_tree.links
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*BASE, 1.0)
    through = nodes.new("ShaderNodeBsdfTranslucent")
    through.inputs["Color"].default_value = (*THROUGH, 1.0)
    mix = nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = share
    links.new(diffuse.outputs["BSDF"], mix.inputs[1])
    links.new(through.outputs["BSDF"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])


def with_diffuse_transmission(path, share):
    """Adds `KHR_materials_diffuse_transmission` of `share` and the colour passed through to
    every material of the binary glTF at `path`."""
    data = open(path, "rb").read()
    (json_len,) = struct.unpack_from("<I", data, 12)
    doc = json.loads(data[20:20 + json_len])
    rest = data[20 + json_len:]
    for m in doc["materials"]:
        m.setdefault("extensions", {})["KHR_materials_diffuse_transmission"] = {
            "diffuseTransmissionFactor": share, "diffuseTransmissionColorFactor": list(THROUGH)}
    doc.setdefault("extensionsUsed", []).append("KHR_materials_diffuse_transmission")
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunk = struct.pack("<II", len(text), 0x4E4F534A) + text
    total = 12 + len(chunk) + len(rest)
    open(path, "wb").write(b"glTF" + struct.pack("<II", 2, total) + chunk + rest)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--share", type=float, default=0.4)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    scene, m = build()
    scene.render.resolution_x, scene.render.resolution_y = 64, 64
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "translucent.glb"), export_format="GLB",
                              export_cameras=True, export_lights=True, export_yup=True)
    with_diffuse_transmission(os.path.join(out, "translucent.glb"), a.share)
    translucent(m, a.share)
    seconds = render(scene, os.path.join(out, "translucent-cycles.exr"), a.spp, (64, 64), bounces=2, transparent=0,
                     depth="32")
    print(f"Cycles: {a.spp} spp at 64x64 on 2 threads in {seconds:.2f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
