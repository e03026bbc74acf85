#!/usr/bin/env bash
# Renders SCENE over a Slurm cluster in N bands of tiles, then merges them into IMAGE — the
# same bytes as `alhazen render SCENE -o IMAGE` on one machine. Prints the two job ids.
#
#   contrib/slurm/submit.sh SCENE IMAGE N [alhazen render options…]
#   ALHAZEN=/path/to/alhazen PARTS=/shared/dir contrib/slurm/submit.sh …
# The parts go to $PARTS (default: IMAGE's name + .parts/), which every node must see.
set -euo pipefail
[ $# -ge 3 ] || { sed -n '2,8p' "$0" >&2; exit 2; }
scene=$(realpath "$1")
image=$(realpath -m "$2")
count=$3
shift 3
here=$(dirname "$(realpath "$0")")
parts=$(realpath -m "${PARTS:-$image.parts}")
mkdir -p "$parts"
export ALHAZEN=${ALHAZEN:-$(command -v alhazen || echo alhazen)}
render=$(sbatch --parsable --export=ALL --array=0-$(( count - 1 )) --output="$parts/render-%a.log" \
    "$here/render.sbatch" "$scene" "$parts" "$@")
render=${render%%;*}
merge=$(sbatch --parsable --export=ALL --dependency=afterok:"$render" --kill-on-invalid-dep=yes \
    --output="$parts/merge.log" "$here/merge.sbatch" "$parts" "$count" "$image")
echo "render array: job $render ($count tasks); merge: job $merge → $image"
