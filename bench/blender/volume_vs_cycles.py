#!/usr/bin/env python3
"""Tinted glass through Blender's glTF exporter against Cycles: a glass cube (Principled BSDF,
transmission 1, roughness 0, IOR 1.5) filled by a Volume Absorption node (colour c, density ρ)
and given a thickness in a "glTF Material Output" group — which is what makes the exporter
write `KHR_materials_volume` (`attenuationColor` c, `attenuationDistance` 1/ρ) —, seen face on
against a white emitting panel behind it, in a black world (so that nothing but the panel's
light through the glass reaches the camera there).

glTF absorbs `−ln(c)·ρ` per unit length, Cycles `(1 − c)·ρ`: through d units of glass alhazen's
image of the exported file is Cycles' times `exp(−d·ρ·(−ln c − (1 − c)))` per channel (d = the
cube's side), which the script prints; the test `blender_volume_differs_from_cycles_as_gltf_says`
(crates/alhazen-import/tests/gltf.rs) measures it over the cube's middle.

    python3 bench/blender/volume_vs_cycles.py OUT_DIR [--spp 1024]

Writes OUT_DIR/volume.glb and OUT_DIR/volume-cycles.exr (48 × 48, CPU, 2 threads, box filter
of one pixel, 16 bounces). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import black_world, export_and_render  # noqa: E402

COLOR = (0.5, 0.8, 0.95)
DENSITY = 1.5
SIDE = 1.0


def glass(name):
    """Clear glass whose volume absorbs by COLOR and DENSITY, of thickness SIDE for glTF."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    p = nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    p.inputs["Transmission Weight"].default_value = 1.0
    p.inputs["Roughness"].default_value = 0.0
    p.inputs["IOR"].default_value = 1.5
    absorb = nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (*COLOR, 1.0)
    absorb.inputs["Density"].default_value = DENSITY
    links.new(absorb.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
    group = bpy.data.node_groups.new("glTF Material Output", "ShaderNodeTree")
    group.interface.new_socket("Thickness", in_out="INPUT", socket_type="NodeSocketFloat")
    settings = nodes.new("ShaderNodeGroup")
    settings.node_tree = group
    settings.inputs["Thickness"].default_value = SIDE
    return m


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_cube_add(size=SIDE, location=(0.0, 0.0, 0.0))
    bpy.context.object.data.materials.append(glass("tinted glass"))
    bpy.ops.object.camera_add(location=(0.0, -5.0, 0.0), rotation=(math.radians(90), 0, 0))
    scene.camera = bpy.context.object
    scene.camera.data.sensor_fit = "HORIZONTAL"
    scene.camera.data.angle = math.radians(14)
    black_world(scene)
    # The panel behind: white, of radiance 1, facing the camera.
    bpy.ops.mesh.primitive_plane_add(size=4, location=(0.0, 2.0, 0.0), rotation=(math.radians(90), 0, 0))
    panel = bpy.data.materials.new("panel")
    panel.use_nodes = True
    p = panel.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    p.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    p.inputs["Emission Strength"].default_value = 1.0
    bpy.context.object.data.materials.append(panel)
    return scene


def predicted():
    return [math.exp(-SIDE * DENSITY * (-math.log(c) - (1.0 - c))) for c in COLOR]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    scene = build()
    export_and_render(scene, out, "volume", (48, 48), a.spp, bounces=16)
    print("predicted alhazen/Cycles:", " ".join(f"{r:.4f}" for r in predicted()))


if __name__ == "__main__":
    main()
