#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on every shipped scene:
# the asymptotic twist (velocity) field and its fixed points, and the verification report
# (out/report/index.html), into out/ (or $1).
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
for campaign in campaigns/*.json; do
  name=$(basename "$campaign" .json)
  echo "== campaign $name" >&2
  build/plate sweep "$campaign" --out "$out/campaigns/$name"
done
echo "== verification report (derivation, Theorem 1 on 10^4 thin and 10^3 thick parts, fields; several minutes)" >&2
build/plate report --out "$out/report"
echo "== speed-accuracy study (methods, limit-cycle solvers, failure maps, model hierarchy; a few minutes)" >&2
build/plate bench --out "$out/report"
echo "== side by side with Bullet, ODE and MuJoCo (the engines found; a few minutes)" >&2
/usr/bin/python3 bench/peers/study.py --out "$out/report"
echo "== campaigns' scaling study (threads and MPI ranks; about a minute)" >&2
/usr/bin/python3 bench/scaling.py --out "$out/report"
echo "== the mutation catalogue (one-line physics bugs the tests must catch; about half an hour)" >&2
# (a surviving mutation is shown in the report's "Mutation score" section; the job goes on)
scripts/mutants.py --report "$out/report" || echo "mutants: not every mutation was killed: see the report" >&2
scripts/check-report.sh "$out/report" --screenshot "$out/report/screenshot.png"
echo "results in $out/ (open $out/report/index.html)" >&2
