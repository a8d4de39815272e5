#!/usr/bin/env python3
"""`plate sweep` end to end (issue 20, point 4): the same table, byte for byte, from one thread, two
threads and `mpirun -np 2`; a run killed mid-way (SIGKILL of the process, SIGKILL of one MPI rank,
SIGINT of the launcher) leaves no table, and the same command resumes it to the uninterrupted table,
skipping the finished cases and cutting a torn journal line; bad input exits 2 naming file and field.
And `plate proofs`, `plate field`, `plate fixed-points`, `plate design` and `plate robustness` under `mpirun -np 2` give the
single-process output to the last digit (but wall times).

    check_sweep.py PLATE SOURCE_DIR WORKDIR [MPIRUN]

Each case is slowed to >= 0.15 s (0.6 s) by the test hook PLATE_TEST_SWEEP_CASE_DELAY where a run is to be
killed in the middle, so that the kill lands mid-run on any machine. Exit 1 with what failed.
"""
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

plate, source, work = sys.argv[1], pathlib.Path(sys.argv[2]).resolve(), pathlib.Path(sys.argv[3]).resolve()
mpirun = sys.argv[4] if len(sys.argv) > 4 and sys.argv[4] else None
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", PLATE_PROGRESS="0",
           OMPI_MCA_rmaps_base_oversubscribe="1")
campaign = work / "campaign.json"
campaign.write_text(json.dumps({
    "name": "check_sweep",
    "scene": str(source / "scenes" / "fig4.json"),
    "parameters": [
        {"name": "x_amp", "pointer": "/plate/harmonics/0/amp", "values": [10, 25]},
        {"name": "mu", "pointer": "/part/friction", "values": [0.3, -0.2]},   # -0.2: a failed row each
        {"name": "rx_phase", "pointer": "/plate/harmonics/2/phase", "from": 0, "to": 4.71238898038469, "count": 4},
    ],
    "compute": {"twist_at": [[0.01, 0, 0.5]], "field": {"grid": [5, 5, 5]}, "fixed_points": True},
}))
CASES = 16


def sweep(out, *extra, launcher=(), delay=None):
    e = dict(env)
    if delay:
        e["PLATE_TEST_SWEEP_CASE_DELAY"] = str(delay)
    return [*launcher, plate, "sweep", str(campaign), "--out", str(out), *extra], e


def run(out, *extra, launcher=(), delay=None):
    cmd, e = sweep(out, *extra, launcher=launcher, delay=delay)
    p = subprocess.run(cmd, env=e, capture_output=True, text=True, timeout=600)
    summary = json.loads(p.stdout) if p.returncode == 0 and p.stdout.strip() else None
    return p, summary


def table(out):
    return (out / "table.csv").read_bytes() + b"\n--\n" + (out / "table.jsonl").read_bytes()


def journal_cases(out):
    j = out / "journal.jsonl"
    return max(0, j.read_text().count("\n") - 1) if j.exists() else 0


