#!/usr/bin/env python3
"""Issue 18's benchmark suite: alhazen's path tracer against Mitsuba 3 on nine scenes (the six of the issue, and three of several lights), each a
Mitsuba XML file that both renderers read as it is (so the twins are one file).

    python3 bench/mitsuba/suite/make_data.py           # textures, sky, meshes (once)
    python3 bench/mitsuba/suite.py reference [NAME…]   # Mitsuba's converged images (committed)
    python3 bench/mitsuba/suite.py run [--runs 3] [NAME…]
    python3 bench/mitsuba/suite.py depths [--runs 3] [NAME…]
    python3 bench/mitsuba/suite.py errors [--spp 64] [--seeds 3] [NAME…]

`run`, per scene, 256×256, 64 spp, max depth 8, on all cores:
1. Equal samples: median wall time of the whole `alhazen render` process (parse, build, render,
   write EXR; also its render alone — the time it reports less the part that built the world
   and its BVHs —, the part that `mi.render` times; its default Sobol sampler,
   `ALHAZEN_SAMPLER=independent` for the files' own) against `mi.render` in Mitsuba
   `llvm_ad_rgb` (after one warm-up render, so the JIT is excluded; alhazen and llvm runs
   alternate so the VM's drift hits both, each alhazen run started once Mitsuba's process has
   gone idle, `settle`) and `scalar_rgb`.
2. Equal time: alhazen renders with the most samples whose run (median of 3) fits in llvm's
   time; RMSE and mean relative error of both images against the committed reference
   (suite/ref/NAME.exr, Mitsuba llvm at 4096 spp), and the relative difference of the means of
   alhazen's 64-spp image and the reference (the model's agreement, not noise).

`depths`, per scene: the render alone of both renderers (alhazen's reported time less its
build, against `mi.render` in llvm) with the path depth capped at 1, 2, 3 and the scene's own:
where the time goes — a depth of 1 is the camera rays, their hits and the emitters seen, each
further depth one bounce with its light sample — and so which part of a sample to speed up.

`errors`, per scene: alhazen's RMSE, mean relative error and image mean against the reference
at `--spp` samples, averaged over seeds 1 to `--seeds` (no timing): a change to the estimator's
noise seen apart from its speed.

Needs `pip install mitsuba numpy`, `apt-get install libllvm19`.
"""
import argparse, os, re, resource, subprocess, sys, tempfile, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SUITE = os.path.join(HERE, "suite")
SCENES = {
    "cornell-box": os.path.join(ROOT, "scenes/mitsuba/cornell-box.xml"),
    "cornell-rough": os.path.join(ROOT, "scenes/mitsuba/cornell-rough.xml"),
    "textured": os.path.join(SUITE, "textured.xml"),
    "glossy": os.path.join(SUITE, "glossy.xml"),
    "envmap": os.path.join(SUITE, "envmap.xml"),
    "million": os.path.join(SUITE, "million.xml"),
    # Several lights (session 57): powers a thousandfold apart, the strongest lighting what is
    # seen, or behind a wall; six equal lamps along a corridor, each lighting its own stretch.
    "five-lamps": os.path.join(ROOT, "bench/lights/five-lamps.xml"),
    "hidden-lamp": os.path.join(ROOT, "bench/lights/hidden-lamp.xml"),
    "corridor": os.path.join(ROOT, "bench/lights/corridor.xml"),
}
EXE = os.environ.get("ALHAZEN", os.path.join(ROOT, "target/release/alhazen"))
# Each renderer with its default sampler: alhazen's Sobol points (the files ask for Mitsuba's
# default, `independent`, which alhazen honours unless told otherwise).
SAMPLER = os.environ.get("ALHAZEN_SAMPLER", "sobol")


def load(path):
    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))[..., :3].astype(np.float64)


def errors(img, ref):
    rmse = float(np.sqrt(((img - ref) ** 2).mean()))
    rel = float((np.abs(img - ref) / np.maximum(ref, 1e-2)).mean())
    return rmse, rel


