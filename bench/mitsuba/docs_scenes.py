#!/usr/bin/env python3
"""Mitsuba 3's own documentation scenes, rendered by alhazen and by Mitsuba, compared block by
block: the scenes users of Mitsuba have, with `<path>`, `<include>`, `serialized` meshes,
forward references and every BSDF of the docs' material preview.

    python3 bench/mitsuba/docs_scenes.py DATA [--spp 64] [--blocks 8x6] [NAME…]

DATA is a checkout of github.com/mitsuba-renderer/mitsuba-data (its `docs/scenes` and
`common` folders). Each scene is rendered as its file says (`$spp` and the like from
`--spp`) by `alhazen render` and by Mitsuba `llvm_ad_rgb`; the table gives each image's mean,
their relative difference and the worst block's, and alhazen's warnings (what it
approximated) by count. Scenes with polarisation, hair, curves, SDF grids or media test what
alhazen does not model and are listed apart.

Needs `pip install mitsuba numpy`, `apt-get install libllvm19`.
"""
import argparse, os, subprocess, sys, tempfile

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.environ.get("ALHAZEN", os.path.join(ROOT, "target/release/alhazen"))
UNMODELLED = ("polarized", "polarizer", "stokes", "pplastic", "hair", "curve", "sdfgrid", "medium", "aov",
              "measured")


def load(path):
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))[..., :3]


def blocks(img, bx, by):
    h, w = img.shape[0] // by * by, img.shape[1] // bx * bx
    return img[:h, :w].reshape(by, h // by, bx, w // bx, 3).mean(axis=(1, 3))


def compare(a, m, bx, by):
    ba, bm = blocks(a, bx, by).mean(axis=2), blocks(m, bx, by).mean(axis=2)
    scale = max(bm.mean(), 1e-6)
    worst = np.abs(ba - bm).max() / scale
    return a.mean(), m.mean(), (a.mean() - m.mean()) / scale, worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data")
    ap.add_argument("names", nargs="*")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--blocks", default="8x6")
    args = ap.parse_intermixed_args()
    bx, by = map(int, args.blocks.split("x"))
    folder = os.path.join(args.data, "docs", "scenes")
    names = args.names or sorted(f[:-4] for f in os.listdir(folder) if f.endswith(".xml"))
    mi.set_variant("llvm_ad_rgb")
    tmp = tempfile.mkdtemp()
    print(f"{args.spp} spp; block = {bx}×{by} grid; differences relative to Mitsuba's mean\n")
    print("| scene | alhazen mean | Mitsuba mean | mean diff | worst block | alhazen warnings |")
    print("|---|---|---|---|---|---|")
    for name in names:
        path = os.path.join(folder, name + ".xml")
        ours = os.path.join(tmp, name + ".exr")
        # `$spp` set from the command line where a file leaves it without a default (as
        # Mitsuba's documentation renders them); every scene at `--spp` either way.
        needs_spp = "$spp" in open(path).read() and '<default name="spp"' not in open(path).read()
        define = ["-D", f"spp={args.spp}"] if needs_spp else []
        run = subprocess.run([EXE, "render", path, "--spp", str(args.spp), "-o", ours, *define], capture_output=True,
                             text=True, cwd=folder)
        warnings = [l for l in run.stderr.splitlines() if l.startswith("warning:")]
        if run.returncode != 0:
            err = next((l for l in run.stderr.splitlines() if l.startswith("error")), run.stderr[-200:])
            print(f"| {name} | error | | | | {err} |")
            continue
        try:
            try:
                scene = mi.load_file(path, spp=args.spp)
            except Exception as e:  # noqa: BLE001 (a file whose sample count is fixed)
                if "unused parameters" not in str(e):
                    raise
                scene = mi.load_file(path)
            theirs = np.array(mi.render(scene, spp=args.spp))[..., :3]
        except Exception as e:  # noqa: BLE001 (a scene Mitsuba cannot load is reported, not fatal)
            print(f"| {name} | rendered | Mitsuba failed: {str(e).splitlines()[0][:80]} | | | |")
            continue
        a = load(ours)
        if a.shape != theirs.shape:
            print(f"| {name} | {a.shape} | {theirs.shape} | size differs | | |")
            continue
        am, mm, d, worst = compare(a, theirs, bx, by)
        kinds = sorted({w.split(": ", 2)[-1][:60] for w in warnings})
        tag = " (unmodelled)" if any(u in name for u in UNMODELLED) else ""
        print(f"| {name}{tag} | {am:.4f} | {mm:.4f} | {d:+.1%} | {worst:.1%} | {len(warnings)}: {'; '.join(kinds)[:160]} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
