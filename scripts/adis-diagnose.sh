#!/usr/bin/env bash
# Diagnose every run and gyro axis of the ADIS16405 recordings in ../shared/data/real/ and print one
# Markdown table (docs/adis16405.md, "Diagnosis"): base model misfit and coverage, the named effects
# with their parameters, the extended model's misfit and coverage, and the out-of-sample −2 ln L per
# block; then the table of which findings repeat across runs and axes (each detector's verdict,
# statistic against its threshold).
#
# Usage: scripts/adis-diagnose.sh [RWCALC] [OUTDIR]
#   RWCALC  the rwcalc binary (default build/rwcalc)
#   OUTDIR  where the JSON of each diagnosis is written (default adis-diagnose/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rw="${1:-$here/build/rwcalc}"
out="${2:-adis-diagnose}"
data="$here/../shared/data/real/imudata_adis16405"
[[ -x "$rw" ]] || { echo "adis-diagnose.sh: $rw is not an executable rwcalc" >&2; exit 2; }
[[ -d "$data" ]] || { echo "adis-diagnose.sh: $data not found (the shared reference data)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "adis-diagnose.sh: python3 is needed for the table" >&2; exit 2; }
mkdir -p "$out"
for run in 1 2 3 4; do
  for axis in x y z; do
    "$rw" diagnose "$data/adis_16405_imu$run.csv.gz" --input rate --rate-unit deg/s --rate 100 \
      --column "gyro_${axis}_dps" --earth-rate 0 --json -o "$out/run${run}_$axis.json" --force
  done
done
python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
def fmt_finding(f):
    e = f["effect"]; p = f["parameters"]
    labels = {"deg/h": "°/h"}
    def v(k, d=3):
        s = f"{p[k]['value']:.{d}g}"
        if p[k]["standard_uncertainty"] is not None: s += f" ± {p[k]['standard_uncertainty']:.2g}"
        return s + " " + labels.get(p[k]["unit"], p[k]["unit"])
    if e == "sinusoid":
        ev = f.get("evidence", {})
        s = f"sinusoid {v('frequency')}, {v('amplitude')}"
        if ev.get("coherent") is False: s += f" (broadened, width {ev['width_hz']:.2g} Hz)"
        return s
    if e == "gauss_markov": return f"Gauss–Markov σ {v('sigma')}, Tc {v('correlation_time')}"
    if e == "bias_step": return f"bias step {v('size')} at {v('time')}"
    if e == "warmup_transient": return f"warm-up {v('amplitude')}, τw {v('time_constant')}"
    if e == "lowpass": return f"low-pass τf {v('time_constant')}"
    return e
print("| run | axis | base misfit | base coverage | named effects | extended misfit | extended coverage | held-out gain −2Δ ln L |")
print("|---|---|---|---|---|---|---|---|")
for run in (1, 2, 3, 4):
    for axis in "xyz":
        j = json.load(open(out / f"run{run}_{axis}.json"))
        g = j["gain"]
        names = "; ".join(fmt_finding(f) for f in j["findings"]) or "none"
        print(f"| {run} | {axis.upper()} | {g['misfit_base']:.2f} | {100*g['coverage_base']:.0f} % | {names} | "
              f"{g['misfit_extended']:.2f} | {100*g['coverage_extended']:.0f} % | "
              + (f"{g['likelihood_holdout']:.1f} |" if g.get('likelihood_holdout') is not None else "— |"))
# Which findings repeat across runs and axes: each detector's verdict per run, with its statistic
# against its threshold (docs/diagnosis.md).
print()
print("| effect | axis | run 1 | run 2 | run 3 | run 4 |")
print("|---|---|---|---|---|---|")
cells = {}
for axis in "xyz":
    for run in (1, 2, 3, 4):
        j = json.load(open(out / f"run{run}_{axis}.json"))
        for d in j["detectors"]:
            st = "**named**" if d["named"] else ("fired" if d["fired"] else ("untested" if "test" not in d else "no"))
            cells.setdefault((d["effect"], axis), []).append(f"{st} {d['statistic']:.3g}/{d['threshold']:.3g}")
for e in ("sinusoid", "sinusoid_hf", "bias_step", "warmup_transient", "gauss_markov", "lowpass"):
    for axis in "xyz":
        if (e, axis) in cells:
            print(f"| {e} | {axis.upper()} | " + " | ".join(cells[(e, axis)]) + " |")
PY