def start_and_wait(out, cases, launcher=(), threads="1", delay=0.15):
    if launcher:
        launcher = [*launcher, "-x", "PLATE_TEST_SWEEP_CASE_DELAY"]
    cmd, e = sweep(out, "--threads", threads, launcher=launcher, delay=delay)
    p = subprocess.Popen(cmd, env=e, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    t0 = time.time()
    while journal_cases(out) < cases and p.poll() is None and time.time() - t0 < 300:
        time.sleep(0.01)
    return p


MPI = [mpirun, "-np", "2", "--oversubscribe"] if mpirun else None

# --- the reference and its copies -------------------------------------------------------------------
ref = work / "ref"
p, s = run(ref, "--threads", "1")
check(p.returncode == 0 and s and s["cases"] == CASES and s["computed"] == CASES, f"one thread: {CASES} cases ({p.stderr.strip()[:300]})")
rows = [json.loads(l) for l in (ref / "table.jsonl").read_text().splitlines()]
failed = [r for r in rows if r["status"] == "failed"]
check(len(rows) == CASES and [r["case"] for r in rows] == list(range(CASES)), "one row per case, in case order")
check(len(failed) == CASES // 2 and all(r["mu"] == -0.2 and "friction" in r["reason"] for r in failed),
      "the 8 cases with friction -0.2 failed with a reason naming the friction; the others are ok")
check(all(r["fp_stable"] is not None and (r["stable_rate"] is None or r["stable_rate"] > 0) for r in rows if r["status"] == "ok"),
      "every ok row has its fixed points classified (a stable one converges: rate > 0)")
check(s and s["failed"] == CASES // 2, "the summary counts the failed rows")

p, s = run(work / "two_threads", "--threads", "2")
check(p.returncode == 0 and table(work / "two_threads") == table(ref), "two threads: the same table, byte for byte")

if MPI:
    out = work / "mpi"
    p, s = run(out, "--threads", "1", launcher=MPI)
    check(p.returncode == 0 and s and "2 MPI ranks" in s["farm"], f"mpirun -np 2 runs ({p.stderr.strip()[:300]})")
    check(p.returncode == 0 and table(out) == table(ref), "mpirun -np 2: the same table, byte for byte")
    ranks = {l.split(",")[1] for l in (out / "timing.csv").read_text().splitlines()[1:]} if p.returncode == 0 else set()
    check(ranks == {"0", "1"}, f"both ranks computed cases (ranks seen: {sorted(ranks)})")
else:
    print("skip mpirun: no MPI launcher given (Open MPI not installed or the program built without it)")

# --- killed and resumed -------------------------------------------------------------------------------
def resumed_equals_ref(out, label, launcher=()):
    before = journal_cases(out)
    check(not (out / "table.csv").exists(), f"{label}: no table after the kill ({before} cases in the journal)")
    check(0 < before < CASES, f"{label}: the kill landed mid-run ({before} of {CASES} cases journaled)")
    # A write cut short by the kill: half a line at the end of the journal.
    with open(out / "journal.jsonl", "a") as j:
        j.write('{"case": 15, "rank": 0, "seconds": 0.2, "row": {"case": 15, "x_a')
    p, s = run(out, "--threads", "2" if not launcher else "1", launcher=launcher)
    check(p.returncode == 0 and s and s["resumed"] == before and s["computed"] == CASES - before
          and s["torn_journal_lines_dropped"] == 1,
          f"{label}: resumed {before} cases, computed the other {CASES - before}, cut the torn line "
          f"({s and {k: s[k] for k in ('resumed', 'computed', 'torn_journal_lines_dropped')}} {p.stderr.strip()[:200]})")
    check(p.returncode == 0 and table(out) == table(ref), f"{label}: the resumed table equals the uninterrupted one")
    # The resumed run appended after the cut journal (not over it): a third run finds every case.
    p, s = run(out, "--threads", "1")
    check(p.returncode == 0 and s and s["resumed"] == CASES and s["computed"] == 0 and s["torn_journal_lines_dropped"] == 0
          and table(out) == table(ref), f"{label}: run again, every case is in the journal, nothing recomputed")


out = work / "killed"
proc = start_and_wait(out, 3)
proc.kill()
proc.wait()
resumed_equals_ref(out, "SIGKILL of the process")

if MPI:
    out = work / "killed_rank"
    proc = start_and_wait(out, 3, launcher=MPI)
    victim = None
    for d in pathlib.Path("/proc").iterdir():   # the rank-1 plate process of this run
        try:
            environ = (d / "environ").read_bytes().split(b"\0")
            cmdline = (d / "cmdline").read_bytes()
        except (OSError, ValueError):
            continue
        if b"OMPI_COMM_WORLD_RANK=1" in environ and str(out).encode() in cmdline:
            victim = int(d.name)
    check(victim is not None, "found rank 1's process")
    if victim:
        os.kill(victim, signal.SIGKILL)
    try:
        rc = proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        rc = "hung"
    check(rc != 0, f"mpirun ends when a rank is killed (exit {rc})")
    resumed_equals_ref(out, "SIGKILL of MPI rank 1", launcher=MPI)

    # (Open MPI's launcher lets its ranks run on for about a second after SIGINT: slower cases here.)
    out = work / "interrupted"
    proc = start_and_wait(out, 3, launcher=MPI, delay=0.6)
    proc.send_signal(signal.SIGINT)
    try:
        rc = proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        rc = "hung"
    check(rc != 0, f"SIGINT ends mpirun (exit {rc})")
    resumed_equals_ref(out, "SIGINT of the launcher", launcher=MPI)

# --- bad input --------------------------------------------------------------------------------------
other = work / "other.json"
spec = json.loads(campaign.read_text())
spec["parameters"][0]["values"] = [10, 26]
other.write_text(json.dumps(spec))
before = table(ref)
p = subprocess.run([plate, "sweep", str(other), "--out", str(ref)], env=env, capture_output=True, text=True)
check(p.returncode == 2 and "journal of another campaign" in p.stderr and table(ref) == before,
      f"another campaign into the same folder: exit 2, the table untouched ({p.returncode}: {p.stderr.strip()[:200]})")
spec["parameters"][0]["pointer"] = "/plate/harmonics/7/amp"
other.write_text(json.dumps(spec))
p = subprocess.run([plate, "sweep", str(other), "--out", str(work / "never")], env=env, capture_output=True, text=True)
check(p.returncode == 2 and str(other) in p.stderr and "parameters[0].pointer" in p.stderr and not (work / "never").exists(),
      f"a pointer to no field: exit 2 naming file and field, no folder ({p.returncode}: {p.stderr.strip()[:200]})")
if MPI:
    p = subprocess.run([*MPI, plate, "sweep", str(other), "--out", str(work / "never")], env=env, capture_output=True, text=True, timeout=120)
    check(p.returncode == 2 and p.stderr.count("parameters[0].pointer") == 1 and not (work / "never").exists(),
          f"the same under mpirun: exit 2, said once (by rank 0), no folder ({p.returncode}: {p.stderr.strip()[:300]})")

# The fingerprint covers the base scene's contents, not its path: the same campaign on an edited scene
# is another campaign.
edited_scene = work / "fig4_heavier.json"
sc = json.loads((source / "scenes" / "fig4.json").read_text())
sc["part"]["mass"] *= 1.5
edited_scene.write_text(json.dumps(sc))
spec = json.loads(campaign.read_text())
copy_dir = work / "edited"
shutil.copytree(ref, copy_dir)
spec["scene"] = str(edited_scene)
same_path = work / "campaign_edited.json"
same_path.write_text(json.dumps(spec))
p = subprocess.run([plate, "sweep", str(same_path), "--out", str(copy_dir)], env=env, capture_output=True, text=True)
check(p.returncode == 2 and "journal of another campaign" in p.stderr,
      f"the same campaign with the base scene's mass changed: another campaign, exit 2 ({p.returncode}: {p.stderr.strip()[:200]})")
# A parameter named like a column the table fills would be overwritten: refused.
spec = json.loads(campaign.read_text())
spec["parameters"][1]["name"] = "status"
named = work / "named_status.json"
named.write_text(json.dumps(spec))
p = subprocess.run([plate, "sweep", str(named), "--out", str(work / "named")], env=env, capture_output=True, text=True)
check(p.returncode == 2 and "parameters[1].name" in p.stderr and not (work / "named").exists(),
      f"a parameter named 'status': exit 2 naming the field, no folder ({p.returncode}: {p.stderr.strip()[:200]})")
# A second writer into a folder in use: refused while the first holds the lock.
busy = work / "busy"
proc = start_and_wait(busy, 1, delay=0.3)
p = subprocess.run([plate, "sweep", str(campaign), "--out", str(busy)], env=env, capture_output=True, text=True)
proc.kill()
proc.wait()
check(p.returncode == 2 and "is writing this folder" in p.stderr, f"a second run into a folder in use: exit 2 ({p.returncode}: {p.stderr.strip()[:200]})")

# --- plate proofs under mpirun: the contraction cases shared over the ranks, the same summary ----------
if MPI:
    outs = []
    for launcher in ((), MPI):
        f = work / f"proofs{len(outs)}.json"
        p = subprocess.run([*launcher, plate, "proofs", "--thin", "24", "--thick", "6", "--surfaces", "2", "--threads", "1",
                            "--out", str(f)], env=env, capture_output=True, text=True, timeout=600)
        outs.append(json.loads(f.read_text()) if p.returncode == 0 else None)
    if all(outs):
        mpi_said = outs[1].pop("mpi", "")
        for o in outs:
            for k in ("thin", "thick"):
                o[k].pop("seconds")   # (wall time)
    check(all(outs) and "2 MPI ranks" in mpi_said and outs[0] == outs[1] and outs[0]["thin"]["valid"] > 0,
          "plate proofs under mpirun -np 2: the same summary as one process, to the last digit (but its wall time)")

# --- plate field, fixed-points and design under mpirun: planes and starts shared, the same output -----
if MPI:
    def outputs(args, out_name, launchers):
        res = []
        for i, (launcher, threads) in enumerate(launchers):
            f = work / f"{out_name}{i}"
            p = subprocess.run([*launcher, plate, *args, "--threads", threads, "--out", str(f)], env=env,
                               capture_output=True, text=True, timeout=600)
            res.append((p.returncode, f.read_bytes() if f.exists() else None, p.stdout, p.stderr))
        return res
    one_two_mpi = [((), "1"), ((), "2"), (MPI, "1")]
    fig6 = str(source / "scenes" / "fig6.json")   # sticks in part: stick fractions, undefined points
    r = outputs(["field", fig6, "--grid", "9", "--format", "csv"], "field", one_two_mpi)
    check(all(x[0] == 0 for x in r) and r[0][1] and r[0][1] == r[1][1] == r[2][1] and r[0][1].count(b"\n") == 730,
          "plate field fig6 (9x9x9) CSV: 1 thread, 2 threads and mpirun -np 2 byte-identical")
    r = outputs(["field", fig6, "--grid", "5"], "fieldjson", [((), "1"), (MPI, "1")])
    if all(x[0] == 0 for x in r):
        a, b = (json.loads(x[1]) for x in r)
        said = b.pop("mpi", "")
        for o in (a, b):
            o.pop("seconds"), o.pop("threads")
    check(all(x[0] == 0 for x in r) and a == b and "2 MPI ranks" in said,
          "plate field JSON under mpirun: the same but wall time and who computed it")
    r = outputs(["fixed-points", str(source / "scenes" / "fig4.json")], "fp", [((), "2"), (MPI, "1")])
    check(all(x[0] == 0 for x in r) and r[0][1] == r[1][1] and b"stable" in r[0][1],
          "plate fixed-points fig4 under mpirun -np 2: byte-identical")
    r = outputs(["design", str(source / "scenes" / "fig1_point.json"), "--target", "sink", "0.02", "-0.01",
                 "--limits", "15", "100", "--starts", "4"], "design", [((), "2"), (MPI, "1")])
    ok = all(x[0] == 0 for x in r) and r[0][1] and r[0][1] == r[1][1]
    if ok:
        a, b = (json.loads(x[2]) for x in r)
        for o in (a, b):
            o.pop("seconds"), o.pop("scene")
            for run_ in o["full_dynamics_runs"]:
                run_.pop("seconds")
        ok = a == b and a["verified"]
    check(ok, "plate design (sink, 4 starts) under mpirun -np 2: the same scene byte for byte, the same summary")
    # plate robustness: the draws shared over the ranks, the same JSON but the wall times; the spec, read
    # by rank 0 and sent, reaches a rank that cannot see it.
    rob = ["robustness", str(source / "scenes" / "designs" / "point_sink.json"), "--uncertainty",
           str(source / "scenes" / "uncertainty" / "ppod.json"), "--draws", "6", "--starts", "2", "--full-draws", "1"]
    r = outputs(rob, "robustness", [((), "2"), (MPI, "1")])
    ok = all(x[0] == 0 for x in r) and r[0][1] and r[1][1]
    if ok:
        a, b = (json.loads(x[1]) for x in r)
        said = b.pop("mpi", "")
        for o in (a, b):
            o.pop("seconds"), o["sensitivity"].pop("seconds")
        ok = a == b and len(a["per_draw"]) == 6 and "2 MPI ranks" in said
    check(ok, "plate robustness (6 draws) under mpirun -np 2: the same JSON as one process, but its wall times")
    moved = work / "spec_rank0_only.json"
    shutil.copy(source / "scenes" / "uncertainty" / "ppod.json", moved)
    spec_mixed = [mpirun, "-np", "1", plate, *rob[:3], str(moved), *rob[4:], "--threads", "1", "--out", str(work / "rmixed.json"),
                  ":", "-np", "1", plate, *rob[:3], str(work / "missing_spec.json"), *rob[4:], "--threads", "1",
                  "--out", str(work / "rmixed.json")]
    p = subprocess.run(spec_mixed, env=env, capture_output=True, text=True, timeout=300)
    check(p.returncode == 0 and (work / "rmixed.json").exists(),
          f"plate robustness, rank 1 without the spec file: rank 0's spec, exit 0 ({p.returncode}: {p.stderr.strip()[:200]})")
    # The work budget means the same shared or not: heave_yaw's 5^3 field takes ~5.7e5 right-hand sides.
    for budget, expect in (("400000", 1), ("1000000", 0)):
        codes = []
        for launcher in ((), MPI):
            p = subprocess.run([*launcher, plate, "field", str(source / "scenes" / "heave_yaw.json"), "--grid", "5", "--threads", "1",
                                "--max-work", budget, "--out", str(work / "budget.json")], env=env, capture_output=True, text=True, timeout=600)
            codes.append(p.returncode)
        check(codes == [expect, expect], f"plate field --max-work {budget}: exit {expect} alone and under mpirun (got {codes})")
    # Rank 0 reads the scene and sends it: a rank that cannot see the file still computes (nodes without
    # a shared filesystem), and one that can while rank 0 cannot gets the same error, no hang.
    mixed = [mpirun, "-np", "1", plate, "field", str(source / "scenes" / "fig4.json"), "--threads", "1", "--out", str(work / "mixed.json"),
             ":", "-np", "1", plate, "field", str(work / "missing.json"), "--threads", "1", "--out", str(work / "mixed.json")]
    p = subprocess.run(mixed, env=env, capture_output=True, text=True, timeout=120)
    check(p.returncode == 0 and (work / "mixed.json").exists(), f"rank 1 without the scene file: rank 0's scene, exit 0 ({p.returncode})")
    p = subprocess.run([*MPI, plate, "field", str(work / "missing.json"), "--out", str(work / "nofield.json")], env=env,
                       capture_output=True, text=True, timeout=120)
    check(p.returncode == 2 and p.stderr.count("missing.json") == 1 and not (work / "nofield.json").exists(),
          f"plate field under mpirun, scene missing: exit 2, said once, no output ({p.returncode}: {p.stderr.strip()[:200]})")

if failures:
    print(f"{len(failures)} check(s) failed", file=sys.stderr)
    sys.exit(1)
shutil.rmtree(work, ignore_errors=True)
print("all sweep checks passed")
