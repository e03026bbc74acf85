#!/usr/bin/env bash
# The Cornell box (scenes/cornell-box.toml) with every surface of one material in turn — the
# course's Lambert, Oren–Nayar, Phong, Blinn–Phong and Cook–Torrance, a clear coat over Lambert
# and over glTF's metallic–roughness, that mix alone with the single-scattering metal and with
# glTF's (Blender's) metal that gives back the light of several facets, a sheen over Lambert —
# rendered by each binary given, one thread, so that what a material costs the path tracer
# shows beside Lambert's. Prints the time each render reports, alternating the binaries round
# by round (VMs drift).
#
#   bench/materials.sh ROUNDS BIN...        (SPP=16 by default)
set -euo pipefail
spp=${SPP:-16}
rounds=$1
shift
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
box="$root/scenes/cornell-box.toml"
each() { sed "s/bsdf = { type = \"lambert\", color = \(\[[^]]*\]\) }/bsdf = $1 }/" "$box" > "$tmp/$2.toml"; }
each '{ type = "lambert", color = \1' lambert
each '{ type = "oren-nayar", color = \1, sigma = 20' oren-nayar
each '{ type = "phong", color = \1, ks = 0.2, exponent = 32' phong
each '{ type = "blinn-phong", color = \1, ks = 0.2, exponent = 32' blinn-phong
each '{ type = "cook-torrance", color = \1, ks = 0.3, roughness = 0.2' cook-torrance
each '{ type = "coated", base = { type = "lambert", color = \1 }, roughness = 0.1' coated
each '{ type = "coated", base = { type = "metallic-roughness", color = \1, metallic = 0.5, roughness = 0.4 }, roughness = 0.05' coated-metallic-roughness
each '{ type = "metallic-roughness", color = \1, metallic = 0.5, roughness = 0.4' metallic-roughness
each '{ type = "metallic-roughness", color = \1, metallic = 0.5, roughness = 0.4, multiscatter = true' metallic-roughness-gltf
each '{ type = "sheen", base = { type = "lambert", color = \1 }' sheen
for m in ${MATERIALS:-lambert oren-nayar phong blinn-phong cook-torrance coated coated-metallic-roughness metallic-roughness metallic-roughness-gltf sheen}; do
    for r in $(seq "$rounds"); do
        for bin in "$@"; do
            t=$("$bin" render "$tmp/$m.toml" -o "$tmp/out.exr" --threads 1 --spp "$spp" 2>&1 | grep -o "in [0-9.]* s" | cut -d' ' -f2)
            echo "$m $(basename "$bin") $t"
        done
    done
done | python3 -c "
import collections, statistics, sys
times = collections.defaultdict(list)
for line in sys.stdin:
    m, b, t = line.split()
    times[(m, b)].append(float(t))
bins = list(dict.fromkeys(b for _, b in times))
print('| material | ' + ' | '.join(bins) + ' |')
print('|---|' + '---|' * len(bins))
for m in dict.fromkeys(m for m, _ in times):
    print(f'| {m} | ' + ' | '.join(f'{statistics.median(times[(m, b)]):.3f} s' for b in bins) + ' |')
"
