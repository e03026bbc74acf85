#!/usr/bin/env python3
"""Specular connections: what they cost and what they buy (BENCHMARKS.md, "Specular connections").

    python3 bench/connections.py speed OLD_BINARY [--runs 5]   # scenes without mirrors: before vs now
    python3 bench/connections.py cost [--runs 3]               # scenes with mirrors: on vs off
    python3 bench/connections.py error [--seconds 4]           # equal-time error on caustic scenes

`speed` alternates OLD_BINARY (built from a commit before the connections) and
target/release/alhazen on scenes that have no connected mirror, and checks the images are
identical. `error` renders scenes/mitsuba/cup-caustic.xml with and without connections for the
same time and measures RMSE and mean relative error over the table inside the cup against Mitsuba
3's particle tracer (crates/alhazen-render/tests/data/mitsuba/cup-caustic-ptracer.exr, made by
bench/mitsuba/caustic_ptracer.py); for the delta-light scenes (coffee-cup, chrome-ball-caustic)
it reports how much light the path tracer without connections misses.
Needs numpy; `error` needs mitsuba (pip install mitsuba) only to read the EXR.
"""
import argparse, os, subprocess, sys, tempfile, time

NEW = "target/release/alhazen"


def run(binary, args):
    t = time.perf_counter()
    subprocess.run([binary, "render", *args, "-q"], check=True)
    return time.perf_counter() - t


def pfm(path):
    import numpy as np
    with open(path, "rb") as f:
        f.readline()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1]


def speed(old, runs):
    scenes = [("cornell-box", ["--integrator", "path", "--spp", "64"]),
              ("cornell-rough", ["--spp", "16"]),
              ("prism", ["--spp", "4"]),
              ("teapot", []),
              ("five-glass-balls", []),
              ("instancing", [])]
    print("| scene | before (s) | now (s) | ratio | same bits |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        for name, extra in scenes:
            a, b = [], []
            pa, pb = os.path.join(d, "a.pfm"), os.path.join(d, "b.pfm")
            for _ in range(runs):
                a.append(run(old, [f"scenes/{name}.toml", *extra, "-o", pa]))
                b.append(run(NEW, [f"scenes/{name}.toml", *extra, "-o", pb]))
            same = open(pa, "rb").read() == open(pb, "rb").read()
            print(f"| {name} {' '.join(extra)} | {min(a):.3f} | {min(b):.3f} | {min(b) / min(a):.3f} | {same} |")


def cost(runs):
    scenes = [("glass-balls", []), ("nine-red-balls", []), ("haas-haus", []), ("coffee-cup", []),
              ("chrome-ball-caustic", []), ("coffee-cup", ["--integrator", "path", "--spp", "16"]),
              ("glass-balls", ["--integrator", "path", "--spp", "16"])]
    print("| scene | connections off (s) | on (s) | ratio |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.pfm")
        for name, extra in scenes:
            off, on = [], []
            for _ in range(runs):
                off.append(run(NEW, [f"scenes/{name}.toml", *extra, "--no-mirror-connections", "-o", out]))
                on.append(run(NEW, [f"scenes/{name}.toml", *extra, "-o", out]))
            print(f"| {name} {' '.join(extra)} | {min(off):.3f} | {min(on):.3f} | {min(on) / min(off):.2f} |")


def spp_for(seconds, args, out):
    """The samples per pixel that take about `seconds` (from a 16-spp run, linear)."""
    t = run(NEW, [*args, "--spp", "16", "-o", out])
    return max(1, int(16 * seconds / t))


def error(seconds):
    import numpy as np
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    ref = np.array(mi.Bitmap("crates/alhazen-render/tests/data/mitsuba/cup-caustic-ptracer.exr"))[..., 0]
    h, w = ref.shape
    half = 6.0 * np.tan(np.radians(12.0))
    yy, xx = np.mgrid[0:h, 0:w]
    u, v = (xx + 0.5) / w * 2 - 1, (yy + 0.5) / h * 2 - 1
    inside = np.sqrt(u * u + v * v) * half < 0.95
    print(f"| cup-caustic.xml, {seconds} s each | spp | RMSE | mean relative error |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.pfm")
        for label, flags in [("with connections", []), ("without", ["--no-mirror-connections"])]:
            args = ["scenes/mitsuba/cup-caustic.xml", *flags]
            spp = spp_for(seconds, args, out)
            t = run(NEW, [*args, "--spp", str(spp), "-o", out])
            img = pfm(out)[..., 0]
            diff = (img - ref)[inside]
            rmse = np.sqrt(np.mean(diff ** 2))
            mre = np.mean(np.abs(diff) / np.maximum(ref[inside], 1e-3))
            print(f"| {label} ({t:.1f} s) | {spp} | {rmse:.4f} | {mre:.4f} |")
        print()
        print("| delta lights | image mean with connections | without | light missed |")
        print("|---|---|---|---|")
        for name in ["coffee-cup", "chrome-ball-caustic"]:
            means = []
            for flags in [[], ["--no-mirror-connections"]]:
                run(NEW, [f"scenes/{name}.toml", "--integrator", "path", "--spp", "16", *flags, "-o", out])
                means.append(float(pfm(out).mean()))
            print(f"| {name} (path, 16 spp) | {means[0]:.4f} | {means[1]:.4f} | {(1 - means[1] / means[0]) * 100:.1f} % |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["speed", "cost", "error"])
    ap.add_argument("old", nargs="?")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=4.0)
    a = ap.parse_args()
    if a.mode == "speed":
        if not a.old:
            sys.exit("speed needs the old binary")
        speed(a.old, a.runs)
    elif a.mode == "cost":
        cost(a.runs)
    else:
        error(a.seconds)


if __name__ == "__main__":
    main()
