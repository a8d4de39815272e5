#!/usr/bin/env python3
"""The peers study (issue 19): Bullet, ODE, MuJoCo and plate on the same questions, one run.

    bench/peers/study.py --out DIR [--build build] [--quick] [--data PEERS.json]

Runs BUILD/bench_peers (the engines found when plate was built; see bench/peers/peers.hpp for each
engine's settings and why), then writes DIR/peers_*.svg (error against CPU time, one curve per engine
and per plate method), DIR/data/peers.json and the report's section DIR/data/peers_section.html,
spliced into DIR/index.html between the peers markers when the report is there. Every sentence of
the section is computed from the run: the ratios are
  * speed-up at equal accuracy: the engine's CPU time at its most accurate setting over the CPU time
    of plate's cheapest setting at least as accurate;
  * accuracy at equal time: the engine's best error over the error of plate's most accurate setting
    that costs no more CPU time than the engine took.
A benchmark, not a test (the drivers' tests are tests/test_peers.cpp).
"""
import argparse
import html
import json
import math
import pathlib
import subprocess
import sys

ap = argparse.ArgumentParser()
ap.add_argument("--out", required=True)
ap.add_argument("--build", default=None)
ap.add_argument("--quick", action="store_true")
ap.add_argument("--data", default=None, help="chart this bench_peers JSON instead of running it")
a = ap.parse_args()
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
from report_section import splice  # noqa: E402
src = pathlib.Path(__file__).resolve().parent.parent.parent
build = pathlib.Path(a.build).resolve() if a.build else src / "build"
out = pathlib.Path(a.out).resolve()
(out / "data").mkdir(parents=True, exist_ok=True)
exe = build / "bench_peers"
data_file = out / "data" / "peers.json"
if a.data:
    d = json.loads(pathlib.Path(a.data).read_text())
elif not exe.exists():
    section = ("<h2>Side by side with Bullet, ODE and MuJoCo</h2><p><b>Not run</b>: no peer engine was found when plate was built "
               "(Debian libbullet-dev, libode-dev, libmujoco-dev), so <code>bench_peers</code> does not exist.</p>\n")
    d = None
else:
    cmd = [str(exe), "--out", str(data_file), "--source", str(src)] + (["--quick"] if a.quick else [])
    p = subprocess.run(cmd)
    if p.returncode != 0:
        sys.exit(f"peers: {' '.join(cmd)} failed ({p.returncode})")
    d = json.loads(data_file.read_text())

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

COLORS = {"plate": "#000000", "Bullet": "#d95f02", "ODE": "#7570b3", "MuJoCo": "#1b9e77"}


def family(system):
    for k in ("Bullet", "ODE", "MuJoCo"):
        if system.startswith(k):
            return k
    return "plate"


def finite(p):
    return p.get("error") is not None and math.isfinite(p["error"]) and p["error"] > 0 and p["cpu"] > 0


def f(x, n=2):
    return f"{x:.{n}g}"


def ratios(points, floor):
    """Per engine: its best point, plate's cheapest point at least as accurate, plate's best point in its time.
    Errors below the reference's own (floor) are not resolved: such a ratio is a lower bound."""
    plate = [p for p in points if p["system"] == "plate" and finite(p)]
    rows = []
    for eng in sorted({p["system"] for p in points if p["system"] != "plate"}):
        mine = [p for p in points if p["system"] == eng and finite(p)]
        if not mine:
            rows.append({"engine": eng, "failed": True})
            continue
        best = min(mine, key=lambda p: (p["error"], p["cpu"]))
        equal_acc = [p for p in plate if p["error"] <= best["error"]]
        cheap = min(equal_acc, key=lambda p: p["cpu"]) if equal_acc else None
        in_time = [p for p in plate if p["cpu"] <= best["cpu"]]
        sharp = min(in_time, key=lambda p: p["error"]) if in_time else None
        # The same against each of the engine's settings: the smallest is the ratio no setting beats.
        per_setting = []
        for p in mine:
            ok = [x for x in plate if x["error"] <= p["error"]]
            if ok:
                per_setting.append((p["cpu"] / min(x["cpu"] for x in ok), p["setting"]))
        worst = min(per_setting) if per_setting else None
        rows.append({"engine": eng, "best": best, "plate_equal_accuracy": cheap, "plate_in_time": sharp,
                     "speedup_any_setting": worst[0] if worst else None, "speedup_any_setting_at": worst[1] if worst else None,
                     "speedup": best["cpu"] / cheap["cpu"] if cheap else None,
                     "accuracy_ratio": best["error"] / max(sharp["error"], floor) if sharp else None,
                     "accuracy_ratio_is_bound": bool(sharp and sharp["error"] < floor)})
    return rows