def settle(limit=10.0):
    """Waits until this process (Mitsuba's threads) is idle. After `mi.render` returns, Mitsuba
    llvm keeps a core busy for ~1.7 s on our machine (its workers spinning); an alhazen run
    started then shares the 2 cores with it and took up to 1.8× its time alone (session 43).
    Each renderer is timed alone: alhazen's runs start once a tenth of a second passes with
    under 5 ms of this process's CPU time."""
    def cpu():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime
    t_end = time.perf_counter() + limit
    while time.perf_counter() < t_end:
        c0 = cpu()
        time.sleep(0.1)
        if cpu() - c0 < 0.005:
            return


def alhazen_run(path, spp, out):
    """The whole process's wall time, and the time alhazen reports for its render alone (its
    summary line on stderr, less the part of it that built the world: parsing, loading meshes
    and images, building the BVHs and writing the image left out, as `mi.render` leaves out
    `mi.load_file`, which builds Mitsuba's Embree scene). It starts once Mitsuba is idle."""
    settle()
    t0 = time.perf_counter()
    done = subprocess.run([EXE, "render", path, "-o", out, "--spp", str(spp), "--sampler", SAMPLER],
                          check=True, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    reported = re.search(r" in ([0-9.]+) s on ", done.stderr)
    building = re.search(r", ([0-9.]+) s of it building the world", done.stderr)
    if not reported:
        return wall, float("nan")
    return wall, float(reported.group(1)) - (float(building.group(1)) if building else 0.0)


def mitsuba_renderer(variant, scene, spp, out):
    """A function timing one Mitsuba render of `scene` (an XML file's path or a scene dict),
    loaded and warmed up (JIT) beforehand; it writes the last image to `out`."""
    mi.set_variant(variant)
    import drjit as dr
    scene = mi.load_dict(scene) if isinstance(scene, dict) else mi.load_file(scene, spp=spp)
    dr.eval(mi.render(scene, spp=spp))
    count = [0]

    def run():
        mi.set_variant(variant)
        count[0] += 1
        t0 = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=count[0])
        dr.eval(img)
        arr = np.array(img)
        elapsed = time.perf_counter() - t0
        mi.Bitmap(arr).write(out)
        return elapsed
    return run


