#!/usr/bin/env bash
# The lanes' path tracer against the per-path one on any scenes: `--kernel portable` renders
# each path alone (the material kernels need a vector unit), the default renders in lanes, and
# the two images must be the same bytes (ARCHITECTURE.md, invariants). Prints the scenes whose
# images differ; exit code 1 if any does.
#
#   bench/lanes_vs_per_path.sh [SCENE...]     (default: every scene under scenes/, the suite's
#                                             and the Blender comparisons' files)
#
# Session 55 found with it that thin metallic–roughness sheets rendered black from behind in
# the lanes. Small renders (24 × 16, 4 spp, path tracing) keep a sweep of ~70 scenes to a minute.
set -uo pipefail
cd "$(dirname "$0")/.."
exe=${ALHAZEN:-target/release/alhazen}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ $# = 0 ]; then
    set -- scenes/*.toml scenes/mitsuba/*.xml scenes/pbrt/*.pbrt bench/mitsuba/suite/*.xml bench/lights/*.xml \
        crates/alhazen-import/tests/data/blender/*.glb
fi
n=0 different=0
for scene in "$@"; do
    n=$((n + 1))
    args=(render "$scene" --integrator path --spp 4 --width 24 --height 16 --quiet)
    "$exe" "${args[@]}" -o "$tmp/lanes.pfm" 2>/dev/null || { echo "$scene: not rendered"; continue; }
    "$exe" "${args[@]}" -o "$tmp/paths.pfm" --kernel portable 2>/dev/null || { echo "$scene: not rendered"; continue; }
    if ! cmp -s "$tmp/lanes.pfm" "$tmp/paths.pfm"; then
        echo "$scene: the lanes' image differs from the per-path tracer's"
        different=$((different + 1))
    fi
done
echo "$n scenes, $different different"
[ "$different" = 0 ]
