#!/usr/bin/env bash
# The C++ tests under AddressSanitizer and UndefinedBehaviorSanitizer (build-asan/), a named
# representative subset so that CI stays well under its budget: the stick-slip engine and its
# modes, the Theorem 1 checks, the generated kernels, limit cycles, the a-priori model choice and
# the fields, the campaigns (journal, farm); then the fuzz target's replay, and the release program
# under valgrind. Any sanitizer or valgrind report fails the run (halt_on_error; UBSan made fatal).
set -euo pipefail
cd "$(dirname "$0")/.."
# Clang (Debian's clang 14 with its sanitizer runtime, scripts/install-deps.sh), not g++: its ASan/UBSan
# build takes about half as long, which outweighs its slower -O1 code, and its UBSan checks more
# (float-cast-overflow is in clang's -fsanitize=undefined, not in g++'s). -O1, the level the sanitizers
# are meant for: at -O2 the longer build costs more than the faster runs save. -g1: line tables for the
# reports. (docs/decisions.md, The sanitizer stage: clang at -O1, runs side by side)
cmake -S . -B build-asan -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g1" \
      -DPLATE_SANITIZE=ON >/dev/null
# (A sanitizer build compiles only the test files whose cases run here: tests/CMakeLists.txt.)
cmake --build build-asan -j"$(nproc)" --target plate_tests plate plate_fuzz_replay
echo "=== sanitizers: built after $SECONDS s"
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1

# The union of the tags (a case with two of them, like the Fig. 6 field's, is listed once). Fig. 6's
# pivoting cycles against the regularised reference (50 s under ASan) is left out: it runs the stiff
# reference solver over cycles that the Fig. 6 field test takes the engine through here anyway.
tags="[stick]~*pivoting cycles agree with the regularised*,[proofs],[kernels],[limit_cycle],[auto],[field],[sweep],[robustness]"
work=build-asan/sanitizer-runs
rm -rf "$work"; mkdir -p "$work"
# (Catch2 2's listing exits with the number of cases it listed: its status says nothing. An alternative
# of the tags that matches nothing, or a listing that fails, must not pass empty: the count below.)
build-asan/tests/plate_tests "$tags" --list-test-names-only > "$work/listing" || true
sed '/^[[:space:]]*$/d' "$work/listing" > "$work/cases"
ncases=$(wc -l < "$work/cases")
[ "$ncases" -ge 60 ] || { echo "sanitizers: only $ncases cases listed for $tags" >&2; exit 1; }
# Each of the four runs below takes one core most of its time and they are independent, so they run
# side by side on the machine's cores (in sequence one core would idle): the cases in two halves
# (every other case in the listing, which interleaves the slow and the fast files), the fuzz replay,
# valgrind.
# (Catch2 2 reads each line of -f as one name, but splits it at commas and takes [ ] * ~ \ as test-spec
# syntax: those are escaped.)
sed 's/[],[*~\\]/\\&/g' "$work/cases" |
  awk -v a="$work/half1" -v b="$work/half2" 'NR % 2 { print > a; next } { print > b }'
run() {   # NAME COMMAND...: output to $work/NAME.log, exit code to $work/NAME.rc
  local name=$1; shift
  set +e; "$@" > "$work/$name.log" 2>&1; echo $? > "$work/$name.rc"
}
# The fuzz target's replay: the committed corpus and 3 000 new seeded mutants (tests/fuzz/), seed 2:
# others than the release test's 10^4 (seed 1), so that the two runs together cover more inputs.
fuzz() { (cd build-asan && tests/plate_fuzz_replay ../tests/fuzz/corpus --mutants 3000 --seed 2); }
# Uninitialised reads, which ASan does not see (a motion that depends on the environment): the
# release program under valgrind on each kind of part and command. Any report fails the run.
memcheck() {
  local args
  for args in "twist scenes/fig4.json --at 0.03 -0.02 1.0" "twist scenes/fig1_point.json --at 0.01 0.02" \
              "twist scenes/heave_yaw.json --at 0.01 0.02 0.5" \
              "simulate scenes/fig6.json --dynamics full --start 0.01 0.02 0.3 --time 0.1" \
              "simulate scenes/heave_yaw_point.json --dynamics u --start 0.01 0.02 --time 0.2" \
              "field scenes/fig1_point.json --grid 3 --threads 1" "fixed-points scenes/fig4.json --grid 3 --threads 1"; do
    echo "valgrind plate $args"
    # shellcheck disable=SC2086
    valgrind -q --error-exitcode=9 build/plate $args >/dev/null || return 1
  done
}
echo "sanitizers: $ncases cases ($tags) in two halves, the fuzz replay and valgrind, side by side" >&2
# (a stop of this script stops the four runs too, rather than leaving them running)
trap 'kill $(jobs -p) 2>/dev/null' INT TERM
run cases1 build-asan/tests/plate_tests -f "$work/half1" --warn NoTests &
run cases2 build-asan/tests/plate_tests -f "$work/half2" --warn NoTests &
run fuzz fuzz &
run valgrind memcheck &
wait
failed=0
for name in cases1 cases2 fuzz valgrind; do
  rc=$(cat "$work/$name.rc" 2>/dev/null || echo missing)
  echo "=== sanitizers: $name: exit $rc" >&2
  cat "$work/$name.log" >&2
  [ "$rc" = 0 ] || failed=1
done
# Both halves together ran every listed case once (Catch2's summary line counts the cases it ran).
ran=$(sed -n 's/.*assertions* in \([0-9]*\) test cases*.*/\1/p' "$work/cases1.log" "$work/cases2.log" |
      awk '{ n += $1 } END { print n + 0 }')
if [ "${ran:-0}" != "$ncases" ]; then
  echo "sanitizers: the halves ran ${ran:-0} cases, $ncases were listed" >&2
  failed=1
fi
exit "$failed"
