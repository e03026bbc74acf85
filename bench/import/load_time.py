#!/usr/bin/env python3
"""Loading a million-triangle mesh: alhazen against Mitsuba 3 (issue 20, "Speed").

    python3 bench/import/load_time.py [--triangles 1000000] [--runs 3] [--dir /tmp/alhazen-load]

Writes a displaced torus of about N triangles as binary PLY and as binary glTF (.glb), and the
scene around it in alhazen TOML, Mitsuba XML and pbrt; then times, alternating the runs:
  * alhazen: the whole `alhazen render SCENE --width 8 --height 8 --spp 1` process (read, parse,
    BVH build, an 8×8 render, exit), per format;
  * Mitsuba 3: `mi.load_file(scene.xml)` in a warm Python process (parse and acceleration
    structure), scalar_rgb and llvm_ad_rgb;
and the peak resident memory of each (a separate process, /usr/bin/time -v).
Needs numpy and mitsuba (`pip install mitsuba numpy`; llvm: `apt-get install libllvm19`).
"""
import argparse, json, os, struct, subprocess, sys, time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ALHAZEN = os.path.join(ROOT, "target", "release", "alhazen")
LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"


def torus(n_tri):
    nu = int(round((n_tri / 2 / 0.5) ** 0.5))
    nv = max(3, n_tri // (2 * nu))
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    r = 0.35 * (1 + 0.08 * np.sin(9 * uu) * np.sin(13 * vv))
    x = (1 + r * np.cos(vv)) * np.cos(uu)
    z = (1 + r * np.cos(vv)) * np.sin(uu)
    y = r * np.sin(vv)
    pos = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * nv + j)
    b = (((i + 1) % nu) * nv + j)
    c = (((i + 1) % nu) * nv + (j + 1) % nv)
    d = (i * nv + (j + 1) % nv)
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]).astype(np.uint32)
    return pos, tris


def write_ply(path, pos, tris):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(pos)}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {len(tris)}\nproperty list uchar uint vertex_indices\nend_header\n".encode())
        f.write(pos.tobytes())
        faces = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<u4", 3)])
        faces["n"] = 3
        faces["i"] = tris
        f.write(faces.tobytes())


def write_glb(path, pos, tris):
    bin_ = pos.tobytes() + tris.tobytes()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 1.2, 3.2], "rotation": [-0.1822355, 0, 0, 0.9832549]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(bin_)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos.nbytes},
                        {"buffer": 0, "byteOffset": pos.nbytes, "byteLength": tris.nbytes}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
                       "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
                      {"bufferView": 1, "componentType": 5125, "count": tris.size, "type": "SCALAR"}],
    }
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    bin_ += b"\0" * (-len(bin_) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(j) + 8 + len(bin_)))
        f.write(struct.pack("<I4s", len(j), b"JSON") + j)
        f.write(struct.pack("<I4s", len(bin_), b"BIN\0") + bin_)


def write_scenes(d):
    open(os.path.join(d, "mesh.toml"), "w").write(
        '[camera]\neye = [0, 1.2, 3.2]\ntarget = [0, 0, 0]\nfov = 40\n[[light]]\ntype = "point"\nposition = [2, 4, 3]\n'
        '[[object]]\nshape = "mesh"\nfile = "mesh.ply"\n')
    open(os.path.join(d, "mesh.xml"), "w").write(
        '<scene version="3.0.0"><integrator type="path"/><sensor type="perspective"><float name="fov" value="40"/>'
        '<transform name="to_world"><lookat origin="0,1.2,3.2" target="0,0,0" up="0,1,0"/></transform>'
        '<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>'
        '<emitter type="point"><point name="position" x="2" y="4" z="3"/></emitter>'
        '<shape type="ply"><string name="filename" value="mesh.ply"/></shape></scene>')
    open(os.path.join(d, "mesh.pbrt"), "w").write(
        'Scale -1 1 1\nLookAt 0 1.2 3.2 0 0 0 0 1 0\nCamera "perspective" "float fov" 40\nWorldBegin\n'
        'LightSource "point" "point3 from" [2 4 3]\nShape "plymesh" "string filename" "mesh.ply"\n')


def alhazen_once(scene):
    t0 = time.perf_counter()
    subprocess.run([ALHAZEN, "render", scene, "-o", "/tmp/alhazen-load.exr", "--width", "8", "--height", "8", "--spp", "1", "-q"], check=True)
    return time.perf_counter() - t0


def peak_rss(cmd):
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True, check=True)
    for line in r.stderr.splitlines():
        if "Maximum resident set size" in line:
            return int(line.split()[-1]) / 1024
    return float("nan")


MITSUBA_CHILD = r'''
import os, sys, time
os.environ.setdefault("DRJIT_LIBLLVM_PATH", "{llvm}")
import mitsuba as mi
mi.set_variant(sys.argv[1])
times = []
for _ in range(int(sys.argv[3])):
    t0 = time.perf_counter(); s = mi.load_file(sys.argv[2]); times.append(time.perf_counter() - t0); del s
print(min(times))
'''


def mitsuba(variant, xml, runs):
    code = MITSUBA_CHILD.format(llvm=LLVM)
    r = subprocess.run([sys.executable, "-c", code, variant, xml, str(runs)], capture_output=True, text=True)
    if r.returncode != 0:
        return float("nan"), r.stderr.strip().splitlines()[-1:]
    return float(r.stdout.strip().splitlines()[-1]), peak_rss([sys.executable, "-c", code, variant, xml, "1"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/alhazen-load")
    a = ap.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    pos, tris = torus(a.triangles)
    write_ply(os.path.join(a.dir, "mesh.ply"), pos, tris)
    write_glb(os.path.join(a.dir, "mesh.glb"), pos, tris)
    write_scenes(a.dir)
    print(f"mesh: {len(tris)} triangles, {len(pos)} vertices; PLY {os.path.getsize(os.path.join(a.dir, 'mesh.ply')) / 2**20:.1f} MiB")
    scenes = ["mesh.toml", "mesh.glb", "mesh.xml", "mesh.pbrt"]
    best = {s: float("inf") for s in scenes}
    for _ in range(a.runs):
        for s in scenes:
            best[s] = min(best[s], alhazen_once(os.path.join(a.dir, s)))
    for s in scenes:
        rss = peak_rss([ALHAZEN, "render", os.path.join(a.dir, s), "-o", "/tmp/alhazen-load.exr", "--width", "8", "--height", "8", "--spp", "1", "-q"])
        print(f"alhazen {s:10s}: {best[s]:.3f} s (process: read, parse, BVH, 8x8 render), peak {rss:.0f} MiB")
    for variant in ["scalar_rgb", "llvm_ad_rgb"]:
        t, rss = mitsuba(variant, os.path.join(a.dir, "mesh.xml"), a.runs)
        print(f"Mitsuba 3 {variant:11s}: {t:.3f} s (mi.load_file), peak {rss} MiB")


if __name__ == "__main__":
    main()
