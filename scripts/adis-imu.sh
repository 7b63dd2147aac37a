#!/usr/bin/env bash
# Analyse every run of the real ADIS16405 recordings (../shared/data/real/imudata_adis16405, runs 1–4,
# 10 000 s at 100 Hz each; not shipped: their licence, CC BY-NC-SA 4.0, forbids it) as an integrator
# would: `rwcalc imu` with its report page, figure and Kalibr noise file per run, then one Markdown
# table of every run and axis (N, B, K with 95 % intervals, χ²/dof) — the table of docs/imu.md,
# "ADIS16405: all six channels".
#
# Usage: scripts/adis-imu.sh [RWCALC] [OUTDIR] [DATADIR]
#   RWCALC   the rwcalc binary (default build/rwcalc)
#   OUTDIR   where each run's report directory goes: OUTDIR/run1 … (default adis-imu/)
#   DATADIR  the recordings (default ../shared/data/real/imudata_adis16405 beside the checkout)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rw="${1:-$here/build/rwcalc}"
out="${2:-adis-imu}"
data="${3:-$here/../shared/data/real/imudata_adis16405}"
[[ -x "$rw" ]] || { echo "adis-imu.sh: $rw is not an executable rwcalc" >&2; exit 2; }
[[ -d "$data" ]] || { echo "adis-imu.sh: $data not found (the ADIS16405 recordings; see docs/imu.md)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "adis-imu.sh: python3 is needed for the table" >&2; exit 2; }
mkdir -p "$out"
for run in 1 2 3 4; do
  "$rw" imu "$data/adis_16405_imu$run.csv.gz" --rate 100 \
    --gyro gyro_x_dps,gyro_y_dps,gyro_z_dps --accel acc_x_g,acc_y_g,acc_z_g \
    --report "$out/run$run" --force --quiet >/dev/null
done
python3 - "$out" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
def cell(c):
    if not c["resolved"]:
        return f"< {c['value']:.4g}"
    return f"{c['value']:.4g} [{c['low95']:.3g}, {c['high95']:.3g}]"
print("| run | column | N | B | K | N SI | χ²/dof |")
print("|---|---|---|---|---|---|---|")
for run in (1, 2, 3, 4):
    j = json.load(open(out / f"run{run}" / "imu.json"))
    for ch in j["channels"]:
        f = ch["fit"]
        chi2 = f["chi2_per_dof"]
        rejected = " rejected" if f["p_value"] is not None and f["p_value"] < 0.001 else ""
        print(f"| {run} | {ch['column']} | {cell(f['N'])} | {cell(f['B'])} | {cell(f['K'])} | "
              f"{f['N']['si']['value']:.3e} | {chi2:.2f}{rejected} |")
print()
print(f"Units: gyros N °/√h, B °/h, K °/h/√h; accelerometers N m/s/√h, B µg, K m/s/h/√h; N SI in rad/s/√Hz or m/s²/√Hz. "
      f"Each run's page: {out}/runN/index.html")
PY
