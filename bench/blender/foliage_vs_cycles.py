#!/usr/bin/env python3
"""The tree crown of bench/foliage/make.py (leaf cards cut out by an image's alpha) built in
Blender, exported with Blender's glTF exporter, and rendered by Cycles: what a Blender user with
foliage would hand alhazen, timed against the renderer they would otherwise use.

    python3 bench/foliage/make.py OUT --cards 20000
    python3 bench/blender/foliage_vs_cycles.py OUT [--spp 64] [--size 320x240]
    alhazen render OUT/foliage.glb -o ours.exr --spp 64 --width 320 --height 240

The leaves' material is a Principled BSDF whose Base Color and Alpha are leaf.png's colour and
alpha (exported as `alphaMode: BLEND`), roughness 1 and IOR 1.5 (glTF's default: Blender's
exporter leaves the IOR out, so a Blender IOR of 1.0 would be read as 1.5 — the crown was then
11 % brighter in alhazen); a trunk, a floor and a sun (strength 3, angle 0), no world light. Cycles: CPU, 2 threads, box pixel filter of one pixel, no denoiser, no adaptive
sampling, 6 bounces of every kind, transparent bounces 64; writes OUT/foliage-cycles.exr and
prints its render time (scene synchronisation and BVH build included, as alhazen's includes its
load and build). Needs `pip install bpy`.
"""
import argparse, math, os, sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_vs_cycles import black_world, render  # noqa: E402  (Cycles' settings, shared)


def build(out):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.wm.obj_import(filepath=os.path.join(out, "leaves.obj"), forward_axis="NEGATIVE_Z", up_axis="Y")
    leaves = bpy.context.selected_objects[0]
    img = bpy.data.images.load(os.path.join(out, "leaf.png"))
    m = bpy.data.materials.new("leaf")
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Linear"
    p = nodes["Principled BSDF"]
    p.inputs["Roughness"].default_value = 1.0
    p.inputs["IOR"].default_value = 1.5
    links.new(tex.outputs["Color"], p.inputs["Base Color"])
    links.new(tex.outputs["Alpha"], p.inputs["Alpha"])
    leaves.data.materials.clear()
    leaves.data.materials.append(m)

    def plain(name, color):
        mat = bpy.data.materials.new(name)
        mat.use_nodes = True
        q = mat.node_tree.nodes["Principled BSDF"]
        q.inputs["Base Color"].default_value = (*color, 1.0)
        q.inputs["Roughness"].default_value = 1.0
        q.inputs["IOR"].default_value = 1.5
        return mat

    bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, 0))
    bpy.context.object.data.materials.append(plain("ground", (0.45, 0.42, 0.35)))
    bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.12, depth=1.6, location=(0, 0, 0.8))
    bpy.context.object.data.materials.append(plain("bark", (0.25, 0.17, 0.1)))
    bpy.ops.object.light_add(type="SUN", location=(0, 0, 10))
    sun = bpy.context.object
    sun.data.energy = 3.0
    sun.data.angle = 0.0
    # The light travels along (-0.4, -1, -0.3) in the scene's y-up axes: (-0.4, 0.3, -1) z-up.
    d = (-0.4, 0.3, -1.0)
    sun.rotation_mode = "QUATERNION"
    from mathutils import Vector
    sun.rotation_quaternion = Vector((0, 0, -1)).rotation_difference(Vector(d).normalized())
    bpy.ops.object.camera_add(location=(0, -7, 2.0))
    cam = bpy.context.object
    cam.rotation_euler = (math.radians(90) + math.atan2(-0.2, 7), 0, 0)
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle = math.radians(45)
    scene.camera = cam
    black_world(scene)
    return scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--size", default="320x240")
    a = ap.parse_args()
    out = os.path.abspath(a.out)
    scene = build(out)
    size = tuple(int(x) for x in a.size.split("x"))
    scene.render.resolution_x, scene.render.resolution_y = size
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "foliage.glb"), export_format="GLB", export_lights=True,
                              export_cameras=True, export_yup=True)
    seconds = render(scene, os.path.join(out, "foliage-cycles.exr"), a.spp, size, bounces=6, transparent=64, depth="32")
    print(f"Cycles: {a.spp} spp at {size[0]}x{size[1]} on 2 threads in {seconds:.2f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
