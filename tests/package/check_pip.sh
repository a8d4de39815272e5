#!/usr/bin/env bash
# The pip package (issue 54, point 1): `pip install --no-build-isolation .` from a copy of the sources
# into a fresh virtual environment (with Debian's site packages: offline, numpy and the build tools come
# from Debian), reusing BUILD_DIR's configured build for the compiled half; then, from /, the installed
# package imports from the environment (not the tree), declares numpy, has CMake's project version,
# and computes the installed program's twist to the bit.
#   check_pip.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
build=$(cd "$1" && pwd); src=$(cd "$2" && pwd); python=$3
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# A copy without build trees: pip builds in the tree it is given, and must not write into the checkout.
tar -C "$src" --exclude='./build*' --exclude=./.git -cf - . | (mkdir "$work/src" && tar -C "$work/src" -xf -)
"$python" -m venv --system-site-packages "$work/venv"
PLATE_BUILD_DIR="$build" "$work/venv/bin/python" -m pip install --no-build-isolation --no-index -q "$work/src" \
  > "$work/pip.log" 2>&1 || { cat "$work/pip.log"; echo "pip install failed"; exit 1; }
rm -rf "$work/src"   # nothing may still need the sources
"$build/plate" twist "$src/scenes/fig4.json" --at 0.02 0.01 0.5 > "$work/twist.json"
version=$(sed -n 's/^project(plate[^)]*VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
cd /
"$work/venv/bin/python" - "$work" "$version" "$src/scenes/fig4.json" <<'PY'
import importlib.metadata as md, json, sys
import plate
work, version, scene = sys.argv[1:4]
assert plate.__file__.startswith(work + "/venv/"), f"imported {plate.__file__}, not the environment's"
assert md.version("plate") == version == plate.__version__, (md.version("plate"), version, plate.__version__)
requires = md.requires("plate") or []
assert any(r.split(";")[0].strip().startswith("numpy") for r in requires), f"numpy not declared: {requires}"
t = json.load(open(work + "/twist.json"))["twist"]
c = plate.twist(plate.load_scene(scene), at=(0.02, 0.01, 0.5)).twist.tolist()
assert t == c, f"installed plate {t} vs pip-installed module {c}"
import os
here = os.path.dirname(plate.__file__)
assert all(os.path.isfile(os.path.join(here, f)) for f in ("_plate.pyi", "py.typed")), os.listdir(here)
print("pip-installed plate", version, "from", plate.__file__, "requires", requires, "agrees with the program:", c)
PY
