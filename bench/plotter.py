#!/usr/bin/env python3
"""Line art for pen plotters: `alhazen lines --optimize` against vpype (issue 21, item 5).

    python3 bench/plotter.py [--out /tmp/alhazen-plotter]

For every scene of scenes/lines/ and three floating-horizon graphs, draws the SVG as it comes
(`alhazen lines --hidden`), then
  * vpype:   `vpype read IN linemerge --tolerance 0.05mm linesort --two-opt write OUT`
  * alhazen: `alhazen lines --hidden --optimize` (join tolerance 0.05 mm)
and measures both outputs the same way with vpype's reader: strokes, and pen-up travel in mm
per layer from the origin (0, 0) through the strokes in file order (`vpype stat` leaves the
first move out; it is printed too). Also checks that vpype reads our three layers as layers
1, 2, 3. Times are wall-clock of the whole command (2 cores). Needs `pip install vpype`.
"""
import argparse, os, subprocess, sys, time

import numpy as np
import vpype

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ALHAZEN = os.path.join(ROOT, "target", "release", "alhazen")
MM = 25.4 / 96  # vpype's unit, the CSS pixel, in mm


def measure(svg):
    doc = vpype.read_multilayer_svg(svg, quantization=0.1)
    strokes, from_origin, between = 0, 0.0, 0.0
    for lid in sorted(doc.layers):
        at = 0j
        for k, line in enumerate(doc.layers[lid]):
            if len(line) == 0:
                continue
            strokes += 1
            step = abs(line[0] - at) * MM
            from_origin += step
            if k > 0:
                between += step
            at = line[-1]
    return strokes, from_origin, between, sorted(doc.layers)


def run(cmd):
    t = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="/tmp/alhazen-plotter")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    cases = [(os.path.splitext(f)[0], [os.path.join(ROOT, "scenes", "lines", f)])
             for f in sorted(os.listdir(os.path.join(ROOT, "scenes", "lines"))) if f.endswith(".toml")]
    cases += [(f"graph-{g}", ["--graph", g, "--net", "81"]) for g in ("ripple", "saddle", "peaks")]
    print(f"{'drawing':32} {'strokes':>15} {'pen-up mm: as drawn':>20} {'vpype':>8} {'alhazen':>8}  {'(no 1st move)':>17}  {'time s: vpype':>13} {'alhazen':>8}")
    for name, args in cases:
        raw, vp, ours = (os.path.join(a.out, f"{name}-{k}.svg") for k in ("raw", "vpype", "alhazen"))
        run([ALHAZEN, "lines", *args, "--hidden", "-q", "-o", raw])
        t_vp = run(["vpype", "read", raw, "linemerge", "--tolerance", "0.05mm", "linesort", "--two-opt", "write", vp])
        t_ours = run([ALHAZEN, "lines", *args, "--hidden", "-q", "--optimize", "-o", ours])
        (n0, u0, _, layers), (n1, u1, b1, _), (n2, u2, b2, _) = measure(raw), measure(vp), measure(ours)
        assert set(layers) <= {1, 2, 3}, (name, layers)
        print(f"{name:32} {n0:>5} {n1:>4} {n2:>4} {u0:>20.0f} {u1:>8.0f} {u2:>8.0f}  {b1:>8.0f} {b2:>8.0f}  {t_vp:>13.2f} {t_ours:>8.2f}")


if __name__ == "__main__":
    sys.exit(main())
