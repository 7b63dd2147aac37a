#!/usr/bin/env bash
# The golden-output test: runs scripts/golden.sh with the built rwcalc and compares each output's
# SHA-256 with tests/golden/SHA256SUMS, recorded from the same commands. An intended change of
# output is recorded again with: scripts/golden.sh DIR && cp DIR/SHA256SUMS tests/golden/
# and the commit says why the outputs changed. Outputs whose input is absent (no ../shared/data)
# are not compared.
# Usage: tests/golden/check.sh RWCALC
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="$(mktemp -d "${TMPDIR:-/tmp}/rwcalc-golden.XXXXXX")"
trap 'rm -rf "$out"' EXIT
"$here/../../scripts/golden.sh" "$out" "$1" >/dev/null
if [[ -s "$out/SKIPPED" ]]; then echo "not compared (input absent):"; sed 's/^/  /' "$out/SKIPPED"; fi
status=0
while read -r sum name; do
  want="$(awk -v n="$name" '$2 == n {print $1}' "$here/SHA256SUMS")"
  if [[ -z "$want" ]]; then echo "no recorded output for $name"; status=1
  elif [[ "$want" != "$sum" ]]; then echo "output changed: $name"; status=1
  fi
done <"$out/SHA256SUMS"
missing="$(awk '{print $2}' "$here/SHA256SUMS" | while read -r n; do
  grep -q " $n\$" "$out/SHA256SUMS" || grep -q "^${n%.out} " "$out/SKIPPED" 2>/dev/null || echo "$n"; done)"
if [[ -n "$missing" ]]; then echo "recorded but not produced: $missing"; status=1; fi
((status == 0)) && echo "golden outputs: $(wc -l <"$out/SHA256SUMS") identical"
exit $status
