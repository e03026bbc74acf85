#!/usr/bin/env bash
# Two-thread wall clock of several alhazen binaries, run in turn (alternated, so a VM's slow
# spells hit them alike): per scene, each binary's median of the `rendered in` times.
#
#   bench/walls.sh ROUNDS "OLD NEW ..." SCENE.xml...     (SPP=64, THREADS=2 by default;
#                                                       the suite's Sobol sampler)
#
# Where bench/ab_pairs.sh measures a sample's cost (one thread per binary), this measures what
# a user waits for on all cores: the threads' share of the work included.
set -euo pipefail
rounds=$1 bins=$2
shift 2
spp=${SPP:-64} threads=${THREADS:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for scene in "$@"; do
    line="$(basename "$scene" .xml):"
    declare -A times=()
    for _ in $(seq "$rounds"); do
        for b in $bins; do
            t=$("$b" render "$scene" -o "$tmp/out.exr" --spp "$spp" --sampler sobol --threads "$threads" 2>&1 |
                grep -o "in [0-9.]* s" | cut -d' ' -f2)
            times[$b]="${times[$b]:-} $t"
        done
    done
    for b in $bins; do
        line="$line $(basename "$b") $(python3 -c "import statistics, sys; print(f'{statistics.median(map(float, sys.argv[1:])):.3f} s')" ${times[$b]})"
    done
    echo "$line"
    unset times
done
