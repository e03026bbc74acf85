#!/usr/bin/env python3
"""How the path tracer's light samples choose among several lights (`--light-choice`), measured:
per scene, the noise of each choice at equal samples against a converged image, and its time.

    python3 bench/lights/choice.py [--spp 32] [--seeds 3] [--ref-spp 4096] [SCENE…]

Per scene (default: this folder's XML scenes and the shipped scenes with several lights), at
160 × 120 with the path tracer and the Sobol sampler: the reference is alhazen's own image at
`--ref-spp` with lights chosen uniformly (every choice converges to the same image, so any
serves; a reference from the choice under test would favour it by nothing but noise), then each
choice renders `--spp` samples with seeds 1 to `--seeds`: RMSE and mean relative error against
the reference (means over the seeds), and the median wall time of those renders.
Needs numpy. `ALHAZEN=path/to/alhazen` picks the binary (default target/release/alhazen).
"""
import argparse, glob, os, subprocess, sys, tempfile, time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXE = os.environ.get("ALHAZEN", os.path.join(ROOT, "target/release/alhazen"))
CHOICES = ["uniform", "power", "measured"]
SHIPPED = ["haas-haus", "teapot", "glass-balls", "geometric-design", "nurbs-design"]


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3 if kind == b"PF" else 1)[::-1].astype(np.float64)


def render(scene, out, spp, seed, choice):
    args = [EXE, "render", scene, "-o", out, "--integrator", "path", "--sampler", "sobol", "--width", "160",
            "--height", "120", "--spp", str(spp), "--seed", str(seed), "--light-choice", choice, "--quiet"]
    t = time.perf_counter()
    subprocess.run(args, check=True)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("scenes", nargs="*")
    a = ap.parse_args()
    scenes = a.scenes or sorted(glob.glob(os.path.join(HERE, "*.xml"))) + [
        os.path.join(ROOT, "scenes", f"{s}.toml") for s in SHIPPED]
    print(f"| scene | {' | '.join(f'{c}: RMSE / mean rel. / time' for c in CHOICES)} |")
    print(f"|---|{'---|' * len(CHOICES)}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            ref_path = f"{tmp}/ref.pfm"
            render(scene, ref_path, a.ref_spp, 1000, "uniform")
            ref = read_pfm(ref_path)
            cells = []
            for choice in CHOICES:
                errs, times = [], []
                for seed in range(1, a.seeds + 1):
                    times.append(render(scene, f"{tmp}/img.pfm", a.spp, seed, choice))
                    img = read_pfm(f"{tmp}/img.pfm")
                    rmse = np.sqrt(((img - ref) ** 2).mean())
                    rel = (np.abs(img - ref) / np.maximum(ref, 1e-2)).mean()
                    errs.append((rmse, rel))
                rmse, rel = np.mean(errs, axis=0)
                cells.append(f"{rmse:.4f} / {rel:.4f} / {np.median(times):.2f} s")
            name = os.path.relpath(scene, ROOT)
            print(f"| {name} | {' | '.join(cells)} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