def chart(q, key_of, title, fname):
    fig, ax = plt.subplots(figsize=(7.2, 4.6))
    groups = {}
    for p in d[q]["points"]:
        if finite(p):
            groups.setdefault(key_of(p), []).append(p)
    for label, pts in sorted(groups.items()):
        pts.sort(key=lambda p: p["cpu"])
        fam = family(label)
        style = "D:" if "averag" in label else "o-" if fam == "plate" else "s--"
        ax.loglog([p["cpu"] for p in pts], [p["error"] for p in pts], style,
                  color="#555555" if "averag" in label else COLORS[fam], label=label, ms=4, lw=1.2,
                  alpha=1 if fam == "plate" or "k 5" in label or "k" not in label else 0.5)
    for p in d[q].get("protocol_error", []):
        ax.loglog([p["cpu"]], [p["error"]], "x", color="#e7298a", ms=8)
    if d[q].get("protocol_error"):
        ax.plot([], [], "x", color="#e7298a", label="plate's full dynamics, the engines' protocol (k = 2, 5, 10, 20)")
    ax.set_xlabel("CPU time [s]")
    ax.set_ylabel("error (relative)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(out / fname)
    plt.close(fig)


if d is not None:
    qs = {"a": "peers_trajectory.svg", "b": "peers_twist.svg", "c": "peers_field.svg", "d": "peers_sticking.svg"}
    for q, fname in qs.items():
        if q == "b":   # one curve per engine and k (over dt)
            key = lambda p: p["system"] if p["system"] == "plate" else p["system"] + ", " + p["setting"].split(", ")[1]
        else:   # (a): plate's direct integration and its stroboscopic averaging apart
            key = lambda p: "plate, stroboscopic averaging" if p["setting"].startswith("averaged") else p["system"]
        chart(q, key, f"({q}) {d[q]['question']}", fname)
    d["ratios"] = {q: ratios(d[q]["points"], d[q]["reference_error"]) for q in qs}
    data_file.write_text(json.dumps(d, indent=1))

    def ratio_rows(q):
        rows = []
        for r in d["ratios"][q]:
            if r.get("failed"):
                rows.append(f"<tr><td>{html.escape(r['engine'])}</td><td colspan=6>every setting failed</td></tr>")
                continue
            b, c, s = r["best"], r["plate_equal_accuracy"], r["plate_in_time"]
            rows.append(
                f"<tr><td>{html.escape(r['engine'])}</td><td>{html.escape(b['setting'])}: {f(b['error'])} in {f(b['cpu'])} s</td>"
                f"<td>{html.escape(c['setting']) + ': ' + f(c['error']) + ' in ' + f(c['cpu']) + ' s' if c else 'none as accurate'}</td>"
                f"<td><b>{f(r['speedup'], 3) + 'x' if r['speedup'] else '-'}</b></td>"
                f"<td>{f(r['speedup_any_setting'], 3) + 'x (' + html.escape(r['speedup_any_setting_at']) + ')' if r['speedup_any_setting'] else '-'}</td>"
                f"<td>{html.escape(s['setting']) + ': ' + f(s['error']) if s else 'none as fast'}</td>"
                f"<td><b>{('>= ' if r['accuracy_ratio_is_bound'] else '') + f(r['accuracy_ratio'], 3) + 'x' if r['accuracy_ratio'] else '-'}</b></td></tr>")
        note = (f"<p>Errors are resolved down to the reference's own, {f(d[q]['reference_error'])} (its change against a reference a "
                "decade looser); an accuracy ratio marked &gt;= met that floor.</p>")
        return note + ("<table><tr><th>engine</th><th>its best setting: error in CPU time</th><th>plate's cheapest setting at least as accurate</th>"
                "<th>speed-up at equal accuracy</th><th>the smallest against any of the engine's settings</th><th>plate's best setting in the engine's time</th><th>accuracy ratio at equal time</th></tr>"
                + "".join(rows) + "</table>")

    def minimum(q, key):
        vals = [r[key] for r in d["ratios"][q] if not r.get("failed") and r.get(key)]
        return min(vals) if vals else None

    def failures(q):
        fs = [p for p in d[q]["points"] if p.get("failure")]
        if not fs:
            return ""
        return ("<p>Runs that did not finish: " + "; ".join(f"{html.escape(p['system'])} {html.escape(p['setting'])}: "
                                                             f"{html.escape(p['failure'])}" for p in fs) + ".</p>")

    b = d["b"]
    prot = b.get("protocol_error", [])
    best_prot = min(prot, key=lambda p: p["error"]) if prot else None
    eng_b = [p for p in b["points"] if p["system"] != "plate" and finite(p)]
    best_eng_b = min(eng_b, key=lambda p: p["error"]) if eng_b else None
    engines = "".join(f"<li><b>{html.escape(e['name'])}</b>: {html.escape(e['settings'])}</li>" for e in d["engines"])
    lift = {}
    for p in d["a"]["points"]:
        if "max_lift" in p:
            lift[p["system"]] = max(lift.get(p["system"], 0), p["max_lift"])
    lifts = ", ".join(f"{html.escape(k)} {f(v * 1e6)} um" for k, v in sorted(lift.items())) or "not measured"
    goal_c = minimum("c", "speedup"), minimum("c", "accuracy_ratio")
    goal_a = minimum("a", "speedup")
    any_c, any_a = minimum("c", "speedup_any_setting"), minimum("a", "speedup_any_setting")

    def goal(x, target):
        return "-" if x is None else (f"{f(x, 3)}x, " + ("met" if x >= target else "<b>NOT met</b>"))

    section = f"""<h2>Side by side with Bullet, ODE and MuJoCo</h2>
<p>Measured by <code>bench/peers/study.py</code>{' (quick: shorter runs, fewer settings)' if d['quick'] else ''} on {html.escape(d['machine'])},
one run, one thread each. The engines found when this plate was built, each set up as a careful user would (what was set and why;
more in <code>bench/peers/*_driver.cpp</code>): the part as one body with three spheres of 0.5 mm whose lowest points are the contacts, the plate as a
kinematic box moved along the full dynamics' plate trajectory, Coulomb friction mu:</p><ul>{engines}</ul>
<p>Before their numbers are used the drivers are tested (<code>tests/test_peers.cpp</code>): on a plate at rest, on a plate translating
uniformly and on a plate rocking slowly (tilt below the friction angle) each keeps the part in place within 0.1 mm and 1 mrad over 2 s; on a plate
translating harmonically in x each drags it as the 1-D Coulomb law integrated on its own says (Bullet and ODE within a fifth of the travel;
MuJoCo's soft friction lets the part travel 1.4-1.6 times as far, whatever its settings); on fig4's plate each ends within 1 mm of plate's
position after 1 s and turns it by 0.5-1.5 times plate's angle. With the engines' friction pyramids (MuJoCo's pyramidal cone, ODE's box, Bullet's
two fixed directions) that last test fails for all three (Bullet and ODE turn the part the wrong way). Time is each system's thread CPU time:
the engines' stepping alone (building the model and moving the plate left out), plate's whole call. Errors are relative: configurations to
(rho, rho, 1 rad), twists to (v_ref, v_ref, v_ref/rho). Largest lift of the part's centre off its resting height in (a):
{lifts}.</p>
<h3>(a) {html.escape(d['a']['question'])}</h3>
<figure><img src="peers_trajectory.svg" alt="trajectory error against CPU time"><figcaption>Final-configuration error against CPU time:
engines over steps dt, plate's event-driven integrator over tolerances, and its stroboscopic averaging of the same full dynamics
(<code>simulate_averaged</code>: Heun's method on the configuration and the plate's orientation over macro steps of many periods, each slope
measured by a burst of the full dynamics; over its macro tolerance at rtol 1e-5) (reference: plate at rtol 1e-12, itself within
{f(d['a']['reference_error'])} of rtol 1e-11).</figcaption></figure>
{ratio_rows('a')}
{failures('a')}
<p>Goal: plate at least 10x faster at equal or better accuracy: the smallest speed-up over the engines (each at its most accurate
setting) is {goal(goal_a, 10)}; against any of their settings, {goal(any_a, 10)}.</p>
<h3>(b) {html.escape(b['question'])}</h3>
<figure><img src="peers_twist.svg" alt="twist error against CPU time"><figcaption>An engine cannot hold the configuration still: it simulates
k periods from rest and averages the next, (q((k+1)T) - q(kT))/T. Dashed: each engine at k = 2, 5, 10, 20 over dt; crosses: plate's own full
dynamics under the same protocol (rtol 1e-11).</figcaption></figure>
<p>This estimate has a method error besides the step error: the part moves while the transient dies out, so it measures the twist somewhere
else. plate's own exact full dynamics under the engines' protocol are {f(best_prot['error']) if best_prot else '-'} off at best
({html.escape(best_prot['setting']) if best_prot else ''}), and the engines' best is {f(best_eng_b['error']) if best_eng_b else '-'}
({html.escape(best_eng_b['system'] + ' ' + best_eng_b['setting']) if best_eng_b else ''}): no step size removes it, while plate's limit cycle
holds q fixed and converges to the reference.</p>
{ratio_rows('b')}
<h3>(c) {html.escape(d['c']['question'])}</h3>
<figure><img src="peers_field.svg" alt="field error against CPU time"><figcaption>The largest twist error over the {d['c']['configurations']}
configurations against the whole field's CPU time: engines with the protocol of (b) at each configuration, plate's field (shooting, warm
starts) on one thread over tolerances.</figcaption></figure>
{ratio_rows('c')}
<p>Goals: plate at least 100x faster than every engine, and at least 100x more accurate. Smallest speed-up at equal accuracy over the engines
(each at its most accurate setting): {goal(goal_c[0], 100)}; against any of their settings (a cheaper step that is nearly as accurate):
{goal(any_c, 100)}; smallest accuracy ratio at equal time: {goal(goal_c[1], 100)}.</p>
<h3>(d) {html.escape(d['d']['question'])}</h3>
<figure><img src="peers_sticking.svg" alt="sticking twists error against CPU time"><figcaption>The {d['d']['configurations']} sticking
configurations: plate's stick-slip limit cycles against the engines' protocol.</figcaption></figure>
{ratio_rows('d')}
{failures('d')}
"""
(out / "data" / "peers_section.html").write_text(section)
splice(out, "<!-- peers:begin -->", "<!-- peers:end -->", section)
if d is not None:
    for q in ("a", "b", "c", "d"):
        for r in d["ratios"][q]:
            if not r.get("failed"):
                print(f"({q}) {r['engine']}: speed-up at equal accuracy {r['speedup']} (smallest over its settings {r['speedup_any_setting']}), "
                      f"accuracy ratio at equal time {r['accuracy_ratio']}")
print(f"peers: {out / 'data' / 'peers_section.html'}")
