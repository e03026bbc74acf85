#!/usr/bin/env bash
# Radiosity solve times (issue 23, item 1): each scene solved at the default settings (and the
# Cornell box at finer element levels), the final image kept to 8×8 pixels at 1 spp so that
# the time is the solve's. Prints one line per run: scene, settings, elements, shots, seconds.
#   bench/radiosity/solve.sh [RUNS]      (ALHAZEN=path/to/alhazen, default target/release)
set -euo pipefail
cd "$(dirname "$0")/../.."
ALHAZEN=${ALHAZEN:-target/release/alhazen}
RUNS=${1:-2}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cases=(
  "scenes/cornell-box.toml|"
  "scenes/cornell-box.toml|--levels 4"
  "scenes/cornell-box.toml|--levels 5"
  "scenes/haas-haus.toml|"
  "scenes/complete-shadow.toml|"
  "scenes/glass-balls.toml|"
  "scenes/nine-red-balls.toml|"
)
for run in $(seq "$RUNS"); do
  for c in "${cases[@]}"; do
    scene=${c%%|*}; extra=${c#*|}
    # shellcheck disable=SC2086
    line=$("$ALHAZEN" render "$scene" --integrator radiosity --width 8 --height 8 --spp 1 $extra \
      -o "$out/x.png" 2>&1 | grep '^rendered')
    elements=$(sed -E 's/.* ([0-9]+) elements.*/\1/' <<<"$line")
    shots=$(sed -E 's/.* ([0-9]+) shots.*/\1/' <<<"$line")
    patches=$(sed -E 's/.*radiosity: ([0-9]+) patches.*/\1/' <<<"$line")
    secs=$(sed -E 's/.* in ([0-9.]+) s on.*/\1/' <<<"$line")
    printf '%s\t%s\tpatches %s\telements %s\tshots %s\t%s s\n' "$scene" "${extra:-default}" "$patches" "$elements" "$shots" "$secs"
  done
done
