#!/usr/bin/env python3
"""Generates the data files the suite's scenes read (textures, an environment map, meshes) into
bench/mitsuba/suite/data/, which git ignores. Deterministic: the same bytes on every run.

    python3 bench/mitsuba/suite/make_data.py

Needs numpy and mitsuba (its Bitmap writes the PNG and EXR files).
"""
import os, sys
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data")


def bitmap(arr, path, srgb):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    if path.endswith(".png"):
        b = mi.Bitmap(np.ascontiguousarray((np.clip(arr, 0, 1) * 255 + 0.5).astype(np.uint8)), mi.Bitmap.PixelFormat.RGB)
        b.set_srgb_gamma(srgb)
    else:
        b = mi.Bitmap(np.ascontiguousarray(arr.astype(np.float32)), mi.Bitmap.PixelFormat.RGB)
    b.write(path)


def wood(n=512):
    """Rings and grain in sRGB: an image texture with detail at every scale."""
    y, x = np.mgrid[0:n, 0:n] / n
    r = np.sqrt((x - 0.3) ** 2 * 4 + (y - 0.6) ** 2) * 24 + 1.5 * np.sin(9 * x + 4 * y)
    t = 0.5 + 0.5 * np.sin(r * np.pi)
    grain = 0.5 + 0.5 * np.sin(173 * y + 11 * np.sin(23 * x))
    base = np.stack([0.55 + 0.25 * t, 0.33 + 0.15 * t, 0.15 + 0.07 * t], -1)
    return base * (0.85 + 0.15 * grain[..., None])


def tile_normals(n=256, tiles=8):
    """A normal map of rounded tiles (tangent space, raw values in [0, 1])."""
    y, x = np.mgrid[0:n, 0:n] / n * tiles
    fx, fy = x % 1 - 0.5, y % 1 - 0.5
    dx = np.where(np.abs(fx) > 0.4, np.sign(fx) * 0.8, 0.0)
    dy = np.where(np.abs(fy) > 0.4, np.sign(fy) * 0.8, 0.0)
    nrm = np.stack([-dx, -dy, np.ones_like(dx)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    return nrm * 0.5 + 0.5


def sky(w=512, h=256):
    """A latitude–longitude sky: blue gradient above, brown ground below, a small bright sun."""
    v, u = (np.mgrid[0:h, 0:w] + 0.5) / np.array([h, w])[:, None, None]
    theta, phi = v * np.pi, u * 2 * np.pi
    d = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), np.sin(theta) * np.sin(phi)], -1)
    up = np.clip(d[..., 1], 0, 1)[..., None]
    img = np.where(d[..., 1:2] > 0, (1 - up) * [0.9, 0.95, 1.1] + up * [0.25, 0.45, 1.0], [0.25, 0.18, 0.12])
    sun = np.array([0.4, 0.6, 0.3]) / np.linalg.norm([0.4, 0.6, 0.3])
    img = img + (d @ sun > 0.995)[..., None] * [400.0, 360.0, 300.0]
    return img


def write_ply(path, pos, tris, normals=None, uv=None):
    props = "property float x\nproperty float y\nproperty float z\n"
    cols = [pos]
    if normals is not None:
        props += "property float nx\nproperty float ny\nproperty float nz\n"
        cols.append(normals)
    if uv is not None:
        props += "property float u\nproperty float v\n"
        cols.append(uv)
    verts = np.concatenate(cols, 1).astype("<f4")
    faces = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<u4", 3)])
    faces["n"], faces["i"] = 3, tris
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(pos)}\n{props}"
                f"element face {len(tris)}\nproperty list uchar uint vertex_indices\nend_header\n".encode())
        f.write(verts.tobytes())
        f.write(faces.tobytes())


def grid_sphere(nu, nv, radius):
    """A latitude–longitude sphere (poles as rings of tiny quads), radius a function of direction."""
    u = np.linspace(0, 1, nu + 1)
    v = np.linspace(1e-4, 1 - 1e-4, nv + 1)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    phi, theta = uu * 2 * np.pi, vv * np.pi
    d = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), -np.sin(theta) * np.sin(phi)], -1)
    pos = d * radius(d)[..., None]
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b, c, e = i * (nv + 1) + j, (i + 1) * (nv + 1) + j, (i + 1) * (nv + 1) + j + 1, i * (nv + 1) + j + 1
    tris = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([a, e, c], -1).reshape(-1, 3)])
    uv = np.stack([uu, 1 - vv], -1).reshape(-1, 2)
    return pos.reshape(-1, 3), d.reshape(-1, 3), uv, tris.astype(np.uint32)


def main():
    os.makedirs(DATA, exist_ok=True)
    bitmap(wood(), os.path.join(DATA, "wood.png"), True)
    bitmap(tile_normals(), os.path.join(DATA, "tiles-normal.png"), False)
    bitmap(sky(), os.path.join(DATA, "sky.exr"), False)
    pos, nrm, uv, tris = grid_sphere(96, 48, lambda d: np.ones(d.shape[:-1]))
    write_ply(os.path.join(DATA, "uv-sphere.ply"), pos, tris, nrm, uv)
    # 708 × 706 quads → 999,696 triangles plus rings: ≥ 1 M triangles of a displaced sphere.
    bumpy = lambda d: 1 + 0.06 * np.sin(17 * d[..., 0]) * np.sin(19 * d[..., 1]) * np.sin(23 * d[..., 2])
    pos, _, _, tris = grid_sphere(709, 706, bumpy)
    write_ply(os.path.join(DATA, "displaced-1m.ply"), pos, tris)
    print(f"wrote {DATA}: displaced-1m.ply has {len(tris):,} triangles", file=sys.stderr)


if __name__ == "__main__":
    main()
