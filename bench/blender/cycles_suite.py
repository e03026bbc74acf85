#!/usr/bin/env python3
"""Issue 18's suite against Blender Cycles: the suite's Mitsuba XML scenes rebuilt in Blender
(geometry, camera and lights exactly; materials as the nearest Cycles shader) and rendered by
Cycles on the CPU, 2 threads, no denoiser, no adaptive sampling, 8 bounces, box filter; the
time of `bpy.ops.render.render` (which includes Cycles' scene sync and BVH build) against the
whole `alhazen render` process at the same size and samples.

    python3 bench/mitsuba/suite/make_data.py      # once
    python3 bench/blender/cycles_suite.py [--spp 64] [--runs 3] [NAME…]

Needs `pip install bpy mitsuba numpy` (Mitsuba only reads the XML files: the same scenes).
"""
import argparse, math, os, subprocess, sys, tempfile, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi
import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "bench/mitsuba"))
import suite  # noqa: E402


def principled(name, color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, transmission=0.0, ior=1.5):
    m = bpy.data.materials.new(name)
    m.use_nodes = True  # noqa (Blender 5 still needs it for node materials)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Transmission Weight"].default_value = transmission
    p.inputs["IOR"].default_value = ior
    return m


def emissive(name, radiance):
    m = bpy.data.materials.new(name)
    m.use_nodes = True  # noqa (Blender 5 still needs it for node materials)
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    e = nodes.new("ShaderNodeEmission")
    peak = max(radiance)
    e.inputs["Color"].default_value = (*(c / peak for c in radiance), 1.0)
    e.inputs["Strength"].default_value = peak
    m.node_tree.links.new(e.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    return m


def material_of(shape, k):
    """The nearest Cycles material to the shape's Mitsuba BSDF (or its emitter)."""
    if shape.emitter() is not None:
        return emissive(f"light{k}", [float(x) for x in np.ravel(mi.traverse(shape.emitter())["radiance.value"])])
    desc, params = str(shape.bsdf()), mi.traverse(shape.bsdf())
    color = lambda key: tuple(float(x) for x in np.ravel(params[key])) if key in params else (0.7, 0.7, 0.7)
    alpha = next((float(np.ravel(params[k])[0]) for k in ("alpha.value", "alpha", "alpha_u.value") if k in params), 0.1)
    if desc.startswith("SmoothDiffuse") or desc.startswith("NormalMap") or desc.startswith("BumpMap"):
        return principled(f"m{k}", color("reflectance.value"), roughness=1.0)
    if "Conductor" in desc:
        return principled(f"m{k}", (0.95, 0.64, 0.54), 1.0, math.sqrt(alpha) if desc.startswith("Rough") else 0.0)
    if "Plastic" in desc:
        return principled(f"m{k}", color("diffuse_reflectance.value"), 0.0, 0.3 if desc.startswith("Rough") else 0.0)
    if "Dielectric" in desc:
        return principled(f"m{k}", (1, 1, 1), 0.0, math.sqrt(alpha) if desc.startswith("Rough") else 0.0, 1.0)
    return principled(f"m{k}")


def build(path):
    """The scene of the XML file `path` in Blender."""
    mi.set_variant("scalar_rgb")
    s = mi.load_file(path)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for k, shape in enumerate(s.shapes()):
        if shape.is_mesh():
            pos = np.array(shape.vertex_positions_buffer()).reshape(-1, 3)
            faces = np.array(shape.faces_buffer()).reshape(-1, 3)
            mesh = bpy.data.meshes.new(f"mesh{k}")
            mesh.from_pydata(pos.tolist(), [], faces.tolist())
            obj = bpy.data.objects.new(f"obj{k}", mesh)
            scene.collection.objects.link(obj)
        else:
            m = np.array(mi.traverse(shape)["to_world"].matrix)
            bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=float(m[0, 0]),
                                                 location=tuple(float(x) for x in m[:3, 3]))
            bpy.ops.object.shade_smooth()
            obj = bpy.context.object
        obj.data.materials.append(material_of(shape, k))
    sensor = s.sensors()[0]
    cam_data = bpy.data.cameras.new("camera")
    cam_data.angle = math.radians(float(np.ravel(mi.traverse(sensor)["x_fov"])[0]))
    cam = bpy.data.objects.new("camera", cam_data)
    flip = np.diag([-1.0, 1.0, -1.0, 1.0])  # Mitsuba's camera looks along +z with +x to the left
    cam.matrix_world = (np.array(sensor.world_transform().matrix) @ flip).T.tolist()
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Strength"].default_value = 0.0
    for e in s.emitters():
        params = mi.traverse(e)
        if "radiance.value" in params and str(e).startswith("Constant"):
            background.inputs["Color"].default_value = (*[float(x) for x in np.ravel(params["radiance.value"])], 1.0)
            background.inputs["Strength"].default_value = 1.0
        elif str(e).startswith("EnvironmentMapEmitter"):
            tex = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
            tex.image = bpy.data.images.load(os.path.join(os.path.dirname(path), "data/sky.exr"))
            world.node_tree.links.new(tex.outputs["Color"], background.inputs["Color"])
            background.inputs["Strength"].default_value = 1.0
    scene.world = world
    return scene


def render(scene, out, spp, res=256):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device, c.samples, c.use_adaptive_sampling, c.use_denoising = "CPU", spp, False, False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = 7
    c.caustics_reflective = c.caustics_refractive = True
    c.blur_glossy, c.sample_clamp_direct, c.sample_clamp_indirect = 0.0, 0.0, 0.0
    c.pixel_filter_type, c.filter_width = "BOX", 1.0
    scene.render.threads_mode, scene.render.threads = "FIXED", 2
    scene.render.resolution_x = scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = out
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("names", nargs="*", default=["cornell-box", "glossy", "envmap", "million"])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    tmp = tempfile.mkdtemp()
    print(f"| scene | alhazen | Cycles | alhazen/Cycles |\n|---|---|---|---|")
    for name in a.names:
        path = suite.SCENES[name]
        scene = build(path)
        render(scene, f"{tmp}/{name}-warm.exr", 1)  # Cycles' kernels loaded once
        pairs = [(suite.alhazen_run(path, a.spp, f"{tmp}/{name}.exr"), render(scene, f"{tmp}/{name}.exr", a.spp))
                 for _ in range(a.runs)]
        ours, cycles = (float(np.median(t)) for t in zip(*pairs))
        print(f"| {name} | {ours:.3f} s | {cycles:.3f} s | **{ours / cycles:.2f}** |", flush=True)


if __name__ == "__main__":
    main()
