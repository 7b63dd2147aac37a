#!/usr/bin/env bash
# The code's habits, checked: every tracked C++ file as .clang-format lays it out, and no finding of
# the project's clang-tidy set (.clang-tidy) in the library and main. Needs a configured build
# directory (its compile_commands.json); CI runs it after the release build.
#   scripts/lint.sh [BUILD_DIR] [--format-only]        (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
format_only=0
[[ ${2:-} == --format-only ]] && format_only=1
if [[ ! -f $build/compile_commands.json ]]; then
  echo "lint.sh: no $build/compile_commands.json; configure first (cmake --preset release)" >&2
  exit 2
fi
echo "clang-format: $(git ls-files '*.cpp' '*.hpp' | wc -l) files"
git ls-files -z '*.cpp' '*.hpp' | xargs -0 clang-format --dry-run --Werror
((format_only)) && exit 0
# The library is compiled one unit per layer (unity build): checking those units reads every source
# once, about a fifth of the time file by file; the few sources kept out of the units come too.
mapfile -t units < <(/usr/bin/python3 - "$build" <<'PY'
import json, sys
for e in json.load(open(sys.argv[1] + "/compile_commands.json")):
    f = e["file"]
    if "/tests/" in f or "/fuzz/" in f or "/bench/" in f or f.endswith("catalog_ru.cpp"):
        continue
    print(f)
PY
)
echo "clang-tidy: ${#units[@]} units"
# The unity units carry a g++-only warning option (-Wno-subobject-linkage) that clang does not know.
printf '%s\0' "${units[@]}" | xargs -0 -P "$(nproc)" -n1 clang-tidy -p "$build" --quiet --warnings-as-errors='*' \
  --extra-arg=-Wno-unknown-warning-option
