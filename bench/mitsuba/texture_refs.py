#!/usr/bin/env python3
"""Test scenes of textures read per point, and their Mitsuba 3 references (`scalar_rgb`'s
`path` integrator), for crates/alhazen-import/tests/mitsuba.rs:

- textured-emitter: a rectangle whose radiance is a bitmap of eight colours, tilted to face
  both a diffuse floor and the camera, so that the image shows the texture read where rays hit
  the light and where the floor's light samples land on it (test
  `a_textured_emitter_agrees_with_mitsuba`);
- principled-maps: a `principled` floor whose roughness (0.8 left, 0.15 right) and metallic
  (1 on one half, 0 on the other) are bitmaps, under a sky and a small tilted light (test
  `principled_maps_agree_with_mitsuba`);
- turned-texture: a rectangle light whose radiance is a smoothly repeating image of waves
  (red along u, green along v, blue along the diagonal) placed by a `to_uv` of a scale, a
  rotation and a translation, seen directly (test `a_turned_texture_agrees_with_mitsuba`);
- masked-card: a card of round holes (a `mask` whose opacity is a bitmap, 0 in the holes and
  1 elsewhere, around a two-sided diffuse BSDF) under a small light, dappling the floor (test
  `a_masked_card_agrees_with_mitsuba`). Mitsuba's shadow rays stop at a mask, so its floor's
  light under the card comes from paths through the holes alone and converges slowly: its
  reference takes four times the samples;
- vertex-colors: a PLY panel of 12 × 12 quads (triangulated) whose vertices carry float
  `red`, `green`, `blue` colours, a diffuse BSDF whose reflectance is the `mesh_attribute`
  `vertex_color`, under a constant white sky (radiance 1): facing the camera, the panel shows
  its interpolated colours themselves (test `vertex_colors_agree_with_mitsuba`).

    python3 bench/mitsuba/texture_refs.py [--spp 8192] [--only NAME]

Writes each scene's XML, its PNGs and NAME-mitsuba.exr into
crates/alhazen-import/tests/data/mitsuba/.
"""
import argparse, os
import numpy as np
import mitsuba as mi

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "crates", "alhazen-import", "tests",
                   "data", "mitsuba")


def write_reference(name, scene, spp, seed):
    """Writes OUT/NAME.xml (`scene`) and Mitsuba 3's image of it at `spp` (`scalar_rgb`, seed
    `seed`) as OUT/NAME-mitsuba.exr."""
    mi.set_variant("scalar_rgb")
    path = os.path.join(OUT, f"{name}.xml")
    with open(path, "w") as f:
        f.write(scene)
    img = mi.render(mi.load_file(path), spp=spp, seed=seed)
    mi.Bitmap(img).write(os.path.join(OUT, f"{name}-mitsuba.exr"))
    print(f"wrote {path} and its reference ({spp} spp)")


def head(what, depth, fov, origin, target, size=(96, 72), integrator="path", script="texture_refs.py"):
    """A scene file's opening: its comment, the integrator, a camera of `size` pixels."""
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- {what} (bench/mitsuba/{script}). -->
<scene version="3.0.0">
    <integrator type="{integrator}"><integer name="max_depth" value="{depth}"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="{fov}"/>
        <transform name="to_world"><lookat origin="{origin}" target="{target}" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="{size[0]}"/><integer name="height" value="{size[1]}"/>
            <rfilter type="box"/><string name="pixel_format" value="rgb"/>
        </film>
    </sensor>
"""


SCENE = head("A rectangle light whose radiance is a bitmap", 4, 50, "0, 1.1, 3.2", "0, 0.45, 0") + """    <shape type="rectangle">
        <transform name="to_world">
            <scale x="0.9" y="0.5" z="1"/>
            <rotate x="1" angle="60"/>
            <translate x="0" y="1.0" z="0"/>
        </transform>
        <emitter type="area">
            <texture name="radiance" type="bitmap">
                <string name="filename" value="textured-emitter.png"/>
                <string name="filter_type" value="bilinear"/>
            </texture>
        </emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale x="2" y="2" z="2"/>
            <rotate x="1" angle="-90"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.6, 0.6"/></bsdf>
    </shape>
