#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on every shipped scene:
# the asymptotic twist (velocity) field and its fixed points, and the numerical checks of
# Theorem 1 (proofs.json), into out/ (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
out=${1:-out}
mkdir -p "$out"
for scene in scenes/*.json; do
  name=$(basename "$scene" .json)
  echo "== $name" >&2
  build/plate field "$scene" --out "$out/$name.field.json"
  build/plate field "$scene" --format csv --out "$out/$name.field.csv"
  build/plate fixed-points "$scene" --out "$out/$name.fixed-points.json"
done
echo "== Theorem 1 checks (10^4 thin, 10^3 thick parts; a few minutes)" >&2
build/plate proofs --out "$out/proofs.json"
echo "results in $out/" >&2
