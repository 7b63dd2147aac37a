#!/usr/bin/env bash
# Installs the Debian 12 packages rwcalc needs to build, test, package and draw figures, those not
# installed yet: as root directly, otherwise through sudo. The one list of them (CI uses it too).
# ninja-build: the presets' generator (it compiles the layers' units side by side; make waits for
# each library before compiling the next layer).
# libsqlite3-dev, libbz2-dev, liblz4-dev, libzstd-dev: ROS bags; g++-11: CI's build with the oldest
# compiler supported (Ubuntu 22.04's); libyaml-dev: the lab profile of report --lab-profile; pandoc:
# report --docx and its tests (optional at run time; chromium, which prints report --pdf, is left
# out for its size, about 290 MB: `apt-get install chromium poppler-utils` runs the PDF tests too).
# clang-format, clang-tidy: the style checks (scripts/lint.sh). python3-jsonschema: the test
# result_schema validates every JSON output against docs/result.schema.json. libfftw3-dev: the
# simulator's flicker FFT (single precision, libfftw3f).
set -euo pipefail
PACKAGES=(cmake g++ make ninja-build libeigen3-dev libcli11-dev libfmt-dev nlohmann-json3-dev zlib1g-dev libssl-dev libboost-dev
          libgtest-dev libbenchmark-dev gnuplot-nox python3-numpy time dpkg-dev man-db gettext python3-yaml
          libsqlite3-dev libbz2-dev liblz4-dev libzstd-dev g++-11 libyaml-dev pandoc
          clang-format clang-tidy python3-jsonschema libfftw3-dev)
missing=()
for p in "${PACKAGES[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
((${#missing[@]})) || exit 0
if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null; then
  as_root=(sudo)
else
  echo "install-deps.sh: installing ${missing[*]} needs root; run this as root or install sudo" >&2
  exit 1
fi
echo "installing: ${missing[*]}"
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