</scene>
"""


PRINCIPLED = head("A principled floor with roughness and metallic maps", 6, 40, "0, 1.2, 3.2", "0, 0, 0") + """    <emitter type="constant"><rgb name="radiance" value="0.3, 0.3, 0.3"/></emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale x="0.6" y="0.3" z="1"/><rotate x="1" angle="150"/><translate x="0" y="1.3" z="-1.2"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="20, 18, 15"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="1.2"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="principled">
            <rgb name="base_color" value="0.79, 0.40, 0.045"/>
            <texture name="roughness" type="bitmap">
                <string name="filename" value="principled-roughness.png"/><boolean name="raw" value="true"/>
            </texture>
            <texture name="metallic" type="bitmap">
                <string name="filename" value="principled-metallic.png"/><boolean name="raw" value="true"/>
            </texture>
        </bsdf>
    </shape>
</scene>
"""


def principled(spp):
    grey = lambda a: a[..., None].repeat(3, 2)
    rough = np.zeros((64, 64), np.uint8)
    rough[:, :32], rough[:, 32:] = 204, 38
    metal = np.zeros((64, 64), np.uint8)
    metal[:32, :] = 255
    mi.Bitmap(grey(rough)).write(os.path.join(OUT, "principled-roughness.png"))
    mi.Bitmap(grey(metal)).write(os.path.join(OUT, "principled-metallic.png"))
    path = os.path.join(OUT, "principled-maps.xml")
    with open(path, "w") as f:
        f.write(PRINCIPLED)
    img = mi.render(mi.load_file(path), spp=spp, seed=3)
    mi.Bitmap(img).write(os.path.join(OUT, "principled-maps-mitsuba.exr"))


MASKED = head("A card of round holes (a mask) over a floor", 8, 40, "0, 2, 5", "0, 0.3, 0") + """    <emitter type="constant"><rgb name="radiance" value="0.05, 0.06, 0.08"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate x="0" y="3" z="-0.3"/></transform>
        <emitter type="area"><rgb name="radiance" value="20, 19, 17"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.8"/><rotate x="1" angle="-75"/><translate x="0" y="1.4" z="0"/></transform>
        <bsdf type="mask">
            <texture name="opacity" type="bitmap">
                <string name="filename" value="masked-card.png"/><boolean name="raw" value="true"/>
            </texture>
            <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.6, 0.15"/></bsdf></bsdf>
        </bsdf>
    </shape>
</scene>
"""


def masked(spp):
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    cx, cy = (x // 8) * 8 + 3.5, (y // 8) * 8 + 3.5
    holes = np.where((x - cx) ** 2 + (y - cy) ** 2 <= 9.0, 0, 255).astype(np.uint8)
    mi.Bitmap(holes[..., None], pixel_format=mi.Bitmap.PixelFormat.Y).write(os.path.join(OUT, "masked-card.png"))
    path = os.path.join(OUT, "masked-card.xml")
    with open(path, "w") as f:
        f.write(MASKED)
    img = mi.render(mi.load_file(path), spp=4 * spp, seed=5)
    mi.Bitmap(img).write(os.path.join(OUT, "masked-card-mitsuba.exr"))


TURNED = head("A rectangle light whose radiance image is scaled, turned and moved by to_uv", 1, 25, "0, 0, 4",
              "0, 0, 0", (64, 64)) + """    <shape type="rectangle">
        <emitter type="area">
            <texture name="radiance" type="bitmap">
                <string name="filename" value="turned-texture.png"/>
                <transform name="to_uv"><scale x="1.5" y="0.75"/><rotate z="1" angle="30"/><translate x="0.15" y="0.3"/></transform>
            </texture>
        </emitter>
    </shape>
