#!/usr/bin/env bash
# Opens a report page in headless Chromium (Debian's) and fails unless a person would see it whole:
# every figure decoded, no error in the page (script errors, resources that fail to load,
# console.error), every $$...$$ formula typeset by KaTeX, every figure shown at least MIN_WIDTH px
# wide (default 600). The page states these itself once loaded (reports/report_html.hpp, kPageCheck);
# this reads them from the DOM Chromium dumps.
# Usage: scripts/check-report.sh DIR [--screenshot FILE.png] [--min-width PX] [--min-images N] [--min-formulas N]
#   (DIR/index.html written by `plate report --out DIR` or `plate bench --out DIR`)
set -euo pipefail
dir=${1:?usage: scripts/check-report.sh DIR [--screenshot FILE.png] [--min-width PX]}
shift
shot="" min_width=600 min_images=1 min_formulas=0
while (($#)); do
  case "$1" in
    --screenshot) shot=${2:?--screenshot FILE}; shift 2 ;;
    --min-width) min_width=${2:?--min-width PX}; shift 2 ;;
    --min-images) min_images=${2:?--min-images N}; shift 2 ;;
    --min-formulas) min_formulas=${2:?--min-formulas N}; shift 2 ;;
    *) echo "check-report: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -f "$dir/index.html" ] || { echo "check-report: $dir/index.html: no such file" >&2; exit 2; }
command -v chromium >/dev/null || { echo "check-report: no chromium (scripts/install-deps.sh installs it)" >&2; exit 2; }
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
url="file://$(realpath "$dir")/index.html"
flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking
       --disable-component-update --disable-sync --user-data-dir="$profile" --allow-file-access-from-files
       --window-size=1400,1000 --virtual-time-budget=15000)
# (a page script that never ends must not hang the check)
dom=$(timeout 120 chromium "${flags[@]}" --dump-dom "$url" 2>/dev/null) || { echo "check-report: FAIL: chromium did not finish loading the page in 120 s" >&2; exit 1; }
attr() { printf '%s' "$dom" | grep -o "$1=\"[^\"]*\"" | head -1 | sed "s/^$1=\"//; s/\"\$//" || true; }
images=$(attr data-images) errors=$(attr data-errors) math=$(attr data-math) width=$(attr data-figure-width)
echo "check-report: images ${images:-?}; errors ${errors:-?}; formulas ${math:-?}; narrowest figure ${width:-?} px"
ok=1
case "$images" in ok:*) ;; *) echo "check-report: FAIL: figures not shown (${images:-no verdict in the page})" >&2; ok=0 ;; esac
case "$images" in ok:*) ((${images#ok:} >= min_images)) || { echo "check-report: FAIL: ${images#ok:} figures, fewer than $min_images" >&2; ok=0; } ;; esac
[ "$errors" = none ] || { echo "check-report: FAIL: errors in the page: ${errors:-no verdict in the page}" >&2; ok=0; }
case "$math" in ok:*) ;; *) echo "check-report: FAIL: formulas not typeset (${math:-no verdict in the page})" >&2; ok=0 ;; esac
case "$math" in ok:*) ((${math#ok:} >= min_formulas)) || { echo "check-report: FAIL: ${math#ok:} formulas, fewer than $min_formulas" >&2; ok=0; } ;; esac
[[ "$width" =~ ^[0-9]+$ ]] && ((width >= min_width)) || { echo "check-report: FAIL: a figure is shown ${width:-?} px wide, below $min_width" >&2; ok=0; }
if [ -n "$shot" ]; then
  rm -f "$shot"
  timeout 120 chromium "${flags[@]}" --window-size=1400,2400 --screenshot="$shot" "$url" >/dev/null 2>&1 || true
  [ -s "$shot" ] || { echo "check-report: FAIL: no screenshot written to $shot" >&2; ok=0; }
  echo "check-report: screenshot $shot"
fi
((ok)) && exit 0 || exit 1
