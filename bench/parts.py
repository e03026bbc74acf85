#!/usr/bin/env python3
"""Exact pixel sums and film parts: what they cost (BENCHMARKS.md, "Renders in parts").

    python3 bench/parts.py sum OLD_BINARY [--runs 5]   # the exact pixel sum: before vs now, a suite
    python3 bench/parts.py split [--runs 3]            # one render vs bands/passes + merge

`sum` alternates OLD_BINARY (built from a commit before exact sums, e.g. 97fe7bc) and
target/release/alhazen, minimum of the runs, 2 threads, and reports the largest change of a
pixel (relative to the image's mean) — rounding once instead of at every sample.
`split` times `render` against the same render made as 4 bands of tiles or 4 passes of samples
(run one after the other) plus `alhazen merge`, checks the bytes are the same, and reports the
parts' sizes. Needs numpy.
"""
import argparse, glob, os, subprocess, tempfile, time

from connections import pfm  # the PFM reader the other benchmark scripts use

NEW = "target/release/alhazen"
SUITE = [("cornell-box", ["--integrator", "path", "--spp", "64"]),
         ("cornell-rough", ["--spp", "16"]),
         ("prism", ["--spp", "4"]),
         ("teapot", []),
         ("five-glass-balls", []),
         ("glass-balls", ["--width", "1920", "--height", "1080", "--spp", "1"]),
         ("haas-haus", [])]

# Passes split samples in blocks of 8: every scene here has at least 32 spp.
SPLIT = [("cornell-box", ["--integrator", "path", "--spp", "64"]),
         ("cornell-rough", ["--spp", "32"]),
         ("prism", ["--spp", "32"]),
         ("glass-balls", ["--width", "640", "--height", "480", "--spp", "32"])]


def timed(binary, args):
    t = time.perf_counter()
    subprocess.run([binary, *args], check=True)
    return time.perf_counter() - t


def sums(old, runs):
    import numpy as np
    print("| scene | before (s) | now (s) | ratio | largest pixel change / image mean |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for name, extra in SUITE:
            a, b = [], []
            pa, pb = os.path.join(d, "a.pfm"), os.path.join(d, "b.pfm")
            for _ in range(runs):
                a.append(timed(old, ["render", f"scenes/{name}.toml", *extra, "-o", pa, "-q"]))
                b.append(timed(NEW, ["render", f"scenes/{name}.toml", *extra, "-o", pb, "-q"]))
            x, y = pfm(pa).astype(np.float64), pfm(pb).astype(np.float64)
            change = np.abs(x - y).max() / max(x.mean(), 1e-30)
            print(f"| {name} {' '.join(extra)} | {min(a):.3f} | {min(b):.3f} | {min(b) / min(a):.3f} | {change:.1e} |")


def split(runs):
    print("| scene | one render (s) | 4 bands + merge (s) | 4 passes + merge (s) | same bytes | bands / passes on disk (MiB) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for name, extra in SPLIT:
            scene = [f"scenes/{name}.toml", *extra, "-q"]
            one, bands, passes = [], [], []
            for _ in range(runs):
                one.append(timed(NEW, ["render", *scene, "-o", f"{d}/one.exr"]))
                for kind, times in (("tile", bands), ("pass", passes)):
                    t = sum(timed(NEW, ["render", *scene, f"--{kind}", f"{i}/4", "-o", f"{d}/{kind}{i}.film"]) for i in range(4))
                    t += timed(NEW, ["merge", *sorted(glob.glob(f"{d}/{kind}*.film")), "-o", f"{d}/{kind}.exr", "-q"])
                    times.append(t)
            same = all(open(f"{d}/{k}.exr", "rb").read() == open(f"{d}/one.exr", "rb").read() for k in ("tile", "pass"))
            size = lambda k: sum(os.path.getsize(p) for p in glob.glob(f"{d}/{k}*.film")) / 2**20
            print(f"| {name} {' '.join(extra)} | {min(one):.3f} | {min(bands):.3f} | {min(passes):.3f} | {same} | {size('tile'):.1f} / {size('pass'):.1f} |")


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("sum")
    s.add_argument("old")
    s.add_argument("--runs", type=int, default=5)
    t = sub.add_parser("split")
    t.add_argument("--runs", type=int, default=3)
    a = p.parse_args()
    sums(a.old, a.runs) if a.cmd == "sum" else split(a.runs)
