#!/usr/bin/env bash
# The C++ tests under AddressSanitizer and UndefinedBehaviorSanitizer (build-asan/), a named
# representative subset so that CI stays well under its budget: the stick-slip engine and its
# modes, the Theorem 1 checks, the generated kernels, limit cycles, the a-priori model choice and
# the fields, the campaigns (journal, farm); then the fuzz target's replay. Any sanitizer report fails the run (halt_on_error; UBSan
# made fatal).
set -euo pipefail
cd "$(dirname "$0")/.."
# -O1 -g1: line tables for the reports, less to compile than -O2 -g (the stage took 13 of CI's 18 minutes
# then; the build alone 8.5 minutes before it compiled only the test files run here)
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g1" -DPLATE_SANITIZE=ON >/dev/null
# (A sanitizer build compiles only the test files whose cases run here: tests/CMakeLists.txt.)
cmake --build build-asan -j"$(nproc)" --target plate_tests plate plate_fuzz_replay
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# One run over the union of the tags (a case with two of them, like the Fig. 6 field's, runs once).
# Fig. 6's pivoting cycles against the regularised reference (50 s under ASan) is left out: it runs the
# stiff reference solver over cycles that the Fig. 6 field test takes the engine through here anyway.
tags="[stick]~*pivoting cycles agree with the regularised*,[proofs],[kernels],[limit_cycle],[auto],[field],[sweep]"
echo "sanitizers: $tags" >&2
build-asan/tests/plate_tests "$tags" --warn NoTests   # (an alternative that matches nothing fails)
# The fuzz target's replay: the committed corpus and 3 000 new seeded mutants (tests/fuzz/), seed 2:
# others than the release test's 10^4 (seed 1), so that the two runs together cover more inputs.
echo "sanitizers: fuzz replay" >&2
(cd build-asan && tests/plate_fuzz_replay ../tests/fuzz/corpus --mutants 3000 --seed 2)
# Uninitialised reads, which ASan does not see (a point part's contacts were once garbage and its
# motion depended on the environment's size): the release program under valgrind on each kind of
# part and command. Any report fails the run.
echo "sanitizers: valgrind (uninitialised values)" >&2
for args in "twist scenes/fig4.json --at 0.03 -0.02 1.0" "twist scenes/fig1_point.json --at 0.01 0.02" \
            "twist scenes/heave_yaw.json --at 0.01 0.02 0.5" \
            "simulate scenes/fig6.json --dynamics full --from 0.01 0.02 0.3 --time 0.1" \
            "simulate scenes/heave_yaw_point.json --dynamics u --from 0.01 0.02 --time 0.2" \
            "field scenes/fig1_point.json --grid 3 --threads 1" "fixed-points scenes/fig4.json --grid 3 --threads 1"; do
  # shellcheck disable=SC2086
  valgrind -q --error-exitcode=9 build/plate $args >/dev/null
done
