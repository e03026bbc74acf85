#!/usr/bin/env bash
# The Slurm check (.ci/run runs it when sbatch is present): starts the one-node cluster,
# renders an example scene as a job array of 4 bands plus a dependent merge job, and checks
# that the merged image has the bytes of one render on one machine.
#
#   contrib/slurm/test.sh            # uses target/debug/alhazen (built by cargo test), or $ALHAZEN
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
export ALHAZEN=${ALHAZEN:-$root/target/debug/alhazen}
[ -x "$ALHAZEN" ] || { echo "no alhazen binary at $ALHAZEN: build it first (cargo build)" >&2; exit 1; }
eval "$("$root/contrib/slurm/setup-single-node.sh")"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=$root/scenes/glass-balls.toml
options=(--width 160 --height 120 --spp 2)
"$ALHAZEN" render "$scene" -o "$work/one.exr" -q "${options[@]}"
PARTS=$work/parts "$root/contrib/slurm/submit.sh" "$scene" "$work/merged.exr" 4 "${options[@]}"
for _ in $(seq 600); do
    [ -z "$(squeue -h -n alhazen-render,alhazen-merge 2>/dev/null)" ] && break
    sleep 0.5
done
if ! cmp -s "$work/one.exr" "$work/merged.exr"; then
    echo "slurm: the merged image is missing or differs from one render; logs:" >&2
    tail -n 20 "$work"/parts/*.log >&2 || true
    exit 1
fi
echo "slurm: 4 array tasks and a merge job gave the bytes of one render"
