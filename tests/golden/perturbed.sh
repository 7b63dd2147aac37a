#!/usr/bin/env bash
# Discrete outcomes must not hang on the last digits of a floating result, which differ between
# processors. This runs scripts/golden.sh on copies of its inputs whose floating values are moved
# by a relative 1e-12 (the rate samples of the reference and ADIS16405 records, alternately up and
# down; the sample rate and pulse weight in the GL-2D files' headers) and requires every integer
# and string of every output (noise types α, classes, counts, named effects, messages with their
# decimals masked) to be as recorded in tests/golden/outputs. Floating numbers are not compared.
# Usage: tests/golden/perturbed.sh RWCALC
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
src="$(cd "$here/../.." && pwd)"
rw="$(realpath "$1")"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/rwcalc-perturbed.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
# The same relative layout as a checkout with ../shared beside it, so outputs name the same files.
mkdir -p "$tmp/main/scripts" "$tmp/main/data"
cp "$src/scripts/golden.sh" "$tmp/main/scripts/"
python3 "$here/perturb_inputs.py" 1e-12 "$src" "$tmp/main"
"$tmp/main/scripts/golden.sh" "$tmp/out" "$rw" >/dev/null 2>"$tmp/stderr" || { cat "$tmp/stderr"; exit 1; }
if [[ -s "$tmp/out/SKIPPED" ]]; then echo "not compared (input absent):"; sed 's/^/  /' "$tmp/out/SKIPPED"; fi
exec python3 "$here/compare.py" check "$here/outputs" "$tmp/out" --discrete
