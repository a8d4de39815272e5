#!/usr/bin/env python3
"""The campaigns' scaling study (issue 20, point 5): a benchmark, not a test.

    bench/scaling.py --out DIR [--plate build/plate] [--source .] [--mpirun mpirun] [--quick]

On this machine's cores, `plate sweep` runs
  * strong scaling: campaigns/fig4_amp_phase.json (400 cases) on 1 process x 1 thread, 1 x 2 threads
    and 2 MPI ranks x 1 thread (wall time, speed-up, efficiency; the three tables must be identical);
  * weak scaling: the same campaign cut to 100 cases per worker (1 worker: 100 cases, 2 workers: 200);
  * load balance: campaigns/heave_yaw_stick_slip.json, sliding and sticking cases whose times differ
    ~10x, on 2 workers: busy time over wall time x workers, against the makespan a static split into
    contiguous blocks would have had with the same measured case times;
  * one large field (fig4, 40^3) and one design (a point-part sink) under the same configurations;
  * the journal's cost: fdatasync of a case-sized line in DIR, the bytes sent per case;
and writes DIR/campaigns_scaling.svg, DIR/data/scaling.json and the report's "Campaigns" section
(DIR/data/campaigns_section.html, spliced into DIR/index.html when the report is there), including
what a 1 000-core run of 10^6 cases would cost, computed from these measurements.
Without MPI (no mpirun, or a program built without it) the MPI rows are left out and the page says so.
"""
import argparse
import html
import json
import os
import pathlib
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ap = argparse.ArgumentParser()
ap.add_argument("--out", required=True)
ap.add_argument("--plate", default=None)
ap.add_argument("--source", default=str(pathlib.Path(__file__).resolve().parent.parent))
ap.add_argument("--mpirun", default=shutil.which("mpirun") or "")
ap.add_argument("--quick", action="store_true", help="a quarter of the cases (a smoke run)")
a = ap.parse_args()
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from report_section import splice  # noqa: E402
src = pathlib.Path(a.source).resolve()
plate = str(pathlib.Path(a.plate).resolve()) if a.plate else str(src / "build" / "plate")
out = pathlib.Path(a.out).resolve()
(out / "data").mkdir(parents=True, exist_ok=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", PLATE_PROGRESS="0")
cores = os.cpu_count() or 1
work = pathlib.Path(tempfile.mkdtemp(prefix="plate_scaling_"))


def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def campaign(name, count_x):
    """fig4_amp_phase with count_x x-amplitudes (20 phases each), the scene path made absolute."""
    spec = json.loads((src / "campaigns" / name).read_text())
    spec["scene"] = str((src / "campaigns" / spec["scene"]).resolve())
    if count_x:
        spec["parameters"][0]["count"] = count_x
    f = work / f"{name[:-5]}_{count_x}.json"
    f.write_text(json.dumps(spec))
    return f


def sweep(camp, ranks, threads, tag):
    d = work / tag
    shutil.rmtree(d, ignore_errors=True)
    cmd = [plate, "sweep", str(camp), "--out", str(d), "--threads", str(threads)]
    if ranks > 1:
        cmd = [a.mpirun, "-np", str(ranks), "--oversubscribe", *cmd]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"scaling: {' '.join(cmd)} failed ({p.returncode}): {p.stderr[-800:]}")
    s = json.loads(p.stdout)
    times = [float(l.split(",")[2]) for l in (d / "timing.csv").read_text().splitlines()[1:]]
    lines = (d / "journal.jsonl").read_text().splitlines()[1:]
    return {"ranks": ranks, "threads": threads, "workers": s["workers"], "cases": s["cases"], "wall": wall,
            "seconds": s["seconds"], "busy": s["busy_seconds"], "efficiency": s["load_balance_efficiency"],
            "case_times": times, "bytes_per_case": statistics.mean(len(l) + 1 for l in lines),
            "table": (d / "table.csv").read_bytes(), "farm": s["farm"], "failed": s["failed"]}


