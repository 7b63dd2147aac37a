#!/usr/bin/env bash
# The golden-output test: runs scripts/golden.sh with the built rwcalc and compares its outputs with
# those recorded in tests/golden/outputs as data (tests/golden/compare.py: strings and integers
# exactly, floating numbers within 1e-9 relative, the pulse records byte for byte). An intended
# change of output is recorded again with
#   scripts/golden.sh DIR && tests/golden/compare.py record DIR tests/golden/outputs
# and the commit says why the outputs changed. Outputs whose input is absent (no ../shared/data)
# are not compared.
# Usage: tests/golden/check.sh RWCALC
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="$(mktemp -d "${TMPDIR:-/tmp}/rwcalc-golden.XXXXXX")"
trap 'rm -rf "$out"' EXIT
"$here/../../scripts/golden.sh" "$out" "$1" >/dev/null
if [[ -s "$out/SKIPPED" ]]; then echo "not compared (input absent):"; sed 's/^/  /' "$out/SKIPPED"; fi
exec python3 "$here/compare.py" check "$here/outputs" "$out"
