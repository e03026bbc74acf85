#!/usr/bin/env bash
# Times alhazen and POV-Ray 3.7 on the same scene (scenes/glass-balls.toml and its twin
# bench/povray/glass-balls.pov) at 800×600, 4 samples per pixel, depth 8, 2 threads, in one
# run, and prints the median wall times and their ratio. Needs `apt-get install povray`.
# Usage: bench/povray-compare.sh [runs]   (default 5)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
command -v povray >/dev/null || { echo "povray not found: apt-get install povray" >&2; exit 2; }
cargo build --release -q
out=$(mktemp -d)
time_cmd() { local s e; s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N); echo "$e - $s" | bc -l; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
ours=(); pov=()
for _ in $(seq "$runs"); do
  # POV-Ray (without photons) does not light surfaces through mirrors: neither do we here.
  ours+=("$(time_cmd ./target/release/alhazen render scenes/glass-balls.toml -o "$out/a.png" --width 800 --height 600 --spp 4 --depth 8 --threads 2 --no-mirror-connections --quiet)")
  # +A0.0 +AM1 +R2: non-adaptive supersampling, 2×2 = 4 samples in every pixel.
  pov+=("$(time_cmd povray +Ibench/povray/glass-balls.pov +O"$out/p.png" +W800 +H600 +A0.0 +AM1 +R2 +WT2 -D -V)")
done
a=$(printf '%s\n' "${ours[@]}" | median); p=$(printf '%s\n' "${pov[@]}" | median)
printf 'alhazen  median %.3f s   (runs: %s)\n' "$a" "${ours[*]}"
printf 'POV-Ray  median %.3f s   (runs: %s)\n' "$p" "${pov[*]}"
printf 'ratio alhazen/POV-Ray = %.3f\n' "$(echo "$a / $p" | bc -l)"
rm -rf "$out"
