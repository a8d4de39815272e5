#!/usr/bin/env bash
# The Python module's type stubs (issue 54): python/plate/_plate.pyi is what scripts/python_stubs.py
# generates from the built module (no drift), mypy --strict accepts the package with them, accepts a
# script that uses the API as documented, and rejects one that passes the wrong types (so the stubs
# constrain something).
#   check_stubs.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
build=$(cd "$1" && pwd); src=$(cd "$2" && pwd); python=$3
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$python" "$src/scripts/python_stubs.py" "$build/python" --check
cd "$work"
export MYPYPATH="$src/python"
mypy=(mypy --strict --cache-dir=/dev/null --no-error-summary)
"${mypy[@]}" -p plate
cat > good.py <<'PY'
from typing import Any

import numpy
import plate

scene: plate.Scene = plate.load_scene("scenes/fig4.json")
c: plate.Cycle = plate.twist(scene, at=[0.03, -0.02, 1.0], twist=[0.0, 0.0, 0.0])
f: plate.Field = plate.field(scene, grid=5)
w: "numpy.ndarray[Any, Any]" = f.twist
points = plate.fixed_points(f).points
tr: plate.Trajectory = plate.simulate(scene, start=[0.03, -0.02, 1.0], time=1.0, dynamics="full")
d: plate.Design = plate.design(scene, fixed_point=(0.02, -0.01, 0.5), limits=(20.0, 150.0), evaluations=100)
n: float = scene.mass + c.twist[0] + tr.t[-1] + len(points)
s2: plate.Scene = plate.Scene(part={"mass": 0.02, "friction": 0.3}, plate={"period": 0.05, "harmonics": []})
same: bool = scene == s2
PY
"${mypy[@]}" good.py
cat > bad.py <<'PY'
import plate

scene = plate.load_scene("scenes/fig4.json")
c = plate.twist(scene, at=0.03)
x: str = scene.mass
plate.simulate(scene, [0.0, 0.0, 0.0], "1 s")
PY
if "${mypy[@]}" bad.py > bad.txt 2>&1; then echo "mypy accepted bad.py: the stubs constrain nothing"; exit 1; fi
for line in 4 5 6; do
  grep -q "^bad.py:$line: error" bad.txt || { cat bad.txt; echo "mypy did not reject bad.py line $line"; exit 1; }
done
echo "stubs: no drift; mypy --strict accepts the package and good.py, rejects bad.py lines 4-6"
