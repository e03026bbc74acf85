#!/usr/bin/env python3
"""Mitsuba 3's particle tracer as the independent reference for caustics through mirrors.

    python3 bench/mitsuba/caustic_ptracer.py OUT.exr [--spp 16384] [--scene scenes/mitsuba/cup-caustic.xml]

Loads the Mitsuba XML twin (the same file alhazen imports), replaces its integrator by `ptracer`
(light paths from the lamp, connected to the camera at every diffuse vertex) with the file's
max_depth, and renders it. The particle tracer finds light reflected by a mirror onto a diffuse
surface naturally, with no knowledge of the mirror's shape: an estimate independent of alhazen's
specular connections. It cannot see through mirrors, so only pixels showing diffuse surfaces
directly are comparable (the cup scene is seen from above for that reason).

Needs `pip install mitsuba`; the llvm variant needs libLLVM (apt-get install libllvm19).
"""
import argparse, os, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import mitsuba as mi


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("--scene", default="scenes/mitsuba/cup-caustic.xml")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--depth", type=int, default=3)
    a = ap.parse_args()
    mi.set_variant(a.variant)
    scene = mi.load_file(a.scene)
    integrator = mi.load_dict({"type": "ptracer", "max_depth": a.depth, "hide_emitters": False})
    start = time.perf_counter()
    # Several passes of at most 4096 samples keep the JIT's memory bounded.
    passes, left, total = [], a.spp, None
    seed = 0
    while left > 0:
        spp = min(left, 4096)
        img = mi.render(scene, integrator=integrator, spp=spp, seed=seed)
        import numpy as np
        arr = np.array(img) * spp
        total = arr if total is None else total + arr
        left -= spp
        seed += 1
    total /= a.spp
    mi.util.write_bitmap(a.out, mi.TensorXf(total.astype("float32")))
    print(f"{a.scene}: ptracer {a.spp} spp in {time.perf_counter() - start:.1f} s -> {a.out}")


if __name__ == "__main__":
    main()
