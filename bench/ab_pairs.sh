#!/usr/bin/env bash
# A/B of two alhazen binaries on a shared, drifting VM: each round runs OLD and NEW at the same
# time, one per core (`taskset`, swapped every round), one thread each, and keeps the ratio of
# their CPU times (`perf stat -e task-clock`), so that the host's slow spells hit both sides.
# Prints, per scene, the median ratio NEW/OLD over the rounds, its range, and whether the two
# images are the same bytes.
#
#   bench/ab_pairs.sh ROUNDS OLD NEW SCENE.xml...     (SPP=16 for quicker rounds; default 64;
#                                                    SAMPLER=sobol as the suite renders)
#
# Needs two cores, `perf` and `taskset`. Session 25 of BENCHMARKS.md used it: 12-20 rounds at
# 16 spp resolve ~3 % where alternated sequential runs (±15 % drift) could not.
set -euo pipefail
spp=${SPP:-64}
# SAMPLER=sobol (or independent) overrides the scene file's sampler, as bench/mitsuba/suite.py does.
sampler=()
[ -n "${SAMPLER:-}" ] && sampler=(--sampler "$SAMPLER")
rounds=$1 old=$2 new=$3
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for scene in "$@"; do
    ratios=""
    for r in $(seq "$rounds"); do
        if [ $((r % 2)) = 0 ]; then a=0 b=1; else a=1 b=0; fi
        taskset -c $a perf stat -x, -o "$tmp/old.txt" -e task-clock "$old" render "$scene" -o "$tmp/old.exr" \
            --spp "$spp" --threads 1 --quiet "${sampler[@]}" >/dev/null 2>&1 &
        taskset -c $b perf stat -x, -o "$tmp/new.txt" -e task-clock "$new" render "$scene" -o "$tmp/new.exr" \
            --spp "$spp" --threads 1 --quiet "${sampler[@]}" >/dev/null 2>&1 &
        wait
        o=$(grep task-clock "$tmp/old.txt" | cut -d, -f1)
        n=$(grep task-clock "$tmp/new.txt" | cut -d, -f1)
        ratios="$ratios $(python3 -c "print($n / $o)")"
    done
    same=$(cmp -s "$tmp/old.exr" "$tmp/new.exr" && echo "same bytes" || echo "DIFFERENT bytes")
    python3 -c "
import statistics, sys
r = sorted(float(v) for v in '$ratios'.split())
print(f'{sys.argv[1]}: new/old median {statistics.median(r):.3f}, range {r[0]:.3f}-{r[-1]:.3f}, {len(r)} rounds, $same')
" "$(basename "$scene" .xml)"
done
