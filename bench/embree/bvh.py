#!/usr/bin/env python3
"""Issue 18's BVH benchmark: alhazen's world against Embree 4 (embreex) on the same mesh and the
same incoherent rays.

    python3 bench/mitsuba/suite/make_data.py     # the 1,001,108-triangle displaced sphere (once)
    python3 bench/embree/bvh.py [--rays 1000000] [--threads 1] [--build sah|morton]

Rays: origins uniform in a ball of radius 3 around the mesh's centre (outside and inside it),
directions towards points uniform in its bounding box: every ray starts somewhere else and
heads somewhere else (incoherent, like a path tracer's secondary rays); a fixed seed.
Build: Embree's `rtcCommit` (the scene created and the mesh attached outside the timing), ours
`World::build` (the PLY already loaded). Throughput: best of three passes each. The hit
distances are compared, so both trace the same rays to the same surfaces.

Needs `pip install embreex numpy`. embreex traces one ray at a time on the calling thread
(its loop is in Cython), so `--threads 1` is the like-for-like comparison.
"""
import argparse, os, subprocess, sys, tempfile, time
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MESH = os.path.join(ROOT, "bench/mitsuba/suite/data/displaced-1m.ply")


def read_ply(path):
    """Positions and triangles of a binary little-endian PLY with float x y z first and
    uchar-counted uint faces (what make_data.py writes)."""
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.readline()
        lines = header.decode().splitlines()
        nv = int(next(l for l in lines if l.startswith("element vertex")).split()[-1])
        nf = int(next(l for l in lines if l.startswith("element face")).split()[-1])
        props = sum(1 for l in lines[lines.index(next(l for l in lines if l.startswith("element vertex"))):]
                    if l.startswith("property float"))
        verts = np.frombuffer(f.read(nv * props * 4), dtype="<f4").reshape(nv, props)[:, :3]
        faces = np.frombuffer(f.read(nf * 13), dtype=[("n", "u1"), ("i", "<u4", 3)])["i"]
    return verts.astype(np.float32), faces.astype(np.int64)


def make_rays(verts, n, seed=18):
    rng = np.random.default_rng(seed)
    lo, hi = verts.min(0), verts.max(0)
    centre = (lo + hi) / 2
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = centre + d * 3.0 * rng.random((n, 1)) ** (1 / 3)
    targets = lo + (hi - lo) * rng.random((n, 3))
    dirs = targets - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return origins.astype(np.float32), dirs.astype(np.float32)


def embree(verts, tris, origins, dirs):
    from embreex import rtcore_scene, mesh_construction
    scene = rtcore_scene.EmbreeScene()
    mesh_construction.TriangleMesh(scene, verts[tris])
    t0 = time.perf_counter()
    scene.run(origins[:1], dirs[:1])  # commits: builds the BVH
    build = time.perf_counter() - t0
    best, out = float("inf"), None
    for _ in range(3):
        t0 = time.perf_counter()
        out = scene.run(origins, dirs, output=1)
        best = min(best, time.perf_counter() - t0)
    t = np.where(out["geomID"] >= 0, out["tfar"], np.inf)
    return build, best, t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--build", choices=["sah", "morton"], default="sah",
                    help="how alhazen builds the mesh's BVH (Embree builds its own)")
    a = ap.parse_args()
    if not os.path.exists(MESH):
        sys.exit(f"{MESH} is missing: run python3 bench/mitsuba/suite/make_data.py")
    verts, tris = read_ply(MESH)
    origins, dirs = make_rays(verts, a.rays)
    tmp = tempfile.mkdtemp()
    rays_bin, hits_bin = os.path.join(tmp, "rays.bin"), os.path.join(tmp, "hits.bin")
    np.concatenate([origins, dirs], 1).astype("<f4").tofile(rays_bin)
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "alhazen-render", "--example", "trace_rays"],
                   cwd=ROOT, check=True)
    exe = os.path.join(ROOT, "target/release/examples/trace_rays")
    ours = subprocess.run([exe, MESH, rays_bin, hits_bin, str(a.threads), a.build], check=True, capture_output=True,
                          text=True).stdout.strip()
    print(ours)
    t_ours = np.fromfile(hits_bin, dtype="<f4")
    build, best, t_embree = embree(verts, tris, origins, dirs)
    print(f"embree:  {len(tris)} triangles, build {build:.3f} s, {a.rays} rays "
          f"({int(np.isfinite(t_embree).sum())} hit) in {best:.3f} s: {a.rays / best / 1e6:.2f} Mrays/s on 1 thread")
    both = np.isfinite(t_ours) & np.isfinite(t_embree)
    disagree = (np.isfinite(t_ours) != np.isfinite(t_embree)).sum()
    rel = np.abs(t_ours[both] - t_embree[both]) / np.maximum(t_embree[both], 1e-6)
    print(f"agreement: {disagree} rays hit in one and not the other; distances within "
          f"{np.percentile(rel, 99.9):.2e} (99.9th percentile), {rel.max():.2e} (max) relative")


if __name__ == "__main__":
    main()
