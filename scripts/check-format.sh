#!/usr/bin/env bash
# Checks that every hand-written C++ file is formatted as .clang-format says (clang-format 14, Debian's
# clang-format package); exits 1 naming the files that are not. --fix formats them in place.
# Generated code (numeric/generated/, its own .clang-format disables formatting) is left as generated.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=--dry-run
if [[ ${1:-} == --fix ]]; then mode=-i; fi
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.hxx' | grep -v '^numeric/generated/')
if ((${#files[@]} == 0)); then
    echo "check-format: no files found" >&2
    exit 1
fi
if [[ $mode == -i ]]; then
    clang-format -i --style=file "${files[@]}"
    echo "check-format: formatted ${#files[@]} files"
    exit 0
fi
bad=()
for f in "${files[@]}"; do
    clang-format --dry-run --Werror --style=file "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]} > 0)); then
    printf 'check-format: not formatted (scripts/check-format.sh --fix): %s\n' "${bad[@]}" >&2
    exit 1
fi
echo "check-format: ${#files[@]} files formatted as .clang-format says"
