#!/usr/bin/env bash
# Photon mapping against the path tracer at equal time on scenes/glass-ball-caustic.toml:
# RMSE against a converged path-traced reference, over the whole image and over the caustic
# (the pixels the reference shows brighter than twice the lit floor's median). Needs python3
# with numpy. Usage: bench/photon/caustic.sh [REFERENCE_SPP]
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release -q
bin=target/release/alhazen
scene=scenes/glass-ball-caustic.toml
out=$(mktemp -d)
ref_spp=${1:-16384}
$bin render $scene --spp "$ref_spp" -o "$out/ref.pfm" --quiet
time_of() { /usr/bin/time -f %e "$@" 2>&1 >/dev/null | tail -1; }
for spp in 16 64 256; do
    t_path=$(time_of $bin render $scene --spp $spp -o "$out/path-$spp.pfm" --quiet)
    t_photon=$(time_of $bin render $scene --integrator photon --spp $spp -o "$out/photon-$spp.pfm" --quiet)
    python3 - "$out" $spp "$t_path" "$t_photon" <<'PY'
import sys, numpy as np
out, spp, tp, tq = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
def pfm(p):
    with open(p, 'rb') as f:
        f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
        return np.frombuffer(f.read(), dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3)[::-1].astype(float)
ref = pfm(f'{out}/ref.pfm')
lum = ref.mean(axis=2)
caustic = lum > 2 * np.median(lum[lum > 0.01])
def rmse(img, mask=None):
    d = ((img - ref) ** 2).mean(axis=2)
    return float(np.sqrt(d[mask].mean() if mask is not None else d.mean()))
a, b = pfm(f'{out}/path-{spp}.pfm'), pfm(f'{out}/photon-{spp}.pfm')
print(f'{spp:>4} spp  path {tp:6.2f} s  rmse {rmse(a):.4f} (caustic {rmse(a, caustic):.4f})   '
      f'photon {tq:6.2f} s  rmse {rmse(b):.4f} (caustic {rmse(b, caustic):.4f})   caustic pixels {int(caustic.sum())}')
PY
done
rm -rf "$out"
