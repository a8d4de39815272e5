#!/usr/bin/env bash
# Checksums of what the program computes, to show that a change of structure changed no result:
#   scripts/golden.sh [--quick] BUILD_DIR OUT_DIR     runs BUILD_DIR/plate on the shipped inputs into OUT_DIR
#                                                     and writes OUT_DIR/checksums.txt
#   scripts/golden.sh --compare A B                   compares two OUT_DIRs' checksums (exit 1 on a difference)
#   scripts/golden.sh --sums OUT_DIR                  OUT_DIR's checksums again (after a change of this script)
# What is checked: the field (JSON and CSV) and fixed points of every shipped scene, twists at a
# configuration, full / U / averaged trajectories, random scenes, Theorem 1's proofs JSON, the point sink,
# line sink, transport, orienter and fig4 fixed-point designs (summary and scene) and a campaign's table.
# Wall-clock figures (seconds, threads, timing.csv, the machine) and statements of units are taken out
# before hashing, and CSV numbers are compared as the doubles they read back to: everything else must
# agree to the bit. --quick leaves out the two slowest (fig4's fixed-point design, the campaign).
set -euo pipefail
cd "$(dirname "$0")/.."

normalise() {   # FILE OUT: its content without wall-clock figures or OUT's own path, on stdout
    python3 - "$1" "$2" <<'EOF'
import json, re, sys
path, out = sys.argv[1], sys.argv[2]
text = open(path).read().replace(out, "OUT")
TIMING = {"seconds", "threads", "machine", "wall_seconds", "elapsed", "decision_seconds", "cpu_seconds",
          "busy_seconds", "load_balance_efficiency", "units"}
def strip(x, key=None):
    if isinstance(x, dict):
        return {k: strip(v, k) for k, v in x.items() if k not in TIMING}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
def try_json(t):
    try:
        return json.loads(t)
    except ValueError:
        return None
j = try_json(text)
if j is not None:
    # design runs keep "seconds" as the run's simulated length: only top-level timings are wall clock
    if isinstance(j, dict) and "full_dynamics_runs" in j:
        j.pop("seconds", None)
        j.pop("scene", None)   # (the --out path given)
        print(json.dumps(j, sort_keys=True))
    else:
        print(json.dumps(strip(j), sort_keys=True))
elif path.endswith(".jsonl"):   # (a journal's lines come in the order the cases finished)
    for line in sorted(json.dumps(strip(json.loads(l)), sort_keys=True) for l in text.splitlines()):
        print(line)
else:
    # CSV and text: lines that name a wall-clock figure are dropped; a CSV's headings lose their units
    # and its numbers are written shortest, so that a change of notation alone (issue 54: 17 digits ->
    # std::to_chars, units in the headings) compares equal while any changed value does not
    def cell(c):
        try:
            return repr(float(c)) if re.fullmatch(r"[-+0-9.eE]+", c) and not re.fullmatch(r"[-+]?[0-9]+", c) else c
        except ValueError:
            return c
    csv = path.endswith(".csv")
    for k, line in enumerate(text.splitlines()):
        if re.search(r"seconds|threads|machine|wall", line) and line.startswith("#"):
            continue
        if csv and not line.startswith("#"):
            line = ",".join(re.sub(r" \[[^]]*\]$", "", cell(c)) for c in line.split(","))
        print(line)
EOF
}

sums() {   # OUT: OUT/checksums.txt from what is in OUT
    local out=$1
    (
        abs=$(cd "$out" && pwd)
        cd "$out"
        for f in $(find . -type f ! -name 'checksums.txt*' ! -name timing.csv ! -name '*.svg' | sort); do
            printf '%s  %s\n' "$(normalise "$f" "$abs" | sha256sum | cut -c1-16)" "$f"
        done
    ) >"$out/checksums.txt.tmp"
    mv "$out/checksums.txt.tmp" "$out/checksums.txt"
}

if [[ ${1:-} == --sums ]]; then   # OUT: the checksums again (after a change of this script)
    sums "$(realpath "$2")"
    exit 0
