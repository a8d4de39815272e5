#!/usr/bin/env bash
# Opens a verification report in headless Chromium (Debian's) and fails if any figure is missing.
# Usage: scripts/check-report.sh DIR   (DIR/index.html written by `plate report --out DIR`)
set -euo pipefail
dir=${1:?usage: scripts/check-report.sh DIR}
[ -f "$dir/index.html" ] || { echo "check-report: $dir/index.html: no such file" >&2; exit 2; }
if ! command -v chromium >/dev/null; then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium >&2
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
dom=$(chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$profile" --allow-file-access-from-files \
  --virtual-time-budget=15000 --dump-dom "file://$(realpath "$dir")/index.html" 2>/dev/null)
state=$(printf '%s' "$dom" | grep -o 'data-images="[^"]*"' | head -1 || true)
echo "check-report: ${state:-no verdict in the page}"
case "$state" in
  *'"ok:'*) exit 0 ;;
  *) exit 1 ;;
esac
