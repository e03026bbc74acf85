#!/usr/bin/env python3
"""Do the C library's transcendental functions give the same bits on processors with and
without fused multiply-add? glibc picks an implementation per processor (an `ifunc`); run this
script twice and compare — once as it is, once with the FMA variants switched off:

    python3 bench/libm/fma_variants.py > /tmp/fma.txt
    GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2_Usable,-FMA_Usable,-AVX2,-FMA \
        python3 bench/libm/fma_variants.py --against /tmp/fma.txt

Python's `math` calls the same libm as Rust's `f64::sin` etc. On glibc 2.36 (Debian 12,
x86-64), 500,000 random arguments: atan2 111, acos 144, sin 365, cos 300, exp 353, log 58
results differ in the last bits. alhazen's renders took the same bytes both ways on every
scene tried (`alhazen render X -o x.exr --spp 4` with and without the variable: the six suite
scenes, `scenes/*.toml`): its hot paths use its own `sin_cos_turns`, and `atan2`/`acos` mostly
pick a texel, which one last bit rarely changes. Rarely is not never (ARCHITECTURE.md,
invariants).
"""
import argparse, math, random, struct, sys

FUNCS = {
    "atan2": lambda x, y: math.atan2(y, x),
    "acos": lambda x, y: math.acos(y),
    "sin": lambda x, y: math.sin(7 * x),
    "cos": lambda x, y: math.cos(7 * x),
    "exp": lambda x, y: math.exp(x),
    "log": lambda x, y: math.log(abs(x) + 1e-9),
}


def values(n):
    rng = random.Random(1)
    args = [(rng.uniform(-1, 1), rng.uniform(-1, 1)) for _ in range(n)]
    return {name: [struct.pack("<d", f(x, y)).hex() for x, y in args] for name, f in FUNCS.items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=500_000)
    ap.add_argument("--against", help="a file an earlier run wrote to stdout")
    a = ap.parse_args()
    mine = values(a.n)
    if not a.against:
        for name, vs in mine.items():
            print(name, " ".join(vs))
        return
    theirs = dict(line.split(" ", 1) for line in open(a.against).read().splitlines())
    for name, vs in mine.items():
        other = theirs[name].split(" ")
        print(f"{name}: {sum(p != q for p, q in zip(vs, other))} of {len(vs)} differ")


if __name__ == "__main__":
    main()
