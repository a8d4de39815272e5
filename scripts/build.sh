#!/usr/bin/env bash
# Configures and builds (Release) into build/, leaving the program at build/plate.
set -euo pipefail
cd "$(dirname "$0")/.."
# With ccache (install-deps installs it), a second copy of the tree built beside this one -- the mutation
# catalogue's scratch copy, scripts/mutants.py -- reuses what this build compiled: paths below the
# checkout's parent are hashed relative to the build folder.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$PWD")}"
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
cmake --build build -j"$(nproc)"
