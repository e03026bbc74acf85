#!/usr/bin/env bash
# Seconds per frame of `alhazen raster` over a suite of scenes, two builds alternated, and
# whether their frames agree (8-bit PNG bytes).
#
#   bench/raster/frames.sh OLD_BINARY NEW_BINARY [RUNS]
#
# The suite: every scene below that exists, plus the path tracer suite's 1,001,108-triangle
# mesh when its data has been generated (`python3 bench/mitsuba/suite/make_data.py`).
# `--no-shadows` on the million-triangle mesh only to match the earlier tables; the other scenes
# use their defaults. Prints one table row per scene: name, old times, new times, same image.
set -euo pipefail
old=${1:?old binary}
new=${2:?new binary}
runs=${3:-2}
cd "$(dirname "$0")/../.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

scenes=(scenes/raster-100k.toml scenes/raster-100k-mirror-ball.toml scenes/teapot.toml
        scenes/glass-balls.toml scenes/cornell-box.toml scenes/nurbs-design.toml
        scenes/lofted-and-spline-surfaces.toml scenes/instancing.toml scenes/cameras/stereo.toml
        scenes/cameras/panorama.toml)
extra=()
if [ -f bench/mitsuba/suite/data/displaced-1m.ply ]; then
    "$new" convert bench/mitsuba/suite/million.xml -o "$work/million.toml" 2>/dev/null
    scenes+=("$work/million.toml")
fi

frame() { # binary scene output → seconds per frame
    local args=(--frames 10)
    case "$2" in
        *million.toml) args+=(--no-shadows) ;;
        *panorama.toml) args=(--frames 2) ;; # seconds a frame before session 17
    esac
    "$1" raster "$2" "${args[@]}" -o "$3" 2>&1 | grep -o 'in [0-9.]* s per frame' | awk '{print $2}'
}

echo "| scene | old s/frame | new s/frame | same PNG |"
echo "|---|---:|---:|---|"
for s in "${scenes[@]}"; do
    [ -f "$s" ] || continue
    o=() n=()
    for _ in $(seq "$runs"); do
        o+=("$(frame "$old" "$s" "$work/old.png")")
        n+=("$(frame "$new" "$s" "$work/new.png")")
    done
    same=$(cmp -s "$work/old.png" "$work/new.png" && echo yes || echo no)
    echo "| $(basename "$s" .toml) | ${o[*]} | ${n[*]} | $same |"
done
