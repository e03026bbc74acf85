#!/usr/bin/env python3
"""Where the path tracer's gap to Mitsuba 3 lies, bounce by bounce: each suite scene cut at a
smaller `max_depth` (1: camera rays, nearest hits and emission only), and an empty scene whose
every camera ray escapes to a constant sky (a path's start and end, nothing else), timed in
both renderers at equal samples.

    python3 bench/mitsuba/stages.py [--depths 1,2,8] [--runs 3] [NAME…]

Per scene and depth: alhazen's render time as it reports it (less the world's build), and
`mi.render` in Mitsuba `llvm_ad_rgb` after a warm-up (the JIT excluded), medians of `--runs`,
runs alternating. The cut scenes are the suite's XML files with that one value changed,
written to a temporary directory. Needs what bench/mitsuba/suite.py needs.
"""
import argparse, os, re, subprocess, sys, tempfile, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from suite import EXE, SAMPLER, SCENES, SUITE, settle  # noqa: E402

EMPTY = """<scene version="3.0.0">
    <default name="spp" value="64"/>
    <integrator type="path"><integer name="max_depth" value="8"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="256"/><integer name="height" value="256"/>
            <rfilter type="box"/><string name="pixel_format" value="rgb"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.2, 0.2, 0.2"/></emitter>
    <!-- One sphere far from the view: the scene is not empty, no camera ray meets it. -->
    <shape type="sphere">
        <point name="center" value="0, -50, 0"/><float name="radius" value="0.01"/>
        <bsdf type="diffuse"/>
    </shape>
</scene>
"""


def cut(path, depth, tmp):
    """The scene at `path` with `max_depth` set to `depth`, its data files found where they are."""
    text = open(path).read()
    text = re.sub(r'(name="max_depth" value=")\d+"', rf'\g<1>{depth}"', text)
    text = text.replace('"data/', f'"{os.path.join(SUITE, "data")}/')
    out = os.path.join(tmp, f"{os.path.basename(path)[:-4]}-d{depth}.xml")
    open(out, "w").write(text)
    return out


def alhazen(path, spp, out):
    settle()
    done = subprocess.run([EXE, "render", path, "-o", out, "--spp", str(spp), "--sampler", SAMPLER],
                          check=True, stderr=subprocess.PIPE, text=True)
    reported = float(re.search(r" in ([0-9.]+) s on ", done.stderr).group(1))
    building = re.search(r", ([0-9.]+) s of it building the world", done.stderr)
    return reported - (float(building.group(1)) if building else 0.0)


def compare(label, path, spp, runs, tmp):
    import drjit as dr
    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_file(path, spp=spp)
    dr.eval(mi.render(scene, spp=spp))
    ours, theirs = [], []
    for i in range(runs):
        ours.append(alhazen(path, spp, os.path.join(tmp, "ours.exr")))
        t0 = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=i + 1)
        dr.eval(img)
        np.array(img)
        theirs.append(time.perf_counter() - t0)
    a, m = float(np.median(ours)), float(np.median(theirs))
    print(f"| {label} | {a:.3f} s | {m:.3f} s | {a / m:.2f} |", flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("names", nargs="*")
    ap.add_argument("--depths", default="1,2,8")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    a = ap.parse_args()
    names = a.names or list(SCENES)
    print("| scene | alhazen render | Mitsuba llvm | ratio |\n|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        empty = os.path.join(tmp, "empty.xml")
        open(empty, "w").write(EMPTY)
        compare("empty (every camera ray escapes)", empty, a.spp, a.runs, tmp)
        for name in names:
            for depth in (int(d) for d in a.depths.split(",")):
                compare(f"{name}, depth {depth}", cut(SCENES[name], depth, tmp), a.spp, a.runs, tmp)


if __name__ == "__main__":
    main()
