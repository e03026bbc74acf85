#!/usr/bin/env python3
"""Mitsuba 3 side of the Cornell box comparison and benchmark.

    python3 bench/mitsuba/cornell.py reference OUT.exr [--spp 4096] [--scene cornell|rough]
    python3 bench/mitsuba/cornell.py time [--spp 64] [--variant llvm_ad_rgb] [--scene ...]

The scene is `mitsuba.cornell_box()` with one change: the film's reconstruction filter is a box
(alhazen averages samples per pixel with a box filter). `--scene rough` replaces the two boxes by
a rough gold sphere and a rough glass sphere (scenes/cornell-rough.toml).
Needs `pip install mitsuba`; the llvm variants need libLLVM (apt-get install libllvm19 and
DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so).
"""
import argparse, os, sys, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import mitsuba as mi


def scene_dict(kind, spp):
    d = mi.cornell_box()
    d["sensor"]["film"]["rfilter"] = {"type": "box"}
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": spp}
    if kind == "rough":
        del d["large-box"], d["small-box"]
        T = mi.ScalarTransform4f
        d["gold-sphere"] = {
            "type": "sphere", "center": [-0.4, -0.6, -0.25], "radius": 0.4,
            "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2,
                     "eta": {"type": "rgb", "value": [0.143119, 0.374957, 1.44248]},
                     "k": {"type": "rgb", "value": [3.98316, 2.38572, 1.60322]}},
        }
        d["glass-sphere"] = {
            "type": "sphere", "center": [0.45, -0.65, 0.3], "radius": 0.35,
            "bsdf": {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.15,
                     "int_ior": 1.5, "ext_ior": 1.0},
        }
    return d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["reference", "time"])
    ap.add_argument("out", nargs="?")
    ap.add_argument("--spp", type=int, default=None)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--scene", default="cornell", choices=["cornell", "rough"])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    mi.set_variant(a.variant)
    if a.mode == "reference":
        spp = a.spp or 4096
        scene = mi.load_dict(scene_dict(a.scene, spp))
        # Render in passes of 256 spp with different seeds and average (memory stays small).
        passes = max(1, spp // 256)
        acc = None
        for i in range(passes):
            img = mi.render(scene, spp=min(spp, 256), seed=1000 + i)
            arr = mi.TensorXf(img).numpy() if hasattr(img, "numpy") else img
            import numpy as np
            arr = np.array(img)
            acc = arr if acc is None else acc + arr
            print(f"pass {i + 1}/{passes}", file=sys.stderr)
        acc /= passes
        mi.Bitmap(acc).write(a.out)
    else:
        spp = a.spp or 64
        scene = mi.load_dict(scene_dict(a.scene, spp))
        img = mi.render(scene, spp=spp)  # warm-up: JIT compilation excluded
        import drjit as dr
        dr.eval(img)
        times = []
        for i in range(a.repeat):
            t0 = time.perf_counter()
            img = mi.render(scene, spp=spp, seed=i + 1)
            dr.eval(img)
            _ = float(dr.sum(dr.ravel(img))[0]) if hasattr(dr, "ravel") else None
            times.append(time.perf_counter() - t0)
        print(f"{a.variant} {a.scene} {spp} spp: best {min(times):.3f} s, median {sorted(times)[len(times)//2]:.3f} s")


if __name__ == "__main__":
    main()
