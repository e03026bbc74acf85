#!/usr/bin/env python3
"""Blender's side of the glTF validation (issue 20): build a scene with Blender's Python module,
export it as glTF 2.0 with Blender's own exporter, and render it with Cycles as the reference.

    python3 bench/blender/gltf_vs_cycles.py OUT_DIR [--spp 4096] [--size 160x120] [--maps | --emission | --alpha]

writes OUT_DIR/materials.glb (what a Blender user would hand alhazen) and
OUT_DIR/materials-cycles.exr (Cycles, CPU, 2 threads, box pixel filter of one pixel, no
denoiser, no adaptive sampling, light paths up to 8 bounces, no caustic filtering).
`--maps` (session 43) gives the sphere a metallic–roughness map instead of its constant
metal — one image, non-colour, its green channel to Roughness and blue to Metallic through a
Separate Color node, which Blender's exporter writes as `metallicRoughnessTexture`: metal on
the upper half of the texture, dielectric below, in eight stripes along u alternately rougher
(0.4) and smoother (0.1) — and names the files materials-maps.glb and
materials-maps-cycles.exr. (Rougher maps part the two renderers by Cycles' multiple-scattering
GGX: a uniform roughness of 0.7 renders the metal 31 % brighter in red there, with or without a
map, where single-scattering microfacets — ours, Mitsuba's — lose that light.)
`--emission` (session 44) stands a panel behind the sphere whose Emission Color is an image of
four stripes (red, green, blue, white, strength 6), exported as `emissiveTexture` with
`KHR_materials_emissive_strength`, on a thin black slab that takes the light of its back (Cycles
emits from both sides of a surface, glTF's importers from the front), and names the files
materials-emission.glb and materials-emission-cycles.exr (test
`blender_emissive_texture_agrees_with_cycles`; Cycles 4096 spp in 94 s).
`--alpha` (session 46) stands a card of leaves between the light and the cube: a green
Principled BSDF whose Alpha is the alpha channel of a 64 × 64 image of round holes (eight by
eight discs of radius 3 texels cut out of an opaque card, bilinear), linked straight to the
Alpha socket, which Blender's exporter writes as `alphaMode: BLEND`; the card and the holes'
shadow on the cube and floor test cut-outs for camera and shadow rays alike; files
materials-alpha.glb and materials-alpha-cycles.exr (test `blender_alpha_cut_out_agrees_with_cycles`).
Needs `pip install bpy`. The committed copies live in crates/alhazen-import/tests/data/blender/
and the test `blender_gltf_agrees_with_cycles` compares alhazen's image of the .glb with the EXR.
"""
import argparse, math, os, sys, time

import bpy


def material(name, color, metallic, roughness):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    return m


