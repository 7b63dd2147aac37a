#!/usr/bin/env bash
# The code's habits, checked: every tracked C++ file as .clang-format lays it out, and no finding of
# the project's clang-tidy set (.clang-tidy) in the library and main. Needs a built build directory
# (its compile_commands.json, and ninja's record of each unit's headers for --changed).
#   scripts/lint.sh [BUILD_DIR] [--format-only | --changed | --record]      (default: build)
# --changed: clang-tidy only over the units that read a file changed since the last whole run
#   that passed (.ci/tidy-baseline: every tracked file's blob hash then; every unit when .clang-tidy
#   or this script changed since). CI runs this: the whole set takes about 175 s of the two cores,
#   more than its budget leaves, and a unit that reads no changed file cannot have a new finding.
# --record: the whole run on a tree without uncommitted changes, and on success the files' hashes
#   written to .ci/tidy-baseline (commit it).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
mode=${2:-all}
if [[ ! -f $build/compile_commands.json ]]; then
  echo "lint.sh: no $build/compile_commands.json; configure first (cmake --preset release)" >&2
  exit 2
fi
# A relative include that leaves its folder reaches another layer's private header, which no include
# path lets it see (docs/architecture.md): refused.
if git grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"\.\./' -- src include; then
  echo "lint.sh: the includes above leave their layer's folder (include a public header instead)" >&2
  exit 1
fi
echo "clang-format: $(git ls-files '*.cpp' '*.hpp' | wc -l) files"
git ls-files -z '*.cpp' '*.hpp' | xargs -0 clang-format --dry-run --Werror
[[ $mode == --format-only ]] && exit 0
if [[ $mode == --record ]] && ! git diff --quiet HEAD; then
  echo "lint.sh: --record needs the changes committed (the baseline names the committed files)" >&2
  exit 2
fi

# The files changed since the baseline (committed or not), as absolute paths; "all" when every unit
# must be checked. The baseline is each tracked file's blob hash at the last whole run, so a shallow
# clone, which has no history, compares as well as a full one.
changed_files() {
  local manifest=.ci/tidy-baseline
  if [[ ! -f $manifest ]]; then
    echo all
    return
  fi
  local changed
  changed=$({
    git ls-files -s | awk 'NR == FNR { hash[$2] = $1; next } hash[$4] != $2 { print $4 }' "$manifest" -
    git diff --name-only
    git ls-files --others --exclude-standard
  } | sort -u)
  if grep -qxE '\.clang-tidy|scripts/lint\.sh' <<<"$changed"; then
    echo all
    return
  fi
  [[ -z $changed ]] || sed "s|^|$PWD/|" <<<"$changed"
}

# The library is compiled one unit per layer (unity build): checking those units reads every source
# once, about a fifth of the time file by file; the few sources kept out of the units come too.
# Each line: the source, then its object (for ninja's list of the headers it read).
mapfile -t entries < <(/usr/bin/python3 - "$build" <<'PY'
import json, shlex, sys
for e in json.load(open(sys.argv[1] + "/compile_commands.json")):
    f = e["file"]
    if "/tests/" in f or "/fuzz/" in f or "/bench/" in f or f.endswith("catalog_ru.cpp"):
        continue
    args = shlex.split(e["command"])
    print(f + "\t" + args[args.index("-o") + 1])
PY
)
units=()
if [[ $mode == --changed ]]; then
  changed=$(changed_files)
  for e in "${entries[@]}"; do
    src=${e%%$'\t'*} obj=${e#*$'\t'}
    if [[ $changed == all ]]; then
      units+=("$src")
    # grep reads to the end (no -q): under pipefail an early exit would fail ninja with SIGPIPE.
    elif ninja -C "$build" -t deps "$obj" | sed -n 's/^    //p' | grep -xFf <(echo "$changed") >/dev/null; then
      units+=("$src")
    fi
  done
  echo "clang-tidy: ${#units[@]} of ${#entries[@]} units read a file changed since .ci/tidy-baseline"
else
  for e in "${entries[@]}"; do units+=("${e%%$'\t'*}"); done
  echo "clang-tidy: ${#units[@]} units"
fi
# The unity units carry a g++-only warning option (-Wno-subobject-linkage) that clang does not know.
if ((${#units[@]})); then
  printf '%s\0' "${units[@]}" | xargs -0 -P "$(nproc)" -n1 clang-tidy -p "$build" --quiet --warnings-as-errors='*' \
    --extra-arg=-Wno-unknown-warning-option
fi
if [[ $mode == --record ]]; then
  git ls-files -s | awk '$4 != ".ci/tidy-baseline" { print $2, $4 }' > .ci/tidy-baseline
  echo "lint.sh: .ci/tidy-baseline holds the files of $(git rev-parse --short HEAD); commit it"
fi
