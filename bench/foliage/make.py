#!/usr/bin/env python3
"""A tree crown of leaf cards: the scene users bring that is mostly holes. Writes OUT/leaves.obj
(N cards, two triangles each, scattered in a ball, turned at random, texture coordinates
0–1), OUT/leaf.png (a leaf's outline in the alpha channel, 128 × 128) and OUT/foliage.toml (the
crown on a trunk over a floor, under a sky and a sun; `alpha = { image = …, cutoff = 0.5 }`).

    python3 bench/foliage/make.py OUT [--cards 20000]
    alhazen render OUT/foliage.toml --spp 16

Used to time cut-out meshes (BENCHMARKS.md, session 46). Needs numpy and mitsuba (for the PNG).
"""
import argparse, math, os
import numpy as np


def leaf_png(path, n=128):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n
    # A pointed oval along the diagonal, with a stem.
    u, v = (x + y) / math.sqrt(2) - 0.2, (x - y) / math.sqrt(2)
    inside = (u > 0) & (u < 1.0) & (np.abs(v) < 0.32 * np.sin(np.pi * np.clip(u, 0, 1)) ** 0.8)
    stem = (np.abs(v) < 0.015) & (u > -0.15) & (u <= 0)
    alpha = np.where(inside | stem, 255, 0).astype(np.uint8)
    rgba = np.stack([np.full_like(alpha, 60), np.full_like(alpha, 140), np.full_like(alpha, 40), alpha], -1)
    mi.Bitmap(rgba, pixel_format=mi.Bitmap.PixelFormat.RGBA).write(path)


def leaves_obj(path, cards, seed=7):
    rng = np.random.default_rng(seed)
    with open(path, "w") as f:
        f.write("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n")
        for k in range(cards):
            d = rng.normal(size=3)
            c = np.array([0, 2.2, 0]) + d / np.linalg.norm(d) * 1.4 * rng.random() ** (1 / 3)
            a, b = rng.normal(size=3), rng.normal(size=3)
            a /= np.linalg.norm(a)
            b -= a * a.dot(b)
            b /= np.linalg.norm(b)
            s = 0.12
            for p in (c - s * a - s * b, c + s * a - s * b, c + s * a + s * b, c - s * a + s * b):
                f.write(f"v {p[0]:.5f} {p[1]:.5f} {p[2]:.5f}\n")
            i = 4 * k + 1
            f.write(f"f {i}/1 {i + 1}/2 {i + 2}/3\nf {i}/1 {i + 2}/3 {i + 3}/4\n")


SCENE = """# A tree crown of {cards} leaf cards cut out by the alpha of leaf.png (bench/foliage/make.py).
background = {{ zenith = [0.25, 0.4, 0.8], horizon = [0.8, 0.85, 0.9] }}

[render]
width = 320
height = 240
spp = 16
max_depth = 6
integrator = "path"

[camera]
eye = [0, 2.0, 7]
target = [0, 1.8, 0]
fov = 45

[[light]]
type = "directional"
direction = [-0.4, -1, -0.3]
intensity = 2.5

[meshes.leaves]
file = "leaves.obj"

[materials.leaf]
color = {{ image = {{ file = "leaf.png" }} }}
alpha = {{ image = {{ file = "leaf.png" }}, cutoff = 0.5 }}

[materials.bark]
color = [0.25, 0.17, 0.1]

[materials.ground]
color = [0.45, 0.42, 0.35]

[[object]]
shape = "plane"
material = "ground"

[[object]]
shape = "cylinder"
base = [0, 0, 0]
top = [0, 1.6, 0]
radius = 0.12
material = "bark"

[[object]]
shape = "mesh"
mesh = "leaves"
material = "leaf"
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--cards", type=int, default=20000)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    leaf_png(os.path.join(a.out, "leaf.png"))
    leaves_obj(os.path.join(a.out, "leaves.obj"), a.cards)
    with open(os.path.join(a.out, "foliage.toml"), "w") as f:
        f.write(SCENE.format(cards=a.cards))


if __name__ == "__main__":
    main()