def reference(name, spp):
    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_file(SCENES[name], spp=256)
    passes, acc = max(1, spp // 256), None
    for i in range(passes):
        arr = np.array(mi.render(scene, spp=256, seed=1000 + i), dtype=np.float64)
        acc = arr if acc is None else acc + arr
        print(f"{name}: pass {i + 1}/{passes}", file=sys.stderr, end="\r")
    os.makedirs(os.path.join(SUITE, "ref"), exist_ok=True)
    out = os.path.join(SUITE, "ref", f"{name}.exr")
    mi.Bitmap((acc / passes).astype(np.float32)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, False).write(out)
    print(f"\n{name}: wrote {out} ({spp} spp)", file=sys.stderr)


def run(name, runs, spp, tmp):
    path = SCENES[name]
    llvm = mitsuba_renderer("llvm_ad_rgb", path, spp, f"{tmp}/llvm.exr")
    alhazen_run(path, spp, f"{tmp}/ours.exr")  # warm the file cache
    pairs = [(*alhazen_run(path, spp, f"{tmp}/ours.exr"), llvm()) for _ in range(runs)]
    t_ours, t_render, t_llvm = (float(np.median(ts)) for ts in zip(*pairs))
    scalar = mitsuba_renderer("scalar_rgb", path, spp, f"{tmp}/scalar.exr")
    t_scalar = float(np.median([scalar() for _ in range(max(1, runs // 2))]))
    spp_eq = max(1, int(spp * t_llvm / t_ours))
    t_eq = float(np.median([alhazen_run(path, spp_eq, f"{tmp}/eq.exr")[0] for _ in range(3)]))
    while t_eq > t_llvm and spp_eq > 1:
        spp_eq -= 1
        t_eq = float(np.median([alhazen_run(path, spp_eq, f"{tmp}/eq.exr")[0] for _ in range(3)]))
    ref = load(os.path.join(SUITE, "ref", f"{name}.exr"))
    ours, eq, mits = (load(f"{tmp}/{f}.exr") for f in ("ours", "eq", "llvm"))
    e_eq, e_mi = errors(eq, ref), errors(mits, ref)
    bias = float(ours.mean() / ref.mean() - 1)
    print(f"| {name} | {t_ours:.3f} s | {t_llvm:.3f} s | {t_scalar:.3f} s | **{t_ours / t_llvm:.2f}** | "
          f"{t_render:.3f} s: {t_render / t_llvm:.2f} | "
          f"{t_ours / t_scalar:.2f} | {spp_eq} spp {t_eq:.2f} s: {e_eq[0]:.5f} / {e_eq[1]:.4f} | "
          f"{e_mi[0]:.5f} / {e_mi[1]:.4f} | {bias * 100:+.2f} % |", flush=True)


def with_depth(path, depth):
    """A copy of scene file `path` whose `max_depth` is `depth`, beside it (its relative file
    names resolve as before); the caller removes it."""
    text = open(path).read()
    capped, n = re.subn(r'(name="max_depth" value=")[^"]*"', rf'\g<1>{depth}"', text)
    if n != 1:
        sys.exit(f"{path}: no single max_depth to cap")
    out = os.path.join(os.path.dirname(path), f".depth-{depth}-{os.path.basename(path)}")
    with open(out, "w") as f:
        f.write(capped)
    return out


def depths(name, runs, spp, tmp):
    path = SCENES[name]
    own = int(re.search(r'name="max_depth" value="(\d+)"', open(path).read()).group(1))
    cells = []
    for depth in [1, 2, 3, own]:
        capped = with_depth(path, depth)
        try:
            llvm = mitsuba_renderer("llvm_ad_rgb", capped, spp, f"{tmp}/llvm.exr")
            alhazen_run(capped, spp, f"{tmp}/ours.exr")
            pairs = [(alhazen_run(capped, spp, f"{tmp}/ours.exr")[1], llvm()) for _ in range(runs)]
        finally:
            os.remove(capped)
        ours, theirs = (float(np.median(ts)) for ts in zip(*pairs))
        cells.append(f"{ours:.3f} / {theirs:.3f} s: **{ours / theirs:.2f}**")
    print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def seed_errors(name, spp, seeds, tmp):
    """alhazen's error at `spp` samples against the reference, over `seeds` seeds (no timing):
    what a change of the estimator does to the noise, apart from speed."""
    ref = load(os.path.join(SUITE, "ref", f"{name}.exr"))
    rmse, rel, bias = [], [], []
    for seed in range(1, seeds + 1):
        out = f"{tmp}/ours.exr"
        subprocess.run([EXE, "render", SCENES[name], "-o", out, "--spp", str(spp), "--sampler", SAMPLER,
                        "--seed", str(seed), "--quiet"], check=True)
        img = load(out)
        e = errors(img, ref)
        rmse.append(e[0]), rel.append(e[1]), bias.append(img.mean() / ref.mean() - 1)
    print(f"| {name} | {np.mean(rmse):.4f} | {np.mean(rel):.4f} | {np.mean(bias) * 100:+.2f} % |", flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["reference", "run", "depths", "errors"])
    ap.add_argument("names", nargs="*")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--seeds", type=int, default=3)
    a = ap.parse_args()
    names = a.names or list(SCENES)
    if a.mode == "reference":
        for n in names:
            reference(n, a.ref_spp)
        return
    if "ALHAZEN" not in os.environ:
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "alhazen-cli"], cwd=ROOT, check=True)
    tmp = tempfile.mkdtemp()
    # Per mode: the table's caption, its columns, and what fills a scene's row.
    cores = f"{os.cpu_count()} cores, {a.spp} spp, medians of {a.runs}"
    modes = {
        "errors": (f"alhazen at {a.spp} spp against the references, means over seeds 1-{a.seeds}",
                   ["RMSE", "mean rel.", "image mean vs ref."], lambda n: seed_errors(n, a.spp, a.seeds, tmp)),
        "depths": (f"{cores}; render alone, alhazen / Mitsuba llvm",
                   ["depth 1", "depth 2", "depth 3", "the scene's depth"], lambda n: depths(n, a.runs, a.spp, tmp)),
        "run": (cores, ["alhazen", "Mitsuba llvm", "Mitsuba scalar", "alhazen/llvm", "alhazen render alone: /llvm",
                        "alhazen/scalar", "alhazen at llvm's time: RMSE / mean rel.",
                        "Mitsuba llvm: RMSE / mean rel.", "mean vs ref."], lambda n: run(n, a.runs, a.spp, tmp)),
    }
    caption, columns, row = modes[a.mode]
    print(caption)
    print("| scene | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    for n in names:
        row(n)

if __name__ == "__main__":
    main()
