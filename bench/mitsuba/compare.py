#!/usr/bin/env python3
"""Issue 4's benchmark: alhazen's path tracer against Mitsuba 3 on the Cornell box, 256×256,
depth 8, on this machine's cores, in one run.

    python3 bench/mitsuba/compare.py [--runs 3] [--spp 64]

1. Equal samples: median wall time of `alhazen render scenes/cornell-box.toml` (whole process:
   parse, build, render, write EXR) against Mitsuba `llvm_ad_rgb` and `scalar_rgb` renders timed
   after one warm-up render (so LLVM's JIT compilation is excluded); alhazen and llvm runs
   alternate, so a drift in the machine's speed affects both alike.
2. Equal time: alhazen re-renders with the largest sample count whose render (median of 3) fits
   in Mitsuba llvm's time, and
   both images are compared with the 16384-spp Mitsuba reference committed in
   crates/alhazen-render/tests/data/mitsuba/cornell-box.exr (RMSE and mean relative error).

Needs `pip install mitsuba numpy`, `apt-get install libllvm19`.
"""
import argparse, os, subprocess, sys, tempfile, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import cornell  # noqa: E402
import suite  # noqa: E402

REF = os.path.join(ROOT, "crates/alhazen-render/tests/data/mitsuba/cornell-box.exr")


def load(path):
    return np.array(mi.Bitmap(path))[..., :3].astype(np.float64)


def errors(img, ref):
    rmse = float(np.sqrt(((img - ref) ** 2).mean()))
    rel = float((np.abs(img - ref) / np.maximum(ref, 1e-2)).mean())
    return rmse, rel


def alhazen_run(spp, out):
    """Wall time of one whole `alhazen render` process."""
    exe = os.path.join(ROOT, "target/release/alhazen")
    suite.settle()
    t0 = time.perf_counter()
    subprocess.run([exe, "render", os.path.join(ROOT, "scenes/cornell-box.toml"), "-o", out,
                    "--spp", str(spp), "--quiet"], check=True)
    return time.perf_counter() - t0


def time_alhazen(spp, out, runs):
    return float(np.median([alhazen_run(spp, out) for _ in range(runs)]))


def mitsuba_renderer(variant, spp, out):
    """A function timing one Mitsuba render of the Cornell box (the suite's timer)."""
    mi.set_variant(variant)  # the scene dict is built with the variant's types
    return suite.mitsuba_renderer(variant, cornell.scene_dict("cornell", spp), spp, out)


def time_mitsuba(variant, spp, out, runs):
    run = mitsuba_renderer(variant, spp, out)
    return float(np.median([run() for _ in range(runs)]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    a = ap.parse_args()
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=ROOT, check=True)
    tmp = tempfile.mkdtemp()
    ref = None
    # alhazen and Mitsuba llvm alternate, so a drift of this VM's speed hits both alike.
    llvm = mitsuba_renderer("llvm_ad_rgb", a.spp, f"{tmp}/llvm.exr")
    pairs = [(alhazen_run(a.spp, f"{tmp}/ours.exr"), llvm()) for _ in range(a.runs)]
    t_ours, t_llvm = (float(np.median(ts)) for ts in zip(*pairs))
    t_scalar = time_mitsuba("scalar_rgb", a.spp, f"{tmp}/scalar.exr", max(1, a.runs // 2))
    ref = load(REF)
    print(f"Cornell box 256x256, {a.spp} spp, max depth 8, {os.cpu_count()} cores")
    print(f"  alhazen (sobol)        {t_ours:7.3f} s")
    print(f"  mitsuba llvm_ad_rgb    {t_llvm:7.3f} s   ratio alhazen/llvm   = {t_ours / t_llvm:.2f}")
    print(f"  mitsuba scalar_rgb     {t_scalar:7.3f} s   ratio alhazen/scalar = {t_ours / t_scalar:.2f}")
    # Equal time: the most samples whose render (median of 3) fits in llvm's time, searched from
    # the estimate the 64-spp time gives.
    spp_eq = max(1, int(a.spp * t_llvm / t_ours))
    t_eq = time_alhazen(spp_eq, f"{tmp}/ours_eq.exr", 3)
    while t_eq > t_llvm and spp_eq > 1:
        spp_eq -= 1
        t_eq = time_alhazen(spp_eq, f"{tmp}/ours_eq.exr", 3)
    while True:
        t_next = time_alhazen(spp_eq + 1, f"{tmp}/ours_next.exr", 3)
        print(f"  equal-time search: {spp_eq} spp {t_eq:.3f} s, {spp_eq + 1} spp {t_next:.3f} s")
        if t_next > t_llvm:
            break
        spp_eq, t_eq = spp_eq + 1, t_next
        os.replace(f"{tmp}/ours_next.exr", f"{tmp}/ours_eq.exr")
    for name, path in [(f"alhazen {a.spp} spp", f"{tmp}/ours.exr"), (f"alhazen {spp_eq} spp ({t_eq:.2f} s)", f"{tmp}/ours_eq.exr"),
                       (f"mitsuba llvm {a.spp} spp ({t_llvm:.2f} s)", f"{tmp}/llvm.exr")]:
        rmse, rel = errors(load(path), ref)
        print(f"  error vs 16k-spp reference: {name:34s} RMSE {rmse:.5f}  mean rel {rel:.4f}")


if __name__ == "__main__":
    main()
