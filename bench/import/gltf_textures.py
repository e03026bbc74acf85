#!/usr/bin/env python3
"""Loading a textured glTF as Blender exports one: two quads, each material with a base colour
texture (times a factor), a normal map and a metallic-roughness map, all SIZE² 8-bit PNGs.

    python3 bench/import/gltf_textures.py [--size 2048] [--runs 3] [--dir /tmp/alhazen-gltf-textures]
                                          [--exe target/release/alhazen ...]

Writes the scene once (the PNGs with Python's zlib: smooth patterns plus noise, so they
compress as photographs do, between noise and flat colour), then times, alternating the
binaries given, the whole `alhazen render scene.gltf --width 8 --height 8 --spp 1` process
(reading, decoding six images, an 8×8 render) and its peak resident memory (/usr/bin/time).
Prints the median of the runs per binary. Needs numpy.
"""
import argparse, json, os, statistics, struct, subprocess, zlib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def png(path, rgb):
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def write_scene(d, n):
    rng = np.random.default_rng(1)
    y, x = np.mgrid[0:n, 0:n] / n
    as_bytes = lambda a: (np.clip(a, 0, 1) * 255).astype(np.uint8)
    for k in range(2):
        base = np.stack([0.5 + 0.5 * np.sin(20 * x + k), 0.5 + 0.5 * np.cos(13 * y), 0.5 + 0.3 * np.sin(7 * (x + y))], -1)
        png(f"{d}/base{k}.png", as_bytes(base + rng.normal(0, 0.05, base.shape)))
        normal = np.stack([0.5 + 0.1 * np.sin(40 * x), 0.5 + 0.1 * np.cos(40 * y), np.ones_like(x)], -1)
        png(f"{d}/normal{k}.png", as_bytes(normal + rng.normal(0, 0.02, normal.shape)))
        png(f"{d}/mr{k}.png", as_bytes(np.stack([np.zeros_like(x), 0.3 + 0.2 * np.sin(9 * x), 0.5 + 0.5 * np.sin(5 * y)], -1)))
    pos = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32)
    nor = np.array([[0, 1, 0]] * 4, np.float32)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    idx = np.array([0, 2, 1, 0, 3, 2], np.uint16)
    blob = pos.tobytes() + nor.tobytes() + uv.tobytes() + idx.tobytes()
    with open(f"{d}/quad.bin", "wb") as f:
        f.write(blob)
    views = [dict(buffer=0, byteOffset=o, byteLength=l) for o, l in ((0, 48), (48, 48), (96, 32), (128, 12))]
    accessors = [
        dict(bufferView=0, componentType=5126, count=4, type="VEC3", min=[-1, 0, -1], max=[1, 0, 1]),
        dict(bufferView=1, componentType=5126, count=4, type="VEC3"),
        dict(bufferView=2, componentType=5126, count=4, type="VEC2"),
        dict(bufferView=3, componentType=5123, count=6, type="SCALAR"),
    ]
    images, textures, materials, meshes, nodes = [], [], [], [], []
    for k in range(2):
        for name in ("base", "normal", "mr"):
            images.append(dict(uri=f"{name}{k}.png"))
            textures.append(dict(source=len(images) - 1))
        t = 3 * k
        pbr = dict(baseColorTexture=dict(index=t), baseColorFactor=[0.9, 0.8, 0.7, 1],
                   metallicRoughnessTexture=dict(index=t + 2), metallicFactor=0.0)
        materials.append(dict(name=f"m{k}", pbrMetallicRoughness=pbr, normalTexture=dict(index=t + 1)))
        meshes.append(dict(primitives=[dict(attributes=dict(POSITION=0, NORMAL=1, TEXCOORD_0=2), indices=3, material=k)]))
        nodes.append(dict(mesh=k, translation=[2.2 * k - 1.1, 0, 0]))
    nodes.append(dict(camera=0, translation=[0, 3, 4], rotation=[-0.3826834, 0, 0, 0.9238795]))
    nodes.append(dict(extensions=dict(KHR_lights_punctual=dict(light=0)), rotation=[-0.5, 0, 0, 0.8660254]))
    gltf = dict(
        asset=dict(version="2.0"), scene=0, scenes=[dict(nodes=list(range(len(nodes))))], nodes=nodes,
        meshes=meshes, materials=materials, textures=textures, images=images,
        buffers=[dict(uri="quad.bin", byteLength=len(blob))], bufferViews=views, accessors=accessors,
        cameras=[dict(type="perspective", perspective=dict(yfov=0.8, znear=0.1))],
        extensionsUsed=["KHR_lights_punctual"],
        extensions=dict(KHR_lights_punctual=dict(lights=[dict(type="directional", intensity=3)])),
    )
    with open(f"{d}/scene.gltf", "w") as f:
        json.dump(gltf, f)


def run(exe, scene, out):
    cmd = ["/usr/bin/time", "-f", "%e %M", exe, "render", scene, "-o", out, "--width", "8", "--height", "8",
           "--spp", "1", "--quiet"]
    done = subprocess.run(cmd, check=True, stderr=subprocess.PIPE, text=True)
    wall, kb = done.stderr.strip().splitlines()[-1].split()
    return float(wall), int(kb) / 1024


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=2048)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/alhazen-gltf-textures")
    ap.add_argument("--exe", action="append")
    a = ap.parse_args()
    exes = a.exe or [os.path.join(ROOT, "target", "release", "alhazen")]
    os.makedirs(a.dir, exist_ok=True)
    scene = os.path.join(a.dir, "scene.gltf")
    write_scene(a.dir, a.size)
    times = {e: [] for e in exes}
    for _ in range(a.runs):
        for e in exes:
            times[e].append(run(e, scene, os.path.join(a.dir, "out.exr")))
    print(f"six {a.size}² 8-bit textures, medians of {a.runs}")
    print("| binary | whole process | peak memory |\n|---|---|---|")
    for e, ts in times.items():
        print(f"| {e} | {statistics.median(t for t, _ in ts):.2f} s | {statistics.median(m for _, m in ts):.0f} MB |")


if __name__ == "__main__":
    main()
