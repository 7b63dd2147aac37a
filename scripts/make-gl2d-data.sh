#!/usr/bin/env bash
# Regenerate data/gl2d: five simulated 2-h, 400 Hz GL-2D runs at -50, -25, 0, +25, +50 °C.
#
# Usage: scripts/make-gl2d-data.sh [RWCALC] [OUTDIR]
#   RWCALC  the built executable (default: build/rwcalc)
#   OUTDIR  where to write (default: data/gl2d)
#
# The output is bit-for-bit reproducible: the same seed gives the same pulse file on any run
# (the generator is fully specified: xoshiro256++ streams, our own ziggurat normals, no threads).
# Coefficients: the GL-2D characterisation by the AV method (Bolotnov & Fomin), N in °/√h and
# B in °/h; Earth rate at 55.75° N; pulse weight 0.92″; white (dither-like) read-out; no K, no R.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rwcalc="${1:-$here/build/rwcalc}"
out="${2:-$here/data/gl2d}"
mkdir -p "$out"

#   name  temperature_C  N_deg_per_sqrt_h  B_deg_per_h  seed
runs=(
  "m50C -50 0.00085 0.0083 52339050"
  "m25C -25 0.00079 0.0076 52339025"
  "0C     0 0.00081 0.0073 52339000"
  "p25C  25 0.00090 0.0078 52339125"
  "p50C  50 0.00098 0.0081 52339150"
)
for r in "${runs[@]}"; do
  read -r name temp n b seed <<<"$r"
  "$rwcalc" simulate -o "$out/gl2d_$name.csv.gz" --truth "$out/gl2d_$name.truth.json" --force \
    --duration 7200 --rate 400 --scale 0.92 --latitude 55.75 --white-readout \
    --arw "$n" --bias-instability "$b" --temperature "$temp" --seed "$seed"
done
