#!/usr/bin/env bash
# A/B of two alhazen binaries by counting, not timing: each renders each scene once under
# Valgrind's cachegrind (one thread), which reports the instructions executed and the data
# cache misses of a simulated cache. The counts are the same from run to run, so a change of
# 1 % shows where this VM's timings drift by ±15 % (bench/ab_pairs.sh needs many rounds for
# 3 %). They are a proxy, not a time: Valgrind has no AVX-512, so the binaries take their AVX2
# kernels, and its cache is not this processor's.
#
#   bench/count_pairs.sh OLD NEW SCENE.xml...     (SPP=4 by default: ~10 s a run; SAMPLER=sobol
#                                                  as the suite renders)
#
# Prints, per scene, NEW/OLD for instructions (Ir), first-level data misses (D1mr + D1mw)
# and last-level misses (DLmr + DLmw), and whether the two images are the same bytes.
set -euo pipefail
spp=${SPP:-4}
# SAMPLER=sobol (or independent) overrides the scene file's sampler, as bench/mitsuba/suite.py does.
sampler=()
[ -n "${SAMPLER:-}" ] && sampler=(--sampler "$SAMPLER")
old=$1 new=$2
shift 2
command -v valgrind >/dev/null || { echo "needs valgrind (apt-get install valgrind)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
count() { # binary scene side
    valgrind --tool=cachegrind --cache-sim=yes --cachegrind-out-file="$tmp/$3.cg" \
        "$1" render "$2" -o "$tmp/$3.exr" --spp "$spp" --threads 1 --quiet "${sampler[@]}" >/dev/null 2>&1
    # The summary line: Ir I1mr ILmr Dr D1mr DLmr Dw D1mw DLmw.
    grep '^summary:' "$tmp/$3.cg" | awk '{print $2, $6 + $9, $7 + $10}'
}
for scene in "$@"; do
    read -r oi o1 oL <<<"$(count "$old" "$scene" old)"
    read -r ni n1 nL <<<"$(count "$new" "$scene" new)"
    same=$(cmp -s "$tmp/old.exr" "$tmp/new.exr" && echo "same bytes" || echo "DIFFERENT bytes")
    python3 -c "
import sys
oi, o1, oL, ni, n1, nL = map(float, sys.argv[2:8])
r = lambda n, o: n / o if o else float('nan')
print(f'{sys.argv[1]}: new/old instructions {r(ni, oi):.4f}, D1 misses {r(n1, o1):.4f}, LL misses {r(nL, oL):.4f}, $same')
" "$(basename "$scene" .xml)" "$oi" "$o1" "$oL" "$ni" "$n1" "$nL"
done
