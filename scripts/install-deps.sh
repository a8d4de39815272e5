#!/usr/bin/env bash
# Installs the Debian packages the project needs, those that are missing only.
set -euo pipefail
pkgs=(g++ cmake make pkg-config libeigen3-dev libboost-dev libgsl-dev libginac-dev libcln-dev
      catch2 nlohmann-json3-dev libcli11-dev gnuplot-nox libjs-katex valgrind chromium
      python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib libnlopt-cxx-dev libceres-dev
      python3-venv python3-pip python3-setuptools python3-wheel   # (pip install ., tests/package/check_pip.sh)
      mypy                    # (the type stubs' check, tests/package/check_stubs.sh)
      doxygen python3-sphinx python3-breathe   # (the API reference, scripts/docs.sh)
      clang libclang-rt-dev   # (the sanitizer build, scripts/test-sanitizers.sh)
      clang-format            # (the format check, scripts/check-format.sh)
      ccache                  # (the mutation catalogue's scratch build reuses the build's objects)
      libopenmpi-dev openmpi-bin
      libbullet-dev libode-dev libmujoco-dev   # (these three: the peer engines, optional to the build)
      libsiconos-numerics-dev   # (the Moreau-Jean stick-slip reference, tests/test_siconos.cpp; optional)
      emscripten    # (the playground in WebAssembly, web/: optional, the target `web` when found)
      dpkg-dev)     # (dpkg-source: the playground's NLopt from Debian's source package, web/fetch_nlopt.sh; optional)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
