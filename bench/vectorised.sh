#!/usr/bin/env bash
# Which of the path tracer's lane kernels the compiler vectorised: for every instance of the
# functions compiled for a vector unit (the material kernels `shade_avx2`/`shade_avx512`, the
# light sampling `sample_lights_*`, the Sobol and environment-map loops), how many instructions
# use 256- or 512-bit registers. An instance with none runs one lane at a time: its loop did
# not vectorise (BENCHMARKS.md, session 36: byte-wide flags kept every AVX2 kernel scalar).
#
#   bench/vectorised.sh [BINARY]      (default target/release/alhazen; needs nm and objdump)
#
# Exits 1 when some instance has no vector register, listing it.
set -euo pipefail
bin=${1:-target/release/alhazen}
pattern='lanes::shade_avx2|lanes::shade_avx512|lanes::sample_lights_avx|sampler::sobol_points_avx|envmap::EnvMap::texels_avx'
scalar=0
while read -r addr size _ name; do
    start=$((16#$addr)) end=$((16#$addr + 16#$size))
    wide=$(objdump -d --no-show-raw-insn --start-address=$start --stop-address=$end "$bin" | grep -cE '%[yz]mm' || true)
    printf '%-48s %8s %6d bytes %6d wide\n' "$name" "$addr" $((16#$size)) "$wide"
    [ "$wide" -gt 0 ] || scalar=$((scalar + 1))
done < <(nm -S -C "$bin" | grep -E " [tT] .*($pattern)")
if [ "$scalar" -gt 0 ]; then
    echo "$scalar instance(s) without vector registers" >&2
    exit 1
fi
