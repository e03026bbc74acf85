#!/usr/bin/env python3
"""Pixel reconstruction filters against Mitsuba 3: three lights seen directly against black (a
tilted square, a bar about a pixel wide, a spot of two pixels) — sharp edges, so the filter
decides every pixel near them — rendered with Mitsuba's default filter (a Gaussian: the file
names none), its Lanczos and its Mitchell–Netravali filters, for the test
`pixel_filters_agree_with_mitsuba` (crates/alhazen-import/tests/mitsuba.rs).

    python3 bench/mitsuba/filter_refs.py [--spp 4096]

Writes pixel-filter-NAME.xml and pixel-filter-NAME-mitsuba.exr (`path` integrator at depth 1:
the lights alone) into crates/alhazen-import/tests/data/mitsuba/. The references come from
`llvm_ad_rgb`, which splats through the filter itself: the `scalar` variants read it from a
table of 31 steps, each the value at its step's near end (`eval_discretized`), a filter
measurably wider than the one named (the spot's pixel 5 % dimmer through the Gaussian).
Needs `apt-get install libllvm19`.
"""
import argparse, os
import numpy as np

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import mitsuba as mi

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "crates", "alhazen-import", "tests",
                   "data", "mitsuba")

FILTERS = {
    "gaussian": "",
    "lanczos": '<rfilter type="lanczos"/>',
    "mitchell": '<rfilter type="mitchell"/>',
}


def light(scale, angle, at, radiance):
    return f"""    <shape type="rectangle">
        <transform name="to_world"><scale x="{scale[0]}" y="{scale[1]}"/><rotate z="1" angle="{angle}"/><translate x="{at[0]}" y="{at[1]}"/></transform>
        <emitter type="area"><rgb name="radiance" value="{radiance}"/></emitter>
    </shape>
"""


def scene(name):
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- Lights seen against black through Mitsuba's {name} pixel filter (bench/mitsuba/filter_refs.py). -->
<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="1"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="64"/><integer name="height" value="48"/>
            <string name="pixel_format" value="rgb"/>
            {FILTERS[name]}
        </film>
    </sensor>
""" + light((0.25, 0.25), 25, (-0.4, 0.1), "4, 2, 1") + light((0.02, 0.25), 10, (0.45, 0.0), "1, 3, 6") \
        + light((0.04, 0.04), 0, (0.2, -0.45), "8, 8, 8") + "</scene>\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=4096)
    args = ap.parse_args()
    mi.set_variant("llvm_ad_rgb")
    for seed, name in enumerate(FILTERS):
        path = os.path.join(OUT, f"pixel-filter-{name}.xml")
        with open(path, "w") as f:
            f.write(scene(name))
        img = mi.render(mi.load_file(path), spp=args.spp, seed=11 + seed)
        # The negative lobes' rings clamped to 0 (the test reads images without negatives and
        # compares the pixels the lights reach).
        img = np.maximum(np.array(img), 0.0)
        mi.Bitmap(img).write(os.path.join(OUT, f"pixel-filter-{name}-mitsuba.exr"))
        print("wrote", path)


if __name__ == "__main__":
    main()