def mapped_material(name, color, path):
    """`color` with Roughness and Metallic read from a 64×64 map written to `path`."""
    n = 64
    img = bpy.data.images.new("metallic-roughness", n, n, alpha=False)
    pixels = []
    for y in range(n):  # Blender's rows run bottom to top, as texture v does
        for x in range(n):
            pixels += [0.0, 0.4 if (x // 8) % 2 == 0 else 0.1, 1.0 if y >= n // 2 else 0.0, 1.0]
    img.pixels = pixels
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    img.colorspace_settings.name = "Non-Color"
    m = material(name, color, 0.0, 0.5)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Linear"
    split = nodes.new("ShaderNodeSeparateColor")
    links.new(tex.outputs["Color"], split.inputs["Color"])
    p = nodes["Principled BSDF"]
    links.new(split.outputs["Green"], p.inputs["Roughness"])
    links.new(split.outputs["Blue"], p.inputs["Metallic"])
    p.inputs["Roughness"].default_value = 1.0
    p.inputs["Metallic"].default_value = 1.0
    return m


def saved_image(name, n, pixel, path, alpha=False):
    """An n × n image whose pixel (x, y) (rows bottom to top) is `pixel(x, y)` (RGBA), saved
    as a PNG at `path`."""
    img = bpy.data.images.new(name, n, n, alpha=alpha)
    img.pixels = [c for y in range(n) for x in range(n) for c in pixel(x, y)]
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    return img


def image_node(m, img):
    """A bilinear image texture node of `img` in material `m`, and `m`'s Principled BSDF."""
    tex = m.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Linear"
    return tex, m.node_tree.nodes["Principled BSDF"]


def emissive_panel(path):
    """A 2.4 × 1.2 panel above the cube and sphere facing the camera, glowing with four stripes read from an image
    written to `path`, on a black slab that absorbs what its back emits."""
    n = 32
    stripes = [(1.0, 0.05, 0.05), (0.05, 1.0, 0.05), (0.05, 0.05, 1.0), (1.0, 1.0, 1.0)]
    img = saved_image("stripes", n, lambda x, y: (*stripes[x * 4 // n], 1.0), path)
    m = material("panel", (0.0, 0.0, 0.0), 0.0, 1.0)
    tex, p = image_node(m, img)
    m.node_tree.links.new(tex.outputs["Color"], p.inputs["Emission Color"])
    p.inputs["Emission Strength"].default_value = 6.0
    bpy.ops.mesh.primitive_plane_add(size=1, location=(0.0, 2.2, 2.7), rotation=(math.radians(90), 0, 0))
    bpy.context.object.scale = (2.4, 1.2, 1.0)
    bpy.context.object.data.materials.append(m)
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0.0, 2.26, 2.7))
    bpy.context.object.scale = (2.5, 0.1, 1.3)
    bpy.context.object.data.materials.append(material("slab", (0.0, 0.0, 0.0), 0.0, 1.0))


def leaf_card(path):
    """A 1.6 × 1.6 card standing between the light and the cube, green, with round holes read
    from the alpha channel of an image written to `path`."""
    def pixel(x, y):
        cx, cy = (x // 8) * 8 + 3.5, (y // 8) * 8 + 3.5
        return (0.2, 0.6, 0.15, 0.0 if (x - cx) ** 2 + (y - cy) ** 2 <= 9.0 else 1.0)

    img = saved_image("holes", 64, pixel, path, alpha=True)
    m = material("leaves", (0.2, 0.6, 0.15), 0.0, 0.8)
    tex, p = image_node(m, img)
    m.node_tree.links.new(tex.outputs["Color"], p.inputs["Base Color"])
    m.node_tree.links.new(tex.outputs["Alpha"], p.inputs["Alpha"])
    bpy.ops.mesh.primitive_plane_add(size=1.6, location=(-0.6, -1.6, 2.4), rotation=(math.radians(70), 0, math.radians(10)))
    bpy.context.object.data.materials.append(m)


def build(maps_path=None, panel_path=None, card_path=None):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    bpy.context.object.data.materials.append(material("floor", (0.6, 0.6, 0.6), 0.0, 1.0))
    bpy.ops.mesh.primitive_cube_add(size=2, location=(-1.4, 0.3, 1), rotation=(0, 0, math.radians(25)))
    bpy.context.object.data.materials.append(material("red", (0.7, 0.08, 0.06), 0.0, 0.6))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=1, location=(1.3, -0.2, 1))
    bpy.ops.object.shade_smooth()
    gold = (1.0, 0.77, 0.34)
    if maps_path:
        bpy.context.object.data.materials.append(mapped_material("gold", gold, maps_path))
    else:
        bpy.context.object.data.materials.append(material("gold", gold, 1.0, 0.35))
    if panel_path:
        emissive_panel(panel_path)
    if card_path:
        leaf_card(card_path)
    bpy.ops.object.light_add(type="POINT", location=(1.5, -3.5, 5.0))
    light = bpy.context.object.data
    light.energy = 1500.0
    light.shadow_soft_size = 0.0
    bpy.ops.object.camera_add(location=(0.3, -8.5, 3.6))
    cam = bpy.context.object
    direction = [0.0 - 0.3, 0.0 + 8.5, 0.9 - 3.6]
    cam.rotation_euler = (math.atan2(math.hypot(direction[0], direction[1]), -direction[2]), 0, math.atan2(direction[0], direction[1]) * -1)
    cam.data.lens = 35
    cam.data.sensor_fit = "HORIZONTAL"
    scene.camera = cam
    black_world(scene)
    return scene


def front_camera(scene, fov_degrees):
    """A camera 4 units in front of the origin (at y = −4, looking along +y), `fov_degrees`
    across the image's width, and a black world: the view of panels standing in the plane
    y = 0."""
    bpy.ops.object.camera_add(location=(0.0, -4.0, 0.0), rotation=(math.radians(90), 0, 0))
    cam = bpy.context.object
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.angle = math.radians(fov_degrees)
    scene.camera = cam
    black_world(scene)


def export_and_render_emission(scene, out, stem, size, spp, pixel_filter=("BOX", 1.0)):
    """Writes OUT/STEM.glb (Blender's glTF exporter, with cameras) and OUT/STEM-cycles.exr:
    Cycles without bounces (what emitters show directly), 32-bit, through `pixel_filter`."""
    export_and_render(scene, out, stem, size, spp, bounces=0, pixel_filter=pixel_filter)


def export_and_render(scene, out, stem, size, spp, bounces, pixel_filter=("BOX", 1.0), glb=True, **export_options):
    """Writes OUT/STEM.glb (Blender's glTF exporter, with cameras and lights and any other
    `export_options`; left out when not `glb`) and OUT/STEM-cycles.exr: Cycles with `bounces`,
    32-bit, through `pixel_filter`."""
    os.makedirs(out, exist_ok=True)
    scene.render.resolution_x, scene.render.resolution_y = size
    if glb:
        bpy.ops.export_scene.gltf(filepath=os.path.join(out, f"{stem}.glb"), export_format="GLB",
                                  export_cameras=True, export_lights=True, export_yup=True, **export_options)
    seconds = render(scene, os.path.join(out, f"{stem}-cycles.exr"), spp, size, bounces=bounces, transparent=0,
                     depth="32", pixel_filter=pixel_filter)
    print(f"Cycles: {spp} spp at {size[0]}x{size[1]} on 2 threads in {seconds:.2f} s", file=sys.stderr)


def facing_panel(scene, m, fov_degrees=25):
    """A 2 × 2 panel of material `m` standing in the plane y = 0, facing the camera of
    `front_camera(scene, fov_degrees)`."""
    bpy.ops.mesh.primitive_plane_add(size=2, location=(0.0, 0.0, 0.0), rotation=(math.radians(90), 0, 0))
    bpy.context.object.data.materials.append(m)
    front_camera(scene, fov_degrees)


def white_world(scene):
    """A uniform white world of strength 1: the sky alhazen gives a glTF without lights."""
    world = scene.world.node_tree.nodes["Background"]
    world.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    world.inputs["Strength"].default_value = 1.0


def sun(rotation_degrees, energy=3.0):
    """A sun of `energy` W/m², of no angular size, turned by `rotation_degrees` (Euler XYZ)."""
    bpy.ops.object.light_add(type="SUN", rotation=tuple(math.radians(a) for a in rotation_degrees))
    bpy.context.object.data.energy = energy
    bpy.context.object.data.angle = 0.0


def mapped(m, tex):
    """Feeds image node `tex` of material `m` the UV coordinates through a Mapping node of
    location (0.15, 0.3), rotation 30° and scale (1.5, 0.75)."""
    nodes, links = m.node_tree.nodes, m.node_tree.links
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.inputs["Location"].default_value = (0.15, 0.3, 0.0)
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(30))
    mapping.inputs["Scale"].default_value = (1.5, 0.75, 1.0)
    links.new(coords.outputs["UV"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], tex.inputs["Vector"])


def floor_under_sun(scene, eye, tilt_degrees, fov_degrees):
    """A grey floor (10 × 10 at z = 0), a camera at `eye` looking along +y tilted down to
    `tilt_degrees` from the vertical with `fov_degrees` across, a sun of 3 W/m² from the side
    and above, and a black world."""
    bpy.ops.mesh.primitive_plane_add(size=10, location=(0, 0, 0))
    bpy.context.object.data.materials.append(material("floor", (0.6, 0.6, 0.6), 0.0, 0.8))
    bpy.ops.object.camera_add(location=eye, rotation=(math.radians(tilt_degrees), 0, 0))
    scene.camera = bpy.context.object
    scene.camera.data.angle = math.radians(fov_degrees)
    sun((40, 10, 30), energy=3.0)
    black_world(scene)


def main_of(stem, build, size=(96, 64), **export_options):
    """The command line of a comparison script: OUT_DIR [--spp 1024], `build()`'s scene
    written as OUT_DIR/STEM.glb and rendered by Cycles at `size` with four bounces."""
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    a = ap.parse_args()
    export_and_render(build(), os.path.abspath(a.out), stem, size, a.spp, bounces=4, **export_options)


def black_world(scene):
    """No light from the world: what a glTF file, which has no world, holds."""
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world


def render(scene, path, spp, size, bounces=8, transparent=8, depth="16", pixel_filter=("BOX", 1.0)):
    """Renders `scene` with Cycles (CPU, 2 threads, `pixel_filter` — by default the box of one
    pixel —, no denoiser, no adaptive sampling, `bounces` of every kind, `transparent`
    transparent bounces) to the EXR `path` of `depth` bits; returns the seconds
    `bpy.ops.render.render` took."""
    w, h = size
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    c = scene.cycles
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = transparent
    scene.cycles.caustics_reflective = True
    scene.cycles.caustics_refractive = True
    scene.cycles.blur_glossy = 0.0
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.pixel_filter_type, scene.cycles.filter_width = pixel_filter
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 2
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = depth
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--maps", action="store_true")
    ap.add_argument("--emission", action="store_true")
    ap.add_argument("--alpha", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    stem = ("materials-maps" if a.maps else "materials-emission" if a.emission
            else "materials-alpha" if a.alpha else "materials")
    out = os.path.abspath(a.out)
    scene = build(os.path.join(out, "metallic-roughness.png") if a.maps else None,
                  os.path.join(out, "stripes.png") if a.emission else None,
                  os.path.join(out, "holes.png") if a.alpha else None)
    size = tuple(int(x) for x in a.size.split("x"))
    scene.render.resolution_x, scene.render.resolution_y = size
    glb = os.path.join(a.out, f"{stem}.glb")
    bpy.ops.export_scene.gltf(filepath=glb, export_format="GLB", export_lights=True, export_cameras=True, export_yup=True)
    seconds = render(scene, os.path.join(os.path.abspath(a.out), f"{stem}-cycles.exr"), a.spp, size)
    print(f"Cycles: {a.spp} spp at {size[0]}x{size[1]} on 2 threads in {seconds:.2f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