fi
if [[ ${1:-} == --compare ]]; then
    a=$2 b=$3
    if diff <(sort "$a/checksums.txt") <(sort "$b/checksums.txt"); then
        echo "golden: $(wc -l <"$a/checksums.txt") outputs identical"
        exit 0
    fi
    echo "golden: outputs differ (above: < $a, > $b)" >&2
    exit 1
fi

quick=0
if [[ ${1:-} == --quick ]]; then quick=1; shift; fi
build=$1 out=$(realpath -m "$2")
plate="$build/plate"
mkdir -p "$out"
run() {   # NAME COMMAND...: stdout to OUT/NAME (exit code kept in OUT/NAME.rc)
    local name=$1; shift
    set +e
    "$@" >"$out/$name" 2>"$out/$name.err"
    echo $? >"$out/$name.rc"
    set -e
}

for scene in scenes/*.json; do
    s=$(basename "$scene" .json)
    run "$s.field.json" "$plate" field "$scene" --threads 2
    run "$s.field.csv" "$plate" field "$scene" --format csv --threads 2
    run "$s.fixed-points.json" "$plate" fixed-points "$scene" --threads 2
    if python3 -c 'import json, sys; p = json.load(open(sys.argv[1]))["part"]; sys.exit(1 if "inertia" in p or "contacts" in p else 0)' "$scene"; then
        at=(0.01 -0.015)
    else
        at=(0.01 -0.015 0.7)
    fi
    run "$s.twist.json" "$plate" twist "$scene" --at "${at[@]}"
done
# (the start's option: --start since issue 54, --from before; so that builds on both sides compare)
start=--from
[[ $("$plate" simulate --help) == *--start* ]] && start=--start
run fig4.full.csv "$plate" simulate scenes/fig4.json --dynamics full "$start" 0.04 -0.04 1.0 --time 3
run fig6.u.csv "$plate" simulate scenes/fig6.json --dynamics u "$start" 0.0167 0 2.693 --time 2
run fig1.averaged.csv "$plate" simulate scenes/fig1.json --dynamics averaged "$start" -0.04 0.03 1.2 --time 4
run fig1_point.field-curve.csv "$plate" simulate scenes/fig1_point.json --dynamics field "$start" 0.03 0.02 --time 5
run heave_yaw.full.csv "$plate" simulate scenes/heave_yaw.json --dynamics full "$start" 0.02 0 0.3 --time 1
for seed in 3 7; do
    run "random.$seed.json" "$plate" random-scene --seed $seed
    run "random.$seed.thin.json" "$plate" random-scene --seed $seed --thin
    run "random.$seed.point.json" "$plate" random-scene --seed $seed --point
done
run proofs.json "$plate" proofs --thin 200 --thick 10 --threads 2
run design.sink.json "$plate" design scenes/fig1_point.json --target sink 0.02 -0.01 --out "$out/design.sink.scene.json" --threads 2
run design.line.json "$plate" design scenes/fig1_point.json --target line-sink 0.01 0 0.5 --out "$out/design.line.scene.json" --threads 2
run design.transport.json "$plate" design scenes/fig1_point.json --target transport 0.02 0.01 --out "$out/design.transport.scene.json" --threads 2
run design.orient.json "$plate" design scenes/foot.json --target orient 1.0 --out "$out/design.orient.scene.json" --threads 2
run design.bad.json "$plate" design scenes/fig1_point.json --target sink 0.02 --out "$out/design.bad.scene.json"
if ((quick == 0)); then
    run design.fig4.json "$plate" design scenes/fig4.json --target fixed-point 0.02 -0.01 0.5 --out "$out/design.fig4.scene.json" --threads 2
    rm -rf "$out/campaign"
    run campaign.json "$plate" sweep campaigns/heave_yaw_stick_slip.json --out "$out/campaign" --threads 2
fi

sums "$out"
echo "golden: $(wc -l <"$out/checksums.txt") outputs in $out/checksums.txt" >&2
