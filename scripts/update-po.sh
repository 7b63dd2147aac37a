#!/usr/bin/env bash
# The message catalogue: extracts every message marked tr(), trf(), trn(), trnf() or N_() in the sources into
# po/rwcalc.pot and merges it into po/ru.po (new messages get an empty msgstr to translate; those
# no longer in the code become obsolete "#~" entries). Needs gettext (xgettext, msgmerge).
# Usage: scripts/update-po.sh [--check]   (--check: only compare, change nothing; status 1 when
#        a message has no Russian text or the catalogue has an entry the code no longer uses)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
pot="$(mktemp "${TMPDIR:-/tmp}/rwcalc-pot.XXXXXX")"
trap 'rm -f "$pot" "$pot.po"' EXIT
mapfile -t sources < <(find src include -name '*.cpp' -o -name '*.hpp' | LC_ALL=C sort)
xgettext --language=C++ --from-code=UTF-8 --no-wrap --sort-by-file --package-name=rwcalc \
  --keyword=tr --keyword=trf --keyword=N_ --keyword=trn:1,2 --keyword=trnf:1,2 \
  --flag=tr:1:no-c-format --flag=trf:1:no-c-format --flag=N_:1:no-c-format --flag=trn:1:no-c-format \
  --flag=trn:2:no-c-format --flag=trnf:1:no-c-format --flag=trnf:2:no-c-format \
  -o "$pot" "${sources[@]}"
if [[ "${1:-}" == --check ]]; then
  status=0
  # Every message of the code has a Russian entry (msgcmp ignores untranslated and fuzzy ones).
  msgcmp po/ru.po "$pot" || status=1
  # No entry the code no longer uses: merging adds nothing obsolete that was not there.
  msgmerge --quiet --no-wrap --no-fuzzy-matching -o "$pot.po" po/ru.po "$pot"
  if grep -q '^#~ msgid' "$pot.po"; then
    echo "po/ru.po: entries no longer in the code:" >&2
    grep '^#~ msgid' "$pot.po" >&2
    status=1
  fi
  msgfmt --check -o /dev/null po/ru.po || status=1
  exit $status
fi
msgmerge --quiet --update --no-wrap --backup=none --no-fuzzy-matching po/ru.po "$pot"
echo "po/ru.po: $(msgattrib --untranslated po/ru.po | grep -c '^msgid' || true) message(s) to translate"
