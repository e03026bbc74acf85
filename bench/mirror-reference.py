#!/usr/bin/env python3
"""Checks `alhazen mirror reflex` against an independent 40-digit reference (mpmath).

The reference does not use the paper's quartic: it scans the reflection condition
"tangential components of the unit rays to E and S cancel" along the circle of the plane MES
(sphere) or of the normal projection (cylinder) at 40 significant digits, refines every sign change
with mpmath.findroot, keeps true reflections on the outside, and lifts a cylinder's reflex by the
unfolded straight path. Usage: bench/mirror-reference.py [N] [path/to/alhazen]   (needs: pip install mpmath)
"""
import json, random, subprocess, sys
from mpmath import mp, mpf, sqrt, cos, sin, pi, findroot

mp.dps = 40

def sub(a, b): return [x - y for x, y in zip(a, b)]
def add(a, b): return [x + y for x, y in zip(a, b)]
def mul(a, k): return [x * k for x in a]
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def norm(a): return sqrt(dot(a, a))
def unit(a): return mul(a, 1 / norm(a))

def visible_on_circle(r, e, s):
    """Canonical frame: centre 0, eye (e, 0), source s = (sx, sy >= 0). Returns phi or None."""
    def g(phi):
        p = [r * cos(phi), r * sin(phi)]
        t = [-sin(phi), cos(phi)]
        a, b = unit(sub([e, mpf(0)], p)), unit(sub(s, p))
        return dot(t, add(a, b))
    n = 4000
    best = None
    prev_phi, prev_g = mpf(0), g(mpf(0))
    for k in range(1, n + 1):
        phi = pi * k / n
        gv = g(phi)
        if prev_g * gv <= 0:
            root = findroot(g, (prev_phi, phi), solver='anderson')
            p = [r * cos(root), r * sin(root)]
            nrm = [cos(root), sin(root)]
            if dot(nrm, unit(sub([e, 0], p))) > 0 and dot(nrm, unit(sub(s, p))) > 0:
                best = root
        prev_phi, prev_g = phi, gv
    return best

def reference(q):
    c, R, E, S = [mpf(x) for x in q["center"]], mpf(q["radius"]), [mpf(x) for x in q["eye"]], [mpf(x) for x in q["point"]]
    if q["mirror"] == "sphere":
        d = sub(E, c); e = norm(d); x = mul(d, 1 / e)
        rel = sub(S, c); sx = dot(rel, x); perp = sub(rel, mul(x, sx)); sy = norm(perp); y = mul(perp, 1 / sy)
        phi = visible_on_circle(R, e, [sx, sy])
        return None if phi is None else add(c, mul(add(mul(x, cos(phi)), mul(y, sin(phi))), R))
    a = unit([mpf(v) for v in q["axis"]])
    he = dot(sub(E, c), a); hs = dot(sub(S, c), a)
    pe = sub(sub(E, c), mul(a, he)); ps = sub(sub(S, c), mul(a, hs))
    e = norm(pe); x = mul(pe, 1 / e)
    y = [a[1] * x[2] - a[2] * x[1], a[2] * x[0] - a[0] * x[2], a[0] * x[1] - a[1] * x[0]]
    sx, sy = dot(ps, x), dot(ps, y)
    if sy < 0: y, sy = mul(y, -1), -sy
    phi = visible_on_circle(R, e, [sx, sy])
    if phi is None: return None
    foot = add(mul(x, R * cos(phi)), mul(y, R * sin(phi)))
    le, ls = norm(sub(pe, foot)), norm(sub(ps, foot))
    return add(add(c, foot), mul(a, he + (hs - he) * le / (le + ls)))

def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    exe = sys.argv[2] if len(sys.argv) > 2 else "target/release/alhazen"
    rng = random.Random(7)
    def rv(s): return [rng.uniform(-s, s) for _ in range(3)]
    queries = []
    while len(queries) < n:
        r = 10 ** rng.uniform(-2, 2)
        c = rv(5 * r)
        def outside():
            while True:
                d = rv(1)
                if 0.01 < sum(v * v for v in d) <= 1: break
            k = r * (1 + 10 ** rng.uniform(-3, 2)) / sum(v * v for v in d) ** 0.5
            return [ci + di * k for ci, di in zip(c, d)]
        q = {"mirror": rng.choice(["sphere", "cylinder"]), "center": c, "radius": r, "eye": outside(), "point": outside()}
        if q["mirror"] == "cylinder":
            q["axis"] = rv(1)
        queries.append(q)
    out = subprocess.run([exe, "mirror", "reflex"], input="\n".join(json.dumps(q) for q in queries), capture_output=True, text=True)
    answers = [json.loads(l) for l in out.stdout.splitlines()]
    worst, mismatched, checked = 0.0, 0, 0
    for q, a in zip(queries, answers):
        if "error" in a: continue
        ref = reference(q)
        got = a["reflexes"][0] if a["reflexes"] else None
        if (ref is None) != (got is None):
            mismatched += 1
            continue
        if ref is None: continue
        checked += 1
        err = float(norm(sub([mpf(v) for v in got], ref)) / q["radius"])
        worst = max(worst, err)
    print(f"{len(queries)} queries, {checked} visible reflexes compared, {mismatched} disagreements on visibility, "
          f"worst position error {worst:.3e} (relative to the radius)")
    sys.exit(1 if mismatched or worst > 1e-12 else 0)

if __name__ == "__main__":
    main()
