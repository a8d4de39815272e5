"""Long calls stop on Ctrl-C within 0.5 s (KeyboardInterrupt, no result), report progress with an
estimate of the time left, and a field has the command line's work budget by default (issue 54)."""
import math
import os
import re
import signal
import subprocess
import threading
import time

import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")


def scene_path(name):
    return os.path.join(SOURCE, "scenes", name + ".json")


def latency_of_ctrl_c(call, after=1.0, tries=2):
    """Seconds from a SIGINT sent to this process `after` s into call() to the KeyboardInterrupt: the best of
    `tries` calls. What the 0.5 s bound guards is the calls' polling (a missing poll waits for the whole call,
    seconds every time); one sample under a parallel ctest also measures the scheduler. With three busy
    loops beside it on this 2-core machine the report's fields section measured 0.41-0.61 s at 1 s in, and
    0.013-0.04 s alone; so the best of two."""
    best = None
    for _ in range(tries):
        t = _latency_once(call, after)
        best = t if best is None else min(best, t)
        if best < 0.5:
            break
    return best


def _latency_once(call, after):
    sent = {}

    def interrupt():
        sent["t"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(after, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
        return time.perf_counter() - sent["t"]
    finally:
        timer.cancel()


def test_ctrl_c_stops_a_long_field_within_half_a_second():
    # fig6 at grid 25 (15625 configurations) takes about 12 s on two cores. The interpreter's
    # thread looks at signals every 0.05 s while the field runs and the field's workers see the request
    # at their next integrator step: measured 0.024-0.026 s here on the loaded 2-core machine. Without
    # PyErr_CheckSignals in that poll the KeyboardInterrupt came only after the whole field, 8.3 s
    # after the signal, as the issue reports.
    sc = plate.load_scene(scene_path("fig6"))
    assert latency_of_ctrl_c(lambda: plate.field(sc, grid=25, max_work=0)) < 0.5


def test_ctrl_c_stops_a_report_within_half_a_second_and_leaves_no_page(tmp_path):
    # The quick report's fields section takes about 10 s here; interrupted after 1 s it leaves no
    # index.html (the page is written whole at the end, and an old one is removed at the start).
    out = tmp_path / "report"
    out.mkdir()
    (out / "index.html").write_text("an older page")
    assert latency_of_ctrl_c(lambda: plate.report(out, quick=True, sections=["fields"])) < 0.5
    assert not (out / "index.html").exists()


def test_ctrl_c_stops_the_speed_study_within_half_a_second(tmp_path):
    # The quick speed study takes minutes; its integrations see the request at their next step.
    assert latency_of_ctrl_c(lambda: plate.bench(tmp_path / "bench")) < 0.5
    assert not (tmp_path / "bench" / "index.html").exists()


def test_ctrl_c_stops_a_design_within_half_a_second():
    # A design whose search and verification take 48 s here; measured latency 0.06-0.11 s.
    part = plate.load_scene(scene_path("fig1_point"))
    assert latency_of_ctrl_c(lambda: plate.design(part, sink=(0.02, -0.01), starts=50, verify_starts=50)) < 0.5


def test_progress_counts_configurations_and_estimates_the_time_left():
    # fig6 at grid 15 on one thread: 1.9 s here, 37 reports.
    seen = []
    f = plate.field(plate.load_scene(scene_path("fig6")), grid=15, threads=1, progress=seen.append)
    assert len(seen) >= 5, "a field of about 2 s reports every 0.05 s"
    assert all(p.total == 15 ** 3 for p in seen)
    done = [p.done for p in seen]
    assert done == sorted(done) and done[-1] == 15 ** 3
    assert seen[-1].seconds_left == 0 and seen[-1].seconds <= f.seconds + 0.1
    left = [p.seconds_left for p in seen if 0 < p.done < p.total]
    assert all(math.isfinite(x) and x > 0 for x in left)
    # The estimate falls as the work goes on: the last third's below the first third's.
    third = max(1, len(left) // 3)
    assert max(left[-third:]) < min(left[:third]), left


def test_robustness_reports_its_draws_done():
    # designs/point_sink under the PPOD spec, 12 draws on one thread: about 0.5 s here.
    seen = []
    r = plate.robustness(plate.load_scene(scene_path("designs/point_sink")), scene_path("uncertainty/ppod"), draws=12,
                         threads=1, progress=seen.append)
    assert seen and all(p.total == 12 for p in seen)
    done = [p.done for p in seen]
    assert done == sorted(done) and done[-1] == 12 and len(r.outcome) == 12
    assert seen[-1].seconds_left == 0 and seen[-1].seconds <= r.seconds + 0.1


def test_an_exception_in_the_progress_callable_stops_the_call():
    def refuse(p):
        raise RuntimeError("stop here")

    t0 = time.perf_counter()
    with pytest.raises(RuntimeError, match="stop here"):
        plate.field(plate.load_scene(scene_path("fig6")), grid=25, max_work=0, progress=refuse)
    assert time.perf_counter() - t0 < 2


def refusal_figures(message):
    return re.search(r"about (\S+) right-hand sides \((\S+) per configuration", message).groups()


def test_a_field_over_the_command_lines_default_budget_is_refused_up_front_as_there():
    sc = plate.load_scene(scene_path("fig6"))
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"above the budget of 2e\+09: raise it with max_work=") as e:
        plate.field(sc, grid=100)   # (6.45e9 right-hand sides estimated; about 40 minutes on one core)
    assert time.perf_counter() - t0 < 30, "refused from five cycles, not after the field"
    if EXE:
        cli = subprocess.run([EXE, "field", scene_path("fig6"), "--grid", "100"], capture_output=True, text=True)
        assert cli.returncode == 2 and "raise it with --max-work" in cli.stderr
        assert refusal_figures(cli.stderr) == refusal_figures(str(e.value))


def test_ctrl_c_stops_proofs_and_a_campaign_and_the_campaign_resumes(tmp_path):
    # Both share their cases over threads of their own (the proofs' pool, the campaign's farm): every
    # thread polls the request, the first Interrupted stops the others and is raised once all joined.
    # Measured here: proofs 0.02-0.05 s, campaign 0.03-0.1 s after the signal.
    assert latency_of_ctrl_c(lambda: plate.proofs(thin=100000, thick=0, surfaces=0, threads=2)) < 0.5
    import json
    base = json.load(open(os.path.join(SOURCE, "campaigns", "heave_yaw_stick_slip.json")))
    base["scene"] = scene_path("heave_yaw")
    base["parameters"] = [{"name": "rz_amp", "pointer": "/plate/harmonics/1/amp", "from": 10, "to": 80, "count": 400}]
    base["compute"] = {"twist_at": [[0.02, 0, 0]], "field": base["compute"]["field"]}
    campaign = tmp_path / "c.json"
    campaign.write_text(json.dumps(base))
    out = tmp_path / "out"
    assert latency_of_ctrl_c(lambda: plate.sweep(campaign, out, threads=2)) < 0.5
    # No table after an interrupted run; the journal keeps the cases that finished, none failed by it.
    assert not (out / "table.csv").exists()
    journal = (out / "journal.jsonl").read_text().splitlines()[1:]
    assert all(json.loads(line)["row"]["status"] != "failed" for line in journal)
