#!/usr/bin/env bash
# End-to-end benchmark of rwcalc against its acceptance targets, in one run, side by side:
#   1. `rwcalc analyze` of the 2-h 400 Hz record, as a whole process, is at least 25× faster than
#      the NumPy baseline (bench/numpy_oavar.py: numpy.loadtxt + AllanTools' overlapping-ADEV
#      algorithm on the octave grid), also as a whole process; the two alternate run by run so that
#      both see the same load;
#   2. `rwcalc analyze` of 24 h at 1 kHz (86.4 M samples) takes at most 3 s and 1.5 GB peak RSS, and
#      `rwcalc imu` of 6 channels × 24 h × 200 Hz at most 6 s (inputs from ../shared when present);
#      `rwcalc imu` of a 24-h 200-Hz ROS 1 bag in at most 2× the time of its rostopic CSV.
#   3. the default 50-run `rwcalc diagnose` of the 2-h record takes at most 1.5× AllanTools' own
#      oadev (with --allantools; without it, 1.5× the NumPy baseline, a stricter stand-in), side by
#      side as in 1.
# Other rows (dense grid, `allan`, `--tau all`, the `cat` floor, and with --allantools the floor of
# analyze's ratio: bench/floor_oadev.cpp, read + octave OADEV and nothing else, the fastest way
# measured) are figures without a target. It builds the `bench` preset if needed, generates the
# inputs with `rwcalc simulate`
# (cached under the build directory) and times whole processes (median of --repeat runs: wall
# clock from bash's EPOCHREALTIME, user+sys CPU from its `time`; peak RSS from /usr/bin/time -v).
# On a shared machine the CPU column is the load-independent figure; the ratio of target 1 is
# given for both wall and CPU time.
#
# Usage: bench/run-benchmarks.sh [--repeat N] [--build-dir DIR] [--no-build] [--skip-24h]
#                                [--skip-tau-all] [--kernels] [--allantools DIR] [--gate] [--floor X]
#   --repeat N        runs per measurement (default 5; the median is reported)
#   --build-dir D     build directory of the bench preset (default build-bench)
#   --no-build        use the existing build as it is
#   --skip-24h        skip the 24-h records (1-kHz pulses and the IMU; ~1 min each to generate once)
#   --skip-tau-all    skip `allan --tau all` and its growth with N
#   --kernels         also run the Google Benchmark kernels (bench_*) after the table
#   --allantools DIR  also time AllanTools' own oadev (bench/allantools_oadev.py, whole process)
#                     side by side with target 1, from a checkout of AllanTools in DIR (not part of
#                     rwcalc; needs python3-scipy); skipped when DIR holds no allantools package
#   --gate            the regression gate CI runs: target 1 alone on an existing build (never
#                     builds; give the release build with --build-dir build), both figures printed;
#                     exits 1 when analyze is less than --floor times as fast as the NumPy baseline
#                     in wall time
#   --floor X         the gate's floor (default 8.33: a third of the 25x target)
# Needs: cmake, g++, GNU time (/usr/bin/time; Debian package `time`), python3 with numpy
# (Debian python3-numpy) for the baseline rows. Commands this build lacks show "not available".
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
repeat=5 build="$here/build-bench" do_build=1 skip24=0 skipall=0 kernels=0 allantools="" gate=0 gate_floor=8.33
while (($#)); do
  case "$1" in
    --repeat) repeat="$2"; shift 2 ;;
    --build-dir) build="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --skip-24h) skip24=1; shift ;;
    --skip-tau-all) skipall=1; shift ;;
    --kernels) kernels=1; shift ;;
    --allantools) allantools="$2"; shift 2 ;;
    --gate) gate=1 do_build=0 skip24=1 skipall=1; shift ;;
    --floor) gate_floor="$2"; shift 2 ;;
    -h|--help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
    *) echo "run-benchmarks.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || { echo "run-benchmarks.sh: --repeat needs a positive integer" >&2; exit 2; }
