#!/usr/bin/env bash
# The golden check's own test, on copies of the recorded outputs (no rwcalc run): every floating
# number moved by a relative 1e-12 (far more than two processors' results differ) must pass; one
# number moved by 1e-6 must fail, naming the output, the key and both values; a changed word in a
# text output must fail, naming the line.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cmp="$here/compare.py"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/rwcalc-golden-self.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAILED: $*"; exit 1; }

python3 "$cmp" perturb 1e-12 "$here/outputs" "$tmp/all12"
python3 "$cmp" check "$here/outputs" "$tmp/all12" || fail "a 1e-12 move of every number was reported"

python3 "$cmp" perturb 1e-6 "$here/outputs" "$tmp/one6" --one
if python3 "$cmp" check "$here/outputs" "$tmp/one6" >"$tmp/one6.log"; then
  fail "a 1e-6 move of one number passed"
fi
cat "$tmp/one6.log"
[[ $(grep -c '^output changed: ' "$tmp/one6.log") -eq 1 ]] || fail "not exactly one output reported"
grep -qE '^output changed: [a-z0-9_]+\.out: \$[^:]*: recorded [-0-9.e]+, got [-0-9.e]+$' "$tmp/one6.log" \
  || fail "the report does not name the output, the key and both values"

# A word changed in a text output (the numbers untouched) is a difference, reported by line.
cp -r "$here/outputs" "$tmp/word"
python3 - "$tmp/word/analyze_text.out.gz" <<'PY'
import gzip, sys
text = gzip.open(sys.argv[1], "rt", encoding="utf-8").read().replace("samples at", "sample at", 1)
gzip.open(sys.argv[1], "wt", encoding="utf-8").write(text)
PY
if python3 "$cmp" check "$here/outputs" "$tmp/word" >"$tmp/word.log"; then fail "a changed word passed"; fi
grep -q '^output changed: analyze_text.out: line [0-9]*: recorded' "$tmp/word.log" || fail "no line named"

# A pulse record is compared byte for byte: another SHA-256 is a difference.
cp -r "$here/outputs" "$tmp/pulses"
sed -i '1s/^\(.\{63\}\)./\1x/' "$tmp/pulses/SHA256SUMS"
if python3 "$cmp" check "$here/outputs" "$tmp/pulses" >"$tmp/pulses.log"; then fail "another pulse record passed"; fi
grep -q '^output changed: simulate_[a-z]*\.out: bytes differ' "$tmp/pulses.log" || fail "no pulse record named"
echo "golden check self-test: passed"
