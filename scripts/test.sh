#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
echo "=== test.sh: build after $SECONDS s"
scripts/build.sh
echo "=== test.sh: the suite after $SECONDS s"
ctest --test-dir build --output-on-failure -j"$(nproc)"