</scene>
"""


def turned(spp):
    n, t = 32, 2 * np.pi / 32
    x, y = np.meshgrid(np.arange(n), np.arange(n))
    waves = np.stack([0.5 + 0.4 * np.sin(t * x), 0.5 + 0.4 * np.sin(t * y + 1.0), 0.5 + 0.4 * np.cos(t * (x + y))], -1)
    mi.Bitmap((waves * 255 + 0.5).astype(np.uint8), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        os.path.join(OUT, "turned-texture.png"))
    path = os.path.join(OUT, "turned-texture.xml")
    with open(path, "w") as f:
        f.write(TURNED)
    img = mi.render(mi.load_file(path), spp=spp, seed=9)
    mi.Bitmap(img).write(os.path.join(OUT, "turned-texture-mitsuba.exr"))


VERTEX_COLORS = head("A diffuse panel coloured by its PLY vertex colours under a white sky", 2, 25, "0, 0, 4",
                     "0, 0, 0", (64, 64)) + """    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
    <shape type="ply">
        <string name="filename" value="vertex-colors.ply"/>
        <bsdf type="diffuse">
            <texture name="reflectance" type="mesh_attribute"><string name="name" value="vertex_color"/></texture>
        </bsdf>
    </shape>
</scene>
"""


def vertex_colors(spp):
    """The panel as an ASCII PLY: (x, y) in [−1, 1]², z = 0, facing +z; colours varying
    smoothly from vertex to vertex (red along x, green along y, blue along the diagonal)."""
    cuts = 12
    xs = np.linspace(-1.0, 1.0, cuts + 1)
    verts = [(x, y) for y in xs for x in xs]
    paint = lambda x, y: (0.5 + 0.4 * np.sin(2.0 * x), 0.5 + 0.4 * np.sin(1.7 * y + 0.5), 0.5 + 0.4 * np.cos(1.3 * (x + y)))
    faces = []
    for j in range(cuts):
        for i in range(cuts):
            a, b, c, d = j * (cuts + 1) + i, j * (cuts + 1) + i + 1, (j + 1) * (cuts + 1) + i + 1, (j + 1) * (cuts + 1) + i
            faces += [(a, b, c), (a, c, d)]
    lines = ["ply", "format ascii 1.0", f"element vertex {len(verts)}", "property float x", "property float y",
             "property float z", "property float red", "property float green", "property float blue",
             f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    lines += [f"{x:.6f} {y:.6f} 0 " + " ".join(f"{c:.6f}" for c in paint(x, y)) for x, y in verts]
    lines += [f"3 {a} {b} {c}" for a, b, c in faces]
    with open(os.path.join(OUT, "vertex-colors.ply"), "w") as f:
        f.write("\n".join(lines) + "\n")
    path = os.path.join(OUT, "vertex-colors.xml")
    with open(path, "w") as f:
        f.write(VERTEX_COLORS)
    img = mi.render(mi.load_file(path), spp=spp, seed=11)
    mi.Bitmap(img).write(os.path.join(OUT, "vertex-colors-mitsuba.exr"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--only", choices=["textured-emitter", "principled-maps", "masked-card", "turned-texture",
                                       "vertex-colors"])
    args = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    mi.set_variant("scalar_rgb")
    if args.only == "masked-card":
        return masked(args.spp)
    if args.only == "turned-texture":
        return turned(args.spp)
    if args.only == "vertex-colors":
        return vertex_colors(args.spp)
    if args.only == "principled-maps":
        return principled(args.spp)
    # Eight colours, four across and two down, each well apart from its neighbours.
    colours = np.array([
        [[255, 40, 40], [40, 255, 40], [40, 40, 255], [255, 255, 255]],
        [[255, 255, 40], [40, 255, 255], [255, 40, 255], [90, 90, 90]],
    ], dtype=np.uint8)
    mi.set_variant("scalar_rgb")
    mi.Bitmap(colours, pixel_format=mi.Bitmap.PixelFormat.RGB).write(os.path.join(OUT, "textured-emitter.png"))
    path = os.path.join(OUT, "textured-emitter.xml")
    with open(path, "w") as f:
        f.write(SCENE)
    scene = mi.load_file(path)
    img = mi.render(scene, spp=args.spp, seed=7)
    mi.Bitmap(img).write(os.path.join(OUT, "textured-emitter-mitsuba.exr"))
    if args.only is None:
        principled(args.spp)
        masked(args.spp)
        turned(args.spp)
        vertex_colors(args.spp)


if __name__ == "__main__":
    main()
