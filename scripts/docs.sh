#!/usr/bin/env bash
# The API reference: Doxygen over the public C++ headers (XML), then Sphinx with breathe over that XML
# and autodoc over the built Python module, warnings as errors in both. Needs the Python module built
# (cmake --build BUILD_DIR --target plate_python) and Debian's doxygen, python3-sphinx and
# python3-breathe (scripts/install-deps.sh installs them).
#   scripts/docs.sh [BUILD_DIR [OUT_DIR]]    (defaults: build, BUILD_DIR/docs/api)
# Writes OUT_DIR/index.html; exit 0 built without a warning, 1 a warning or error (printed), 2 a tool
# or the built module missing.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
out=${2:-$build/docs/api}
# (Debian's interpreter: the module is built for it, and Sphinx and breathe are its; PLATE_PYTHON overrides)
python=${PLATE_PYTHON:-/usr/bin/python3}

missing=()
command -v doxygen >/dev/null || missing+=(doxygen)
"$python" -c "import sphinx" 2>/dev/null || missing+=(python3-sphinx)
"$python" -c "import breathe" 2>/dev/null || missing+=(python3-breathe)
if ((${#missing[@]})); then
  echo "docs.sh: missing ${missing[*]} (scripts/install-deps.sh installs them)" >&2
  exit 2
fi
if ! ls "$build"/python/plate/_plate*.so >/dev/null 2>&1; then
  echo "docs.sh: no Python module in $build/python (cmake --build $build --target plate_python)" >&2
  exit 2
fi
build=$(cd "$build" && pwd)
out=$(realpath -m "$out")
case "$out/" in "$src"/docs/*) echo "docs.sh: OUT_DIR $out is inside the source's docs/" >&2; exit 2 ;; esac
mkdir -p "$out"

# Doxygen: XML only, into OUT_DIR/.doxygen (a fresh one: stale XML of a removed header would linger).
rm -rf "$out/.doxygen"
mkdir -p "$out/.doxygen"
export PLATE_SRC=$src PLATE_DOXYGEN_OUT=$out/.doxygen
if ! doxygen "$src/docs/api/Doxyfile" || [ -s "$out/.doxygen/warnings.log" ]; then
  cat "$out/.doxygen/warnings.log" >&2
  echo "docs.sh: doxygen warned (above): fix the header comment or docs/api/doxygen_filter.py" >&2
  exit 1
fi

# Sphinx: -W warnings are errors, --keep-going lists them all, -n every cross-reference must resolve;
# -E a fresh environment (no page kept from a run on older XML).
export PLATE_PYTHON_DIR=$build/python PLATE_DOXYGEN_XML=$out/.doxygen/xml
if ! "$python" -m sphinx -b html -W --keep-going -n -E -q -d "$out/.doctrees" "$src/docs/api" "$out"; then
  echo "docs.sh: Sphinx warned or failed (above): fix the page, the docstring or the header comment" >&2
  exit 1
fi
echo "docs.sh: API reference in $out/index.html"
