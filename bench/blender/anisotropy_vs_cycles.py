#!/usr/bin/env python3
"""Brushed metal: three gold spheres of a Principled BSDF with Anisotropic 0.9, roughness 0.4 and
Anisotropic Rotation 0, 0.125 and 0.25 (0°, 45° and 90°; the tangent the UV map's), single-
scattering GGX, lit by a sun, through Blender's glTF exporter (which writes `KHR_materials_anisotropy`) against Cycles,
for the test `blender_anisotropy_agrees_with_cycles` (crates/alhazen-import/tests/gltf.rs).

Blender's exporter writes the Principled BSDF's own numbers — Anisotropic as
`anisotropyStrength`, the rotation in radians — but the two read them differently: Cycles
stretches the facets to `α/a` along the tangent and `α·a` across it (`a = √(1 − 0.9s)`,
Disney's), glTF to `α + (1 − α)s²` along and `α` across. The test renders the file as glTF
reads it and also as Cycles does (alhazen's `AnisotropyModel::Disney`, which Mitsuba's
`principled` shares), both with single-scattering metals.

    python3 bench/blender/anisotropy_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/anisotropy.glb and OUT_DIR/anisotropy-cycles.exr (96 × 32, CPU, 2 threads, box
filter of one pixel, four bounces). Needs `pip install bpy`.
"""
import os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import front_camera, main_of, material, sun  # noqa: E402

ROUGHNESS, ANISOTROPIC = 0.4, 0.9
ROTATIONS = [0.0, 0.125, 0.25]


def brushed(name, rotation):
    """A gold Principled BSDF brushed along its UV map's tangent turned by `rotation` turns."""
    m = material(name, (1.0, 0.78, 0.34), 1.0, ROUGHNESS)
    nodes = m.node_tree.nodes
    p = nodes["Principled BSDF"]
    p.inputs["Anisotropic"].default_value = ANISOTROPIC
    p.inputs["Anisotropic Rotation"].default_value = rotation
    # Single scattering: the facets' stretch apart from the renderers' different ways of giving
    # back the light of several facets (Cycles scales the lobe by 1/E(μ_o), alhazen adds Kulla
    # and Conty's broad lobe: under a sun the two differ by more than the stretch is tested to).
    p.distribution = "GGX"
    tangent = nodes.new("ShaderNodeTangent")
    tangent.direction_type = "UV_MAP"
    m.node_tree.links.new(tangent.outputs["Tangent"], p.inputs["Tangent"])
    return m


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for k, rotation in enumerate(ROTATIONS):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, segments=48, ring_count=24, location=(k - 1.0, 0.0, 0.0))
        bpy.ops.object.shade_smooth()
        bpy.context.object.data.materials.append(brushed(f"brushed {rotation:g}", rotation))
    front_camera(scene, 40)
    sun((60, 0, -25), energy=4.0)
    return scene


if __name__ == "__main__":
    main_of("anisotropy", build, size=(96, 32))