mpi = bool(a.mpirun)
if mpi:   # built with MPI? (a program without it refuses to run under a launcher: exit 2)
    probe = subprocess.run([a.mpirun, "-np", "2", "--oversubscribe", plate, "sweep", "/nonexistent.json", "--out", str(work / "p")],
                           env=env, capture_output=True, text=True)
    mpi = "built without MPI" not in probe.stderr
configs = [(1, 1), (1, 2)] + ([(2, 1)] if mpi else [])
scale = 4 if a.quick else 1
base_x = 20 // scale

# Strong scaling.
strong_camp = campaign("fig4_amp_phase.json", base_x)
strong = [sweep(strong_camp, r, t, f"strong_{r}x{t}") for r, t in configs]
identical = all(s["table"] == strong[0]["table"] for s in strong)
# Weak scaling: 100 cases per worker (quick: 25).
weak = [sweep(campaign("fig4_amp_phase.json", max(2, 5 // scale) * (r * t)), r, t, f"weak_{r}x{t}") for r, t in configs]
# Load balance on sliding and sticking cases.
mixed_camp = src / "campaigns" / "heave_yaw_stick_slip.json"
lb = [sweep(mixed_camp, r, t, f"mixed_{r}x{t}") for r, t in configs if r * t == 2]


# One large field and one design, shared the same ways (plate field / plate design under mpirun).
def timed(args, ranks, threads, tag):
    f = work / tag
    cmd = [plate, *args, "--threads", str(threads), "--out", str(f)]
    if ranks > 1:
        cmd = [a.mpirun, "-np", str(ranks), "--oversubscribe", *cmd]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"scaling: {' '.join(cmd)} failed ({p.returncode}): {p.stderr[-800:]}")
    return {"ranks": ranks, "threads": threads, "wall": wall, "output": f.read_bytes(), "stdout": p.stdout}


G = 40 // scale if not a.quick else 16
field_args = ["field", str(src / "scenes" / "fig4.json"), "--grid", str(G), "--format", "csv"]
fields = [timed(field_args, r, t, f"field_{r}x{t}.csv") for r, t in configs]
design_args = ["design", str(src / "scenes" / "fig1_point.json"), "--target", "sink", "0.02", "-0.01", "--limits", "15", "100"]
if a.quick:
    design_args += ["--starts", "4"]
designs = [timed(design_args, r, t, f"design_{r}x{t}.json") for r, t in configs]
for d in designs:
    d["evaluations"] = json.loads(d["stdout"])["evaluations"]
fields_identical = all(x["output"] == fields[0]["output"] for x in fields)
designs_identical = all(x["output"] == designs[0]["output"] for x in designs)
# The field's serial part: the lines (x, y_0, theta) and (x, y, theta_0), solved in order in every process.
serial_share = (G * G + G * (G - 1)) / G**3


def static_makespan(times, workers):
    """The wall time of a static split into contiguous blocks, with the measured case times."""
    n = len(times)
    blocks = [times[w * n // workers:(w + 1) * n // workers] for w in range(workers)]
    return max(sum(b) for b in blocks)


# The journal's cost on this disk: fdatasync after each case-sized line (as rank 0 does).
line = "x" * int(strong[0]["bytes_per_case"] - 1) + "\n"
jf = out / "data" / "fsync_probe.jsonl"
with open(jf, "w") as f:
    t0 = time.perf_counter()
    for _ in range(200):
        f.write(line)
        f.flush()
        os.fdatasync(f.fileno())
    fsync = (time.perf_counter() - t0) / 200
jf.unlink()

one = strong[0]
t_case = statistics.mean(one["case_times"])
t_med = statistics.median(one["case_times"])
bytes_case = one["bytes_per_case"] + 4   # the result back, the 4-byte index out
N, P = 10**6, 1000
ideal = N * t_case / P
rate_needed = P / t_case                # cases per second arriving at rank 0
rate_root = 1 / fsync                   # cases per second rank 0 can journal, one fdatasync each
data = {
    "machine": f"{cpu_model()}, {cores} cores", "quick": a.quick, "mpi": mpi,
    "strong": [{k: v for k, v in s.items() if k not in ("table", "case_times")} for s in strong],
    "weak": [{k: v for k, v in s.items() if k not in ("table", "case_times")} for s in weak],
    "load_balance": [dict({k: v for k, v in s.items() if k not in ("table", "case_times")},
                          static_makespan=static_makespan(s["case_times"], s["workers"]),
                          case_min=min(s["case_times"]), case_max=max(s["case_times"])) for s in lb],
    "field": {"grid": G, "serial_share": serial_share, "identical": fields_identical,
              "runs": [{k: v for k, v in x.items() if k not in ("output", "stdout")} for x in fields]},
    "design": {"identical": designs_identical,
               "runs": [{k: v for k, v in x.items() if k not in ("output", "stdout")} for x in designs]},
    "identical_tables": identical, "fdatasync_seconds": fsync, "mean_case_seconds": t_case,
    "median_case_seconds": t_med, "bytes_per_case": bytes_case,
    "estimate": {"cases": N, "cores": P, "ideal_seconds": ideal, "arrival_rate": rate_needed,
                 "journal_rate": rate_root, "bytes_total": N * bytes_case},
}
(out / "data" / "scaling.json").write_text(json.dumps(data, indent=1))

# The figure.
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, ax = plt.subplots(1, 3, figsize=(13.5, 4.2))
labels = [f"{s['ranks']} rank{'s' if s['ranks'] > 1 else ''} x {s['threads']}" for s in strong]
speedup = [strong[0]["wall"] / s["wall"] for s in strong]
ax[0].bar(labels, speedup, color="#2c7fb8")
ax[0].axhline(1, color="#888", lw=0.8)
ax[0].plot(labels, [s["workers"] for s in strong], "k_", ms=40, mew=2, label="ideal")
ax[0].set_title(f"strong scaling: {strong[0]['cases']} cases of fig4", fontsize=11)
ax[0].set_ylabel("speed-up over 1 x 1 (wall time)")
ax[0].legend()
weff = [weak[0]["wall"] / s["wall"] for s in weak]
ax[1].bar([f"{s['ranks']} x {s['threads']}\n{s['cases']} cases" for s in weak], weff, color="#41b6c4")
ax[1].axhline(1, color="k", lw=1.5)
ax[1].set_ylim(0, 1.15)
ax[1].set_title("weak scaling: cases per worker fixed", fontsize=11)
ax[1].set_ylabel("efficiency T(1 worker) / T(n workers)")
xs = range(len(lb))
ax[2].bar([x - 0.2 for x in xs], [s["seconds"] for s in lb], 0.4, label="self-scheduled (measured)", color="#253494")
ax[2].bar([x + 0.2 for x in xs], [d["static_makespan"] for d in data["load_balance"]], 0.4,
          label="static blocks (from the case times)", color="#a1dab4")
ax[2].set_xticks(list(xs), [f"{s['ranks']} x {s['threads']}" for s in lb])
ax[2].set_ylabel("wall time [s]")
ax[2].set_title(f"load balance: {lb[0]['cases']} sliding and sticking cases" if lb else "load balance", fontsize=11)
ax[2].legend(fontsize=9)
fig.tight_layout()
fig.savefig(out / "campaigns_scaling.svg")

# The section: every number from the runs above.
def f(x, p=3):
    return f"{x:.{p}g}"


rows = "".join(f"<tr><td>{html.escape(s['farm'])}</td><td>{s['cases']}</td><td>{f(s['wall'])}</td><td>{f(s['seconds'])}</td>"
               f"<td>{f(strong[0]['wall'] / s['wall'])}</td><td>{f(strong[0]['wall'] / s['wall'] / s['workers'])}</td>"
               f"<td>{f(s['efficiency'])}</td></tr>" for s in strong)
wrows = "".join(f"<tr><td>{html.escape(s['farm'])}</td><td>{s['cases']}</td><td>{f(s['wall'])}</td>"
                f"<td>{f(weak[0]['wall'] / s['wall'])}</td></tr>" for s in weak)
lrows = "".join(f"<tr><td>{html.escape(s['farm'])}</td><td>{f(d['case_min'])} to {f(d['case_max'])}</td><td>{f(s['seconds'])}</td>"
                f"<td>{f(s['efficiency'])}</td><td>{f(d['static_makespan'])}</td><td>{s['failed']}</td></tr>"
                for s, d in zip(lb, data["load_balance"]))
root_bound = N / rate_root
# The mixed campaign's failed rows, by reason, read from its table.
import collections
import csv
reasons = collections.Counter()
if lb:
    with open(work / f"mixed_{lb[0]['ranks']}x{lb[0]['threads']}" / "table.csv") as t:
        for r in csv.DictReader(t):
            if r["status"] == "failed":
                reasons[r["reason"]] += 1
reasons_sentence = ("The mixed campaign's failed rows, by reason (from its table): " +
                    "; ".join(f"{html.escape(k)} ({v})" for k, v in reasons.most_common()) +
                    ". A failed case keeps its row and the campaign goes on.") if reasons else "No case of the mixed campaign failed."
mpi_rows = [s for s in strong + weak if s["ranks"] > 1]
launch_sentence = (f"mpirun adds {f(min(s['wall'] - s['seconds'] for s in mpi_rows))} to {f(max(s['wall'] - s['seconds'] for s in mpi_rows))} s"
                   " here (wall time minus the program's own)" if mpi_rows else "no MPI run here")
section = f"""<h2>Campaigns: <code>plate sweep</code> over threads and MPI ranks</h2>
<p>Measured by <code>bench/scaling.py</code>{' (quick: a quarter of the cases)' if a.quick else ''} on {html.escape(data['machine'])}.
{'MPI: Open MPI, <code>mpirun --oversubscribe</code>.' if mpi else '<b>No MPI run</b>: mpirun is missing or this plate was built without MPI; the rows below are threads only.'}
The tables of every strong-scaling run are {'identical byte for byte' if identical else '<b>NOT identical</b>'} (each case runs on one thread with the
same inputs, wherever it runs). Cases are handed out one at a time as workers free up (self-scheduling); rank 0 appends each result to the
journal with one <code>fdatasync</code>.</p>
<figure><img src="campaigns_scaling.svg" alt="scaling of plate sweep"><figcaption>Left: strong scaling of {strong[0]['cases']} fig4 cases
(fixed points on a 7x7x7 field each). Middle: weak scaling at {weak[0]['cases']} cases per worker. Right: a campaign mixing sliding and
sticking cases, self-scheduled, against a static split into contiguous blocks with the same case times.</figcaption></figure>
<table><tr><th>strong scaling</th><th>cases</th><th>wall [s]</th><th>in the program [s]</th><th>speed-up</th><th>efficiency</th>
<th>busy / (wall x workers)</th></tr>{rows}</table>
<table><tr><th>weak scaling</th><th>cases</th><th>wall [s]</th><th>efficiency</th></tr>{wrows}</table>
<table><tr><th>load balance (heave_yaw_stick_slip)</th><th>case times [s]</th><th>wall [s]</th><th>busy / (wall x workers)</th>
<th>static blocks' makespan [s]</th><th>failed rows</th></tr>{lrows}</table>
<p>{reasons_sentence}</p>
<h3>One large field, one design</h3>
<p><code>plate field</code>, <code>plate fixed-points</code> and <code>plate design</code> share their work the same way under
<code>mpirun</code>: a field's planes x = const (after the lines (x, y<sub>0</sub>, theta) and (x, y, theta<sub>0</sub>), which every
process solves in order because each cycle start is predicted from those before it: {f(100 * serial_share, 2)} % of a {G}<sup>3</sup>
grid, so at most {f(1 / serial_share, 3)}x over any number of ranks), a design's starts and its verification. The outputs of the runs below
are {'identical byte for byte' if fields_identical and designs_identical else '<b>NOT identical</b>'}.</p>
<table><tr><th></th>{''.join(f"<th>{x['ranks']} rank{'s' if x['ranks'] > 1 else ''} x {x['threads']}</th>" for x in fields)}</tr>
<tr><td>fig4 field, {G}<sup>3</sup> = {G**3} configurations: wall [s] (speed-up)</td>{''.join(f"<td>{f(x['wall'])} ({f(fields[0]['wall'] / x['wall'])})</td>" for x in fields)}</tr>
<tr><td>point-part sink design, {designs[0]['evaluations']} evaluations: wall [s] (speed-up)</td>{''.join(f"<td>{f(x['wall'])} ({f(designs[0]['wall'] / x['wall'])})</td>" for x in designs)}</tr></table>
<h3>What a 1 000-core run of 10<sup>6</sup> cases would cost</h3>
<p>A fig4 case (fixed points on a 7x7x7 field) took {f(t_case)} s on average here (median {f(t_med)} s) and sends {f(bytes_case, 4)} bytes
(its row back, a 4-byte index out). 10<sup>6</sup> such cases are {f(N * t_case / 3600)} core-hours: on {P} cores, ideally {f(ideal)} s
({f(ideal / 60)} min). Results would reach rank 0 at {f(rate_needed)} cases/s, {f(N * bytes_case / 1e9)} GB in all
({f(rate_needed * bytes_case / 1e6)} MB/s: nothing for a cluster network). The limit is the journal: one <code>fdatasync</code> took
{f(fsync * 1e3)} ms on this disk, so rank 0 can journal at most {f(rate_root)} cases/s one at a time
{'-- fewer than arrive: the run would take ' + f(root_bound) + ' s, bound by rank 0, unless the journal commits cases in groups (one fdatasync per batch of ' + f(rate_needed / rate_root * 2, 2) + ' or more, losing at most that batch on a kill) or each rank journals its own cases' if rate_root < rate_needed else '-- more than arrive, so the run stays compute-bound'}.
The launcher's start-up is in the wall times above: {launch_sentence}.</p>
"""
(out / "data" / "campaigns_section.html").write_text(section)
splice(out, "<!-- campaigns:begin -->", "<!-- campaigns:end -->", section)
shutil.rmtree(work, ignore_errors=True)
print(json.dumps({k: data[k] for k in ("machine", "identical_tables", "fdatasync_seconds", "mean_case_seconds", "estimate")}, indent=1))
for x in fields:
    print(f"field {G}^3 {x['ranks']} x {x['threads']}: wall {x['wall']:.3f} s, speed-up {fields[0]['wall'] / x['wall']:.3f}")
for x in designs:
    print(f"design {x['ranks']} x {x['threads']}: wall {x['wall']:.3f} s, speed-up {designs[0]['wall'] / x['wall']:.3f}")
print(f"fields identical: {fields_identical}, designs identical: {designs_identical}")
for s in strong:
    print(f"strong {s['farm']}: {s['cases']} cases, wall {s['wall']:.3f} s, speed-up {strong[0]['wall'] / s['wall']:.3f}")
for s in weak:
    print(f"weak {s['farm']}: {s['cases']} cases, wall {s['wall']:.3f} s, efficiency {weak[0]['wall'] / s['wall']:.3f}")
for s, d in zip(lb, data["load_balance"]):
    print(f"mixed {s['farm']}: wall {s['seconds']:.3f} s, busy/(wall x workers) {s['efficiency']:.3f}, static blocks {d['static_makespan']:.3f} s")
