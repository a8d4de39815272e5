#!/usr/bin/env bash
# The package (issue 17, point 2): install the build into a temporary prefix, move the prefix
# elsewhere (relocatable), run the installed plate from / and check it finds its scenes beside
# itself, then build a consumer project with find_package(plate CONFIG) against it and check it
# computes the same twist as the installed program, and reads a design target (plate::design) and a
# campaign (plate::sweep) as their files say. The licence, changelog, citation and README
# are installed under share/doc/plate.
# With the Python module built, the installed module is imported from / with the documented
# PYTHONPATH=PREFIX/lib/python3/dist-packages and must give the installed program's twist.
#   check_install.sh BUILD_DIR SOURCE_DIR [PYTHON]
set -euo pipefail
build=$(cd "$1" && pwd); src=$(cd "$2" && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/first" > /dev/null
mv "$work/first" "$work/moved"
prefix="$work/moved"
cd /
version=$("$prefix/bin/plate" --version)
echo "$version"
case "$version" in *"$prefix/share/plate"*) ;; *) echo "installed plate does not use its own share/plate"; exit 1;; esac
for f in LICENSE CHANGELOG.md CITATION.cff README.md; do
  [ -s "$prefix/share/doc/plate/$f" ] || { echo "the package lacks share/doc/plate/$f"; exit 1; }
done
"$prefix/bin/plate" twist "$prefix/share/plate/scenes/fig4.json" --at 0.02 0.01 0.5 > "$work/twist.json"
cmake -S "$src/tests/package/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/consumer" > /dev/null
"$work/consumer/consumer" "$prefix/share/plate/scenes/fig4.json" "$src/campaigns/fig4_amp_phase.json" > "$work/consumer.txt"
python3 - "$work/twist.json" "$work/consumer.txt" "$src/campaigns/fig4_amp_phase.json" <<'PY'
import json, math, sys
lines = open(sys.argv[2]).read().split("\n")
ok, *twist = lines[0].split()
assert ok == "1", "consumer: cycle not converged"
t = json.load(open(sys.argv[1]))["twist"]
c = [float(x) for x in twist]
assert t == c, f"installed plate {t} vs consumer {c}"
print("consumer and installed plate agree:", c)
# plate::design: the target read back as given; plate::sweep: a grid campaign has the product of its
# parameters' counts as cases, the last at every parameter's "to".
kind, *at = lines[1].split()
assert kind == "sink" and [float(v) for v in at] == [0.01, -0.02], lines[1]
campaign = json.load(open(sys.argv[3]))
cases, *last = lines[2].split()
assert int(cases) == math.prod(p["count"] for p in campaign["parameters"]), (cases, campaign["parameters"])
assert [float(v) for v in last] == [p["to"] for p in campaign["parameters"]], (last, campaign["parameters"])
print("consumer's design target and campaign (%s cases) as expected" % cases)
PY
python=${3:-}
if [ -n "$python" ]; then
  for f in __init__.py _plate.pyi py.typed; do
    [ -f "$prefix/lib/python3/dist-packages/plate/$f" ] || { echo "the Python module's $f was not installed"; exit 1; }
  done
  PYTHONPATH="$prefix/lib/python3/dist-packages" "$python" - "$work/twist.json" "$prefix" <<'PY'
import json, sys
import plate
assert plate.__file__.startswith(sys.argv[2]), plate.__file__
t = json.load(open(sys.argv[1]))["twist"]
c = plate.twist(plate.load_scene(sys.argv[2] + "/share/plate/scenes/fig4.json"), at=(0.02, 0.01, 0.5)).twist.tolist()
assert t == c, f"installed plate {t} vs installed Python module {c}"
print("installed Python module and installed plate agree:", c)
PY
fi
