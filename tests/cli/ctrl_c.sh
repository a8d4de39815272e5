#!/bin/sh
# Ctrl-C stops a long `plate field` within 0.5 s (issue 54, point 4): SIGINT 1 s into a fig6 field at
# grid 25 (12.5 s here when not stopped); the program must be gone within 0.5 s of the signal, with a
# non-zero status and no output file (nor its temporary).
# Usage: ctrl_c.sh PLATE_EXE SCENES_DIR
set -u
exe=$1
scenes=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$exe" field "$scenes/fig6.json" --grid 25 --max-work 1000000000000000 --out "$dir/field.json" 2>"$dir/err" &
pid=$!
sleep 1
t0=$(date +%s%N)
kill -INT "$pid"
wait "$pid"
status=$?
t1=$(date +%s%N)
ms=$(((t1 - t0) / 1000000))
echo "exit status $status, ${ms} ms after SIGINT"
fail=0
if [ "$ms" -ge 500 ]; then echo "FAIL: still running ${ms} ms after SIGINT"; fail=1; fi
if [ "$status" -eq 0 ]; then echo "FAIL: exit status 0 after SIGINT"; fail=1; fi
if [ -e "$dir/field.json" ] || [ -e "$dir/field.json.tmp" ]; then echo "FAIL: an output file was left"; fail=1; fi
exit $fail
