#!/usr/bin/env bash
# Golden outputs: run a fixed set of rwcalc commands on the shipped data (data/gl2d) and the
# reference data (../shared/data) and write each command's output to OUTDIR. OUTDIR/BYTE_IDENTICAL
# names the outputs that carry no floating result (pulse records), which are compared byte for
# byte; the others are compared as numbers (tests/golden/compare.py). tests/golden/check.sh does
# that in the test suite; `scripts/golden.sh DIR && tests/golden/compare.py record DIR
# tests/golden/outputs` records an intended change (the commit says why the outputs changed).
#
# Usage: scripts/golden.sh OUTDIR [RWCALC]
#   OUTDIR  directory for the outputs (created; its old outputs are replaced)
#   RWCALC  the rwcalc binary (default build/rwcalc)
# Commands whose input is absent (no ../shared/data) are skipped and listed in OUTDIR/SKIPPED.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:?usage: golden.sh OUTDIR [RWCALC]}"
rw="$(realpath "${2:-$here/build/rwcalc}")"
[[ -x "$rw" ]] || { echo "golden.sh: $rw is not an executable rwcalc" >&2; exit 2; }
mkdir -p "$out"
out="$(cd "$out" && pwd)"
rm -f "$out"/*.out "$out"/*.csv "$out"/*.gz "$out/SKIPPED" "$out/BYTE_IDENTICAL"
cd "$here"   # inputs are named relative to the checkout, so outputs do not depend on where it lives
ref=../shared/data/reference
adis=../shared/data/real/imudata_adis16405
gl=data/gl2d

# name  input-that-must-exist  command...
run() {
  local name="$1" need="$2"; shift 2
  if [[ ! -e "$need" ]]; then echo "$name (no $need)" >>"$out/SKIPPED"; return; fi
  "$rw" "$@" >"$out/$name.out"
}

for f in "$gl"/*.csv.gz; do
  t="$(basename "$f" .csv.gz)"
  run "analyze_${t}_json" "$f" analyze --json "$f"
done
run analyze_text "$gl/gl2d_0C.csv.gz" analyze "$gl/gl2d_0C.csv.gz"
run analyze_avg100 "$gl/gl2d_p25C.csv.gz" analyze --json --b-estimate avg100 "$gl/gl2d_p25C.csv.gz"
run batch_json "$gl/gl2d_0C.csv.gz" batch --json "$gl"/*.csv.gz
run batch_text "$gl/gl2d_0C.csv.gz" batch "$gl"/*.csv.gz
run batch_csv "$gl/gl2d_0C.csv.gz" batch --csv "$gl"/*.csv.gz
run batch_jsonl "$gl/gl2d_0C.csv.gz" batch --jsonl "$gl"/*.csv.gz
for est in oadev adev mdev; do
  # Every τ of a 2-h record is a 350-MB output whose comparison alone took minutes: the `all` grid
  # runs on the NBS14 record below and on an ADIS16405 axis (a real 10^6-point output).
  for grid in octave decade dense; do
    run "allan_gl2d_${est}_${grid}" "$gl/gl2d_m25C.csv.gz" allan --json --estimator "$est" --tau "$grid" "$gl/gl2d_m25C.csv.gz"
  done
  run "allan_gl2d_${est}_list" "$gl/gl2d_m25C.csv.gz" allan --json --estimator "$est" --tau 0.01,1,10,100 "$gl/gl2d_m25C.csv.gz"
  run "allan_nbs14_${est}_all" "$ref/nbs14_riley/nbs14_1000point_freq.txt" allan --json --estimator "$est" --tau all \
    --input rate --rate-unit 1 --rate 1 "$ref/nbs14_riley/nbs14_1000point_freq.txt"
done
run allan_text "$gl/gl2d_m50C.csv.gz" allan "$gl/gl2d_m50C.csv.gz"
run allan_csv "$gl/gl2d_m50C.csv.gz" allan --csv --tau decade "$gl/gl2d_m50C.csv.gz"
run allan_adis_x "$adis/adis_16405_imu1.csv.gz" allan --json --tau all --input rate --rate-unit deg/s --rate 100 \
  --column gyro_x_dps "$adis/adis_16405_imu1.csv.gz"
run analyze_adis_z "$adis/adis_16405_imu2.csv.gz" analyze --json --input rate --rate-unit deg/s --rate 100 \
  --column gyro_z_dps --earth-rate 0 "$adis/adis_16405_imu2.csv.gz"
run diagnose_gl2d "$gl/gl2d_0C.csv.gz" diagnose --json --seed 7 "$gl/gl2d_0C.csv.gz"
run diagnose_adis_y "$adis/adis_16405_imu1.csv.gz" diagnose --json --seed 1 --runs 30 --input rate --rate-unit deg/s \
  --rate 100 --column gyro_y_dps --earth-rate 0 "$adis/adis_16405_imu1.csv.gz"
run simulate_plain "$gl" simulate -o - --duration 600 --seed 3 --arw 0.004 --bias-instability 0.003 --rrw 0.002 --ramp 0.001
run simulate_effects "$gl" simulate -o - --duration 900 --seed 5 --arw 0.004 --white-readout --white-angle 0.3 \
  --sinusoid 0.01:0.05:0.3 --gauss-markov 0.02:30 --bias-step 400:0.03 --warmup 0.1:120 --bias 1.5
run simulate_fast "$gl" simulate -o - --duration 300 --rate 1000 --seed 11 --arw 0.01 --rrw 0.01 --no-earth-rate
printf '%s\n' simulate_plain.out simulate_effects.out simulate_fast.out >"$out/BYTE_IDENTICAL"
# The model file is named relative to OUTDIR, so its path (written as metadata) is the same everywhere.
if [[ -s "$out/analyze_gl2d_0C_json.out" ]]; then
  (cd "$out" && "$rw" simulate -o - --duration 600 --seed 2 --from analyze_gl2d_0C_json.out >simulate_from.out)
fi
# The diagnosis reports its own run time; that is the one field that may change between runs.
for f in "$out"/diagnose_*.out; do
  [[ -e "$f" ]] && sed -i -E 's/^(  "seconds": ).*,$/\1"(run time)",/' "$f"
done
echo "golden.sh: $(ls "$out" | grep -c '\.out$') outputs in $out"