[[ "$gate_floor" =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "run-benchmarks.sh: --floor needs a positive number" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "run-benchmarks.sh: GNU time is missing: apt-get install -y time" >&2; exit 2; }

# ---- build ------------------------------------------------------------------------------------
if ((do_build)); then
  if [[ ! -f "$build/CMakeCache.txt" ]]; then
    cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DRWCALC_BUILD_BENCH=ON -DRWCALC_BUILD_TESTS=OFF >/dev/null
  fi
  cmake --build "$build" -j2 >/dev/null
fi
rw="$build/rwcalc"
[[ -x "$rw" ]] || { echo "run-benchmarks.sh: $rw not built" >&2; exit 2; }
py=""
for p in /usr/bin/python3 python3; do
  if command -v "$p" >/dev/null && "$p" -c 'import numpy' 2>/dev/null; then py="$p"; break; fi
done

# ---- inputs (cached; regenerated only when missing) -------------------------------------------
inputs="$build/bench-inputs"
mkdir -p "$inputs"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
gl2d() {  # gl2d NAME TEMP N B SEED [DURATION_S]: one GL-2D-like run, as scripts/make-gl2d-data.sh
  local f="$inputs/gl2d_$1${6:+_$6s}.csv"
  [[ -s "$f" ]] || "$rw" simulate -o "$f" --force --duration "${6:-7200}" --rate 400 --scale 0.92 --latitude 55.75 \
    --white-readout --arw "$3" --bias-instability "$4" --temperature "$2" --seed "$5" >/dev/null
  echo "$f"
}
echo "generating inputs in $inputs (cached) ..." >&2
run2h="$(gl2d p50C 50 0.00098 0.0081 52339150)"
day="$inputs/day_1kHz.csv"
if ((!skip24)) && [[ ! -s "$day" ]]; then
  # 24 h at 1 kHz = 86.4 M samples (~180 MB of text). ARW + RRW + white read-out: the exact
  # flicker FFT of 173 M points would need ~7 GB to generate, and analyze time does not depend
  # on which noise the samples carry.
  echo "generating the 24-h 1 kHz record (once) ..." >&2
  "$rw" simulate -o "$day" --force --duration 86400 --rate 1000 --scale 0.92 --latitude 55.75 \
    --white-readout --arw 0.001 --rrw 0.0005 --seed 86400 >/dev/null
fi

# A 6-channel 24-h 200-Hz IMU record (17.28 M lines, ~660 MB): the ADIS16405 static run of
# ../shared/data/real repeated to a day (its own 100 Hz read as 200 Hz; the time does not depend on
# what the samples hold). Skipped without the shared data.
imu_day="$inputs/imu_day_200Hz.csv"
adis="$here/../shared/data/real/imudata_adis16405/adis_16405_imu1.csv.gz"
if ((!skip24)) && [[ ! -s "$imu_day" && -s "$adis" ]]; then
  echo "generating the 24-h 6-channel IMU record (once) ..." >&2
  { gzip -dc "$adis" | sed -n 3p  # the header row; then 17.28 copies of the 1 M data lines
    for _ in $(seq 17); do gzip -dc "$adis" | sed -n '4,$p'; done
    gzip -dc "$adis" | sed -n '4,280003p'; } >"$imu_day.part" && mv "$imu_day.part" "$imu_day"
fi

# A 24-h 200-Hz static IMU as a ROS 1 bag and as its `rostopic echo -p` CSV (bench/make_ros_imu.py;
# about 6.3 GB and 3.5 GB, ~8 min to write once, mostly the disk's time). Skipped without numpy.
ros_bag="$inputs/imu_day_200Hz.bag" ros_csv="$inputs/imu_day_200Hz_rostopic.csv"
if ((!skip24)) && [[ -n "${py:-}" && ( ! -s "$ros_bag" || ! -s "$ros_csv" ) ]]; then
  echo "generating the 24-h 200-Hz ROS 1 bag and its rostopic CSV (once) ..." >&2
  "$py" "$here/bench/make_ros_imu.py" "$ros_bag.part" "$ros_csv.part" && mv "$ros_bag.part" "$ros_bag" &&
    mv "$ros_csv.part" "$ros_csv"
fi

# ---- measurement helpers ----------------------------------------------------------------------
calc() { awk "BEGIN { print $1 }"; }  # arithmetic without bc
loadavg() { cut -d' ' -f1 /proc/loadavg; }
# measure N CMD...: run CMD N times; sets med_s (median wall s), cpu_s (median user+sys CPU s),
# rss_mb (largest peak RSS, MB), status (exit status of the last failing run, else 0). Wall and
# CPU time are the process's own, with no wrapper process in between: the wall from bash's
# EPOCHREALTIME around it (µs), the CPU from bash's `time` (the child's rusage, ms); peak RSS comes
# from /usr/bin/time -v around up to three further runs (GNU time's own start would otherwise add
# 1–2 ms to every wall time). Each run writes new files: the last run's are removed first, outside
# the timed part, because a file truncated and written again is flushed to disk when it is closed
# (ext4's auto_da_alloc), a cost of the file system that would be timed as the process's own.
measure() {
  local n="$1"; shift
  local times=() cpus=() rss=0 r t0 t1 u sy
  local TIMEFORMAT='%3U %3S'
  status=0
  for ((i = 0; i < n; i++)); do
    rm -f "$tmp/out.txt" "$tmp/err.txt" "$tmp/t.txt"
    t0=$EPOCHREALTIME
    if { time "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"; } 2>"$tmp/t.txt"; then :; else status=$?; fi
    t1=$EPOCHREALTIME
    read -r u sy <"$tmp/t.txt" || true
    times+=("$(calc "$t1 - $t0")")
    cpus+=("$(calc "${u:-0} + ${sy:-0}")")
    ((status)) && break
    if ((i < 3)); then
      /usr/bin/time -v -o "$tmp/time.txt" "$@" >/dev/null 2>&1 || true
      r=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$tmp/time.txt")
      ((${r:-0} > rss)) && rss=$r
    fi
  done
  med_s=$(median "${times[@]}")
  cpu_s=$(median "${cpus[@]}")
  rss_mb=$(calc "$rss / 1024")
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
# available SUBCOMMAND: true when this build implements it.
available() { "$rw" "$1" --help >/dev/null 2>&1 && ! "$rw" "$1" --help 2>&1 | grep -q "not yet available"; }
has_option() { "$rw" "$1" --help 2>&1 | grep -q -- "$2"; }

rows=()
# row TARGET LIMIT WALL CPU RSS RESULT LOAD
row() { rows+=("$(printf '| %s | %s | %s | %s | %s | %s | %s |' "$@")"); }
fmt_ms() { printf '%.0f ms' "$(calc "$1 * 1000")"; }
fmt_s() { printf '%.2f s' "$1"; }
fmt_mb() { printf '%.0f MB' "$1"; }
verdict() { if awk "BEGIN { exit !($1) }"; then echo "met"; else echo "**missed**"; fi; }
failed() { echo "failed (exit $status: $(head -c 120 "$tmp/err.txt" | tr '\n|' '  '))"; }

# ---- the targets ------------------------------------------------------------------------------
echo "measuring (median of $repeat runs each) ..." >&2
# timed ROW LIMIT CONDITION CMD...: one row with wall, CPU and RSS; CONDITION is an awk expression
# over w (wall s), c (CPU s) and r (RSS MB) that says whether the target is met ("" for none).
timed() {
  local name="$1" limit="$2" cond="$3" l; shift 3
  l=$(loadavg); measure "$repeat" "$@"
  if ((status)); then row "$name" "$limit" "$(failed)" "" "" "" "$l"; return 1; fi
  local res=""
  [[ -n "$cond" ]] && res=$(verdict "$(echo "$cond" | sed "s/\bw\b/$med_s/g; s/\bc\b/$cpu_s/g; s/\br\b/$rss_mb/g")")
  row "$name" "$limit" "$(fmt_t "$med_s")" "$(fmt_t "$cpu_s")" "$(fmt_mb "$rss_mb")" "$res" "$l"
}
fmt_t() { awk -v t="$1" 'BEGIN { if (t < 1) printf "%.0f ms", t * 1000; else printf "%.2f s", t }'; }

# side_by_side N CMD_A -- CMD_B: alternate A and B N times; sets a_s/a_c and b_s/b_c (median wall
# and CPU seconds of each), rss_mb (A's peak RSS) and status.
side_by_side() {
  local n="$1"; shift
  local a=() b=() wa=() ca=() wb=() cb=() rss=0 st=0
  while [[ "$1" != "--" ]]; do a+=("$1"); shift; done; shift; b=("$@")
  for ((k = 0; k < n; k++)); do
    measure 1 "${a[@]}"; wa+=("$med_s"); ca+=("$cpu_s"); ((status)) && st=$status
    rss=$(awk -v x="$rss_mb" -v y="$rss" 'BEGIN { print (x > y) ? x : y }')
    measure 1 "${b[@]}"; wb+=("$med_s"); cb+=("$cpu_s"); ((status)) && st=$status
    ((st)) && break
  done
  a_s=$(median "${wa[@]}") a_c=$(median "${ca[@]}") b_s=$(median "${wb[@]}") b_c=$(median "${cb[@]}")
  rss_mb=$rss status=$st
}

# The gate: target 1 alone, both figures, and the verdict in the exit status. A ratio of two
# processes measured together, never an absolute time: a loaded machine slows both.
if ((gate)); then
  available analyze || { echo "run-benchmarks.sh: $rw has no analyze command" >&2; exit 2; }
  [[ -n "$py" ]] || { echo "run-benchmarks.sh: --gate needs python3 with numpy (python3-numpy)" >&2; exit 2; }
  side_by_side "$repeat" "$rw" analyze "$run2h" --json -- "$py" "$here/bench/numpy_oavar.py" "$run2h" --grid octave
  ((status)) && { echo "run-benchmarks.sh: a run failed (exit $status): $(head -c 300 "$tmp/err.txt")" >&2; exit 2; }
  sw=$(calc "$b_s / $a_s") sc=$(calc "$b_c / $a_c")
  printf 'analyze of the 2-h 400-Hz file vs the NumPy baseline (read + octave OADEV), median of %s alternating runs:\n' "$repeat"
  printf '  rwcalc analyze: %s wall, %s CPU;  NumPy baseline: %s wall, %s CPU\n' \
    "$(fmt_t "$a_s")" "$(fmt_t "$a_c")" "$(fmt_t "$b_s")" "$(fmt_t "$b_c")"
  printf '  ratio: %.1fx wall (%.1fx CPU); floor %sx (target 25x); load %s\n' "$sw" "$sc" "$gate_floor" "$(loadavg)"
  if awk "BEGIN { exit !($sw < $gate_floor) }"; then
    printf 'benchmark gate: FAILED: analyze is %.2fx as fast as the baseline, below the floor of %sx\n' "$sw" "$gate_floor" >&2
    exit 1
  fi
  echo "benchmark gate: passed"
  exit 0
fi

speed_name="analyze 2-h 400 Hz vs NumPy read + octave OADEV (whole processes)"
# analyze_vs NAME PEER_CMD...: analyze of the 2-h file side by side with a peer process; its row,
# the target met when analyze is at least 25 times as fast in wall time.
analyze_vs() {
  local name="$1" l; shift
  l=$(loadavg)
  side_by_side "$repeat" "$rw" analyze "$run2h" --json -- "$@"
  if ((status)); then row "$name" "≥ 25× faster" "$(failed)" "" "" "" "$l"; return; fi
  local sw sc
  sw=$(calc "$b_s / $a_s") sc=$(calc "$b_c / $a_c")
  row "$name" "≥ 25× faster" \
    "$(printf '%.1f× (%s vs %s)' "$sw" "$(fmt_t "$a_s")" "$(fmt_t "$b_s")")" \
    "$(printf '%.1f× (%s vs %s)' "$sc" "$(fmt_t "$a_c")" "$(fmt_t "$b_c")")" \
    "$(fmt_mb "$rss_mb")" "$(verdict "$sw >= 25")" "$l"
}
if ! available analyze; then
  row "$speed_name" "≥ 25× faster" "not available" "" "" "" ""
elif [[ -z "$py" ]]; then
  row "$speed_name" "≥ 25× faster" "not measured (no python3 with numpy)" "" "" "" ""
else
  analyze_vs "$speed_name" "$py" "$here/bench/numpy_oavar.py" "$run2h" --grid octave
fi
# The floor of that ratio: bench/floor_oadev.cpp (read + octave OADEV, nothing else, the fastest
# way measured) side by side with AllanTools; analyze does all that and more.
floor_vs_allantools() {
  local name="floor: bench/floor_oadev.cpp (read + octave OADEV only) vs AllanTools' own oadev" l
  if ! "${CXX:-g++}" -O2 -std=c++20 -pthread "$here/bench/floor_oadev.cpp" -o "$tmp/floor_oadev" 2>"$tmp/err.txt"; then
    row "$name" "analyze's ceiling" "not built: $(head -c 200 "$tmp/err.txt")" "" "" "" ""
    return
  fi
  l=$(loadavg)
  side_by_side "$repeat" "$tmp/floor_oadev" "$run2h" -- "$py" "$here/bench/allantools_oadev.py" "$allantools" "$run2h"
  if ((status)); then row "$name" "analyze's ceiling" "$(failed)" "" "" "" "$l"; return; fi
  row "$name" "analyze's ceiling" \
    "$(printf '%.1f× (%s vs %s)' "$(calc "$b_s / $a_s")" "$(fmt_t "$a_s")" "$(fmt_t "$b_s")")" \
    "$(printf '%.1f× (%s vs %s)' "$(calc "$b_c / $a_c")" "$(fmt_t "$a_c")" "$(fmt_t "$b_c")")" \
    "$(fmt_mb "$rss_mb")" "" "$l"
}
at_name="analyze 2-h 400 Hz vs AllanTools' own oadev (read + octave OADEV, whole processes)"
if [[ -n "$allantools" ]]; then
  if [[ ! -f "$allantools/allantools/__init__.py" ]]; then
    row "$at_name" "≥ 25× faster" "skipped (no allantools package in $allantools)" "" "" "" ""
  elif [[ -z "$py" ]] || ! "$py" -c 'import scipy' 2>/dev/null; then
    row "$at_name" "≥ 25× faster" "skipped (AllanTools needs python3 with numpy and scipy)" "" "" "" ""
  elif available analyze; then
    analyze_vs "$at_name" "$py" "$here/bench/allantools_oadev.py" "$allantools" "$run2h"
    floor_vs_allantools
  fi
fi
if available analyze; then
  if ((!skip24)); then
    timed "analyze 24-h 1 kHz (86.4 M samples)" "≤ 3 s, ≤ 1.5 GB" "w <= 3 && r <= 1536" \
      "$rw" analyze "$day" --json || true
  fi
  if [[ -s "$imu_day" ]] && available imu; then
    timed "imu 6 channels × 24 h × 200 Hz (17.28 M lines)" "≤ 6 s" "w <= 6" "$rw" imu "$imu_day" --rate 200 --json \
      --gyro gyro_x_dps,gyro_y_dps,gyro_z_dps --accel acc_x_g,acc_y_g,acc_z_g || true
  fi
  if ((!skip24)) && [[ -s "$ros_bag" ]] && has_option imu --topic; then
    bag_name="imu 24-h 200-Hz ROS 1 bag vs its rostopic CSV (side by side)" l=$(loadavg)
    side_by_side "$repeat" "$rw" imu "$ros_bag" --json -- "$rw" imu "$ros_csv" --json
    if ((status)); then
      row "$bag_name" "≤ 2× the CSV's time" "$(failed)" "" "" "" "$l"
    else
      bw=$(calc "$a_s / $b_s") bc=$(calc "$a_c / $b_c")
      row "$bag_name" "≤ 2× the CSV's time" "$(printf '%.2f× (%s vs %s)' "$bw" "$(fmt_t "$a_s")" "$(fmt_t "$b_s")")" \
        "$(printf '%.2f× (%s vs %s)' "$bc" "$(fmt_t "$a_c")" "$(fmt_t "$b_c")")" "$(fmt_mb "$rss_mb")" \
        "$(verdict "$bw <= 2")" "$l"
    fi
  fi
  if has_option analyze --tau; then
    timed "analyze 2-h, dense grid (20/decade to N/10)" "—" "" "$rw" analyze "$run2h" --json --tau dense || true
  fi
elif ((!skip24)); then
  row "analyze 24-h 1 kHz (86.4 M samples)" "≤ 3 s, ≤ 1.5 GB" "not available" "" "" "" ""
fi

# diagnose, side by side with AllanTools' own oadev (import, read, octave OADEV) when --allantools
# gives it: the default 50-run diagnosis of the 2-h 400 Hz record in at most 1.5× its time. Without
# AllanTools the NumPy baseline (the same algorithm without AllanTools' import, about half its time)
# stands in for it with the same limit, a stricter one; with AllanTools the NumPy row is a figure.
# A build whose command answers that it is not available gets "n/a".
diag_name="diagnose 2-h 400 Hz (50 runs) vs NumPy read + octave OADEV"
have_allantools=0
if [[ -n "$allantools" && -f "$allantools/allantools/__init__.py" && -n "$py" ]] && "$py" -c 'import scipy' 2>/dev/null; then
  have_allantools=1
fi
if ! available diagnose; then
  row "$diag_name" "≤ 1.5× NumPy" "n/a (diagnose not available)" "" "" "" ""
elif [[ -z "$py" ]]; then
  timed "$diag_name" "≤ 1.5× NumPy" "" "$rw" diagnose "$run2h" --json --runs 50 || true
else
  l=$(loadavg)
  side_by_side "$repeat" "$rw" diagnose "$run2h" --json --runs 50 -- "$py" "$here/bench/numpy_oavar.py" "$run2h" --grid octave
  if ((status)); then row "$diag_name" "≤ 1.5× NumPy" "$(failed)" "" "" "" "$l"
  else
    dw=$(calc "$a_s / $b_s") dc=$(calc "$a_c / $b_c")
    if ((have_allantools)); then limit="(vs NumPy)" result=""; else limit="≤ 1.5× NumPy" result=$(verdict "$dw <= 1.5"); fi
    row "$diag_name" "$limit" \
      "$(printf '%.2f× (%s vs %s)' "$dw" "$(fmt_t "$a_s")" "$(fmt_t "$b_s")")" \
      "$(printf '%.2f× (%s vs %s)' "$dc" "$(fmt_t "$a_c")" "$(fmt_t "$b_c")")" \
      "$(fmt_mb "$rss_mb")" "$result" "$l"
  fi
  if ((have_allantools)); then
    at_diag="diagnose 2-h 400 Hz (50 runs) vs AllanTools' own oadev (read + octave OADEV, whole processes)"
    l=$(loadavg)
    side_by_side "$repeat" "$rw" diagnose "$run2h" --json --runs 50 -- "$py" "$here/bench/allantools_oadev.py" "$allantools" "$run2h"
    if ((status)); then row "$at_diag" "≤ 1.5× AllanTools" "$(failed)" "" "" "" "$l"
    else
      dw=$(calc "$a_s / $b_s") dc=$(calc "$a_c / $b_c")
      row "$at_diag" "≤ 1.5× AllanTools" \
        "$(printf '%.2f× (%s vs %s)' "$dw" "$(fmt_t "$a_s")" "$(fmt_t "$b_s")")" \
        "$(printf '%.2f× (%s vs %s)' "$dc" "$(fmt_t "$a_c")" "$(fmt_t "$b_c")")" \
        "$(fmt_mb "$rss_mb")" "$(verdict "$dw <= 1.5")" "$l"
    fi
  fi
fi

if available allan; then
  timed "allan 2-h, octave grid (21 τ)" "(vs NumPy)" "" "$rw" allan "$run2h" --json && allan_oct=$med_s
  timed "allan 2-h, dense grid" "(vs NumPy)" "" "$rw" allan "$run2h" --json --tau dense && allan_dense=$med_s
  if ((!skipall)); then
    # Growth with N: the same model at 1/8, 1/4, 1/2 and the full 2 h; one run each (capped).
    prev="" growth="" expo=""
    for dur in 900 1800 3600 7200; do
      f="$run2h"; ((dur < 7200)) && f="$(gl2d p50C 50 0.00098 0.0081 52339150 "$dur")"
      l=$(loadavg); measure 1 timeout 900 "$rw" allan "$f" --json --tau all
      if ((status)); then growth+=" ${dur}s: exit $status;"; break; fi
      growth+=" $((dur * 400 / 1000))k: $(fmt_t "$med_s") wall, $(fmt_t "$cpu_s") CPU;"
      if [[ -n "$prev" ]]; then expo=$(calc "log($cpu_s / $prev) / log(2)"); fi
      prev=$cpu_s; last_wall=$med_s; last_rss=$rss_mb
    done
    if [[ -n "$prev" && $status -eq 0 ]]; then
      dep=""
      if [[ -n "$py" ]]; then
        # Departure of the FFT path from the exact kernel: 40 log-spaced τ of the same record
        # through an explicit list (always exact), against the `all` output.
        cp "$tmp/out.txt" "$tmp/all.json"
        list=$("$py" -c 'import json,sys; j=json.load(open(sys.argv[1])); m0=j.get("fft_from_af",1); n=len(j["points"]); t=j["tau0_s"]
ms=sorted({int(round(m0*(n/m0)**(i/39))) for i in range(40)}); print(",".join(repr(m*t) for m in ms))' "$tmp/all.json")
        if "$rw" allan "$run2h" --json --tau "$list" >"$tmp/exact.json" 2>/dev/null; then
          dep=$("$py" -c 'import json,sys; a={p["af"]:p["dev"] for p in json.load(open(sys.argv[1]))["points"]}
e=json.load(open(sys.argv[2]))["points"]; print("%.1e" % max(abs(a[p["af"]]/p["dev"]-1) for p in e))' "$tmp/all.json" "$tmp/exact.json")
          dep="; FFT path vs exact at 40 τ: max relative σ departure $dep"
        fi
      fi
      row "allan --tau all, 2-h (every m to N/2)" "seconds; state growth" "$(fmt_t "$last_wall")" "$(fmt_t "$prev")" \
        "$(fmt_mb "$last_rss")" "$(printf 'CPU ∝ N^%.2f:%s%s' "${expo:-0}" "$growth" "$dep")" "$l"
    else
      row "allan --tau all, 2-h (every m to N/2)" "seconds; state growth" "not measured:$growth" "" "" "" "$l"
    fi
  fi
else
  row "allan 2-h, octave grid (21 τ)" "(vs NumPy)" "not available" "" "" "" ""
  ((skipall)) || row "allan --tau all, 2-h (every m to N/2)" "seconds; state growth" "not available" "" "" "" ""
fi

if [[ -n "$py" ]]; then
  for g in octave dense; do
    l=$(loadavg); measure "$repeat" "$py" "$here/bench/numpy_oavar.py" "$run2h" --grid "$g"
    ref=""; [[ $g == octave && -n "${allan_oct:-}" ]] && ref=$(printf 'rwcalc %.0f× faster' "$(calc "$med_s / $allan_oct")")
    [[ $g == dense && -n "${allan_dense:-}" ]] && ref=$(printf 'rwcalc %.0f× faster' "$(calc "$med_s / $allan_dense")")
    stage=$(grep -o 'load .*' "$tmp/err.txt" || true)
    row "NumPy baseline OADEV 2-h, $g grid" "baseline ($stage)" "$(fmt_t "$med_s")" "$(fmt_t "$cpu_s")" "$(fmt_mb "$rss_mb")" "$ref" "$l"
  done
else
  row "NumPy baseline OADEV 2-h" "baseline" "not available (no numpy)" "" "" "" ""
fi
timed "floor: cat of the 2-h file ($(du -k "$run2h" | cut -f1) kB)" "—" "" cat "$run2h" || true

# ---- the table --------------------------------------------------------------------------------
echo
echo "$("$rw" --version 2>/dev/null | head -1) — $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores," \
  "$(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -1); median of $repeat runs; load = 1-min load average"
echo
echo "| target | limit | wall (median) | CPU user+sys (median) | peak RSS | result | load |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"

if ((kernels)); then
  echo
  for b in "$build"/bench/bench_*; do [[ -x "$b" ]] && "$b" --benchmark_min_time=0.2 2>/dev/null; done
fi
