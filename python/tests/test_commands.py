"""Every command of the command line from Python (issue 54, point 2), each checked against the program
itself: random scenes, campaigns, the averaged and auto dynamics; paths as str or os.PathLike; the
field's stops on its grid."""
import csv
import json
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")
needs_exe = pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")


def scene_path(name):
    return os.path.join(SOURCE, "scenes", name + ".json")


def cli_rows(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


@needs_exe
@pytest.mark.parametrize("flags", [[], ["--thin"], ["--point"]])
def test_random_scene_is_the_programs_for_the_same_seed(tmp_path, flags):
    out = tmp_path / "r.json"
    subprocess.run([EXE, "random-scene", "--seed", "7", *flags, "--out", str(out)], check=True)
    kw = {f[2:]: True for f in flags}
    assert plate.random_scene(7, **kw) == plate.load_scene(out)
    assert plate.random_scene(7, **kw) != plate.random_scene(8, **kw)
    with pytest.raises(ValueError, match="exclude each other"):
        plate.random_scene(7, thin=True, point=True)


@needs_exe
@pytest.mark.parametrize("dynamics, name, start, time, model_tol", [
    ("averaged", "fig1", [-0.04, 0.03, 1.2], 4.0, 1e-2),
    # (fig6 within 0.5: auto picks a thin part under the reduced U-dynamics, predicted 0.19)
    ("auto", "fig6", [0.02, 0.01, 0.3], 2.0, 0.5),
])
def test_simulate_averaged_and_auto_end_where_the_programs_runs_end(tmp_path, dynamics, name, start, time, model_tol):
    # The same library calls on the same inputs: the program's last row, to the bit (its numbers read
    # back to the doubles computed).
    scene = scene_path(name)
    out = tmp_path / "run.csv"
    cli = subprocess.run([EXE, "simulate", scene, "--dynamics", dynamics, "--model-tol", str(model_tol), "--start",
                          *map(str, start), "--time", str(time), "--out", str(out)], capture_output=True, text=True,
                         check=True)
    heading, rows = cli_rows(out)
    assert heading[:4] == ["t [s]", "s_x [m]", "s_y [m]", "theta [rad]"]
    tr = plate.simulate(plate.load_scene(scene), start, time, dynamics=dynamics, model_tol=model_tol)
    assert len(tr.t) == len(rows)
    assert tr.t[-1] == float(rows[-1][0])
    assert list(tr.q[-1]) == [float(c) for c in rows[-1][1:4]]
    if dynamics == "auto":
        assert tr.model is not None and f"picked {tr.model['picked']} " in cli.stderr
        assert tr.model["picked"] == "thin / reduced-u" and tr.dynamics == "auto: thin / reduced-u"
        assert 0 < tr.model["predicted_error"] <= model_tol
    else:
        assert tr.model is None and tr.dynamics == "averaged"
        # The full run from the same start and the averaged one end together, to the averaging's accuracy
        # (measured 5.4e-6 m after 40 mm of travel; within 3x that): a run that stayed put, or followed
        # another field, does not.
        full = plate.simulate(plate.load_scene(scene), start, time, dynamics="full")
        assert np.linalg.norm(full.q[-1][:2] - full.q[0][:2]) > 0.03
        assert np.linalg.norm(full.q[-1][:2] - tr.q[-1][:2]) < 1.6e-5


@needs_exe
def test_a_campaign_from_python_writes_the_programs_table(tmp_path):
    base = json.load(open(os.path.join(SOURCE, "campaigns", "heave_yaw_stick_slip.json")))
    base["scene"] = scene_path("heave_yaw")
    base["parameters"] = [{"name": "rz_amp", "pointer": "/plate/harmonics/1/amp", "values": [20, 60]}]
    base["compute"] = {"twist_at": [[0.02, 0, 0]]}
    campaign = tmp_path / "c.json"
    campaign.write_text(json.dumps(base))
    seen = []
    s = plate.sweep(campaign, tmp_path / "py", threads=1, progress=seen.append)
    assert s["cases"] == 2 and s["computed"] == 2 and s["failed"] == 0
    assert seen and seen[-1].done == seen[-1].total == 2
    subprocess.run([EXE, "sweep", str(campaign), "--out", str(tmp_path / "cli"), "--threads", "1"], check=True,
                   capture_output=True)
    assert (tmp_path / "py" / "table.csv").read_bytes() == (tmp_path / "cli" / "table.csv").read_bytes()
    # Run again: every case is in the journal.
    again = plate.sweep(str(campaign), str(tmp_path / "py"))
    assert again["resumed"] == 2 and again["computed"] == 0


@needs_exe
def test_proofs_from_python_are_the_programs_and_fail_on_a_wrong_model(tmp_path):
    out = tmp_path / "proofs.json"
    subprocess.run([EXE, "proofs", "--thin", "40", "--thick", "4", "--surfaces", "5", "--threads", "2", "--out", str(out)],
                   check=True)

    def no_times(x):
        if isinstance(x, dict):
            return {k: no_times(v) for k, v in x.items() if k != "seconds"}
        return [no_times(v) for v in x] if isinstance(x, list) else x
    j = plate.proofs(thin=40, thick=4, surfaces=5, threads=2)
    assert no_times(j) == no_times(json.load(open(out)))
    assert j["passed"] and j["failed"] == []
    # Pushing friction (mu -> -mu) breaks Theorem 1's contraction: the verdict names it.
    wrong = plate.proofs(thin=10, thick=0, surfaces=0, threads=2, wrong_model="pushing-friction")
    assert not wrong["passed"] and wrong["failed"] == ["thin"] and wrong["wrong_model"] == "pushing-friction"
    with pytest.raises(ValueError, match="wrong_model: expected none"):
        plate.proofs(thin=1, wrong_model="mu4")


@needs_exe
def test_the_report_from_python_is_the_programs(tmp_path):
    # The same sections, seed and quick mode: the same figures and data files to the byte, and the same
    # page but for the run's timings and its folder's name.
    page = plate.report(tmp_path / "py", quick=True, sections=["fig3", "orient"])
    assert page == str(tmp_path / "py" / "index.html")
    subprocess.run([EXE, "report", "--quick", "--sections", "fig3", "orient", "--out", str(tmp_path / "cli")], check=True,
                   capture_output=True)
    py = sorted(p.relative_to(tmp_path / "py") for p in (tmp_path / "py").rglob("*") if p.is_file())
    cli = sorted(p.relative_to(tmp_path / "cli") for p in (tmp_path / "cli").rglob("*") if p.is_file())
    assert py == cli and len(py) > 10
    for rel in py:
        if rel.name != "index.html":
            assert (tmp_path / "py" / rel).read_bytes() == (tmp_path / "cli" / rel).read_bytes(), rel

    def page_of(folder):
        # (the run's seconds: the total, the sections' timing rows, the orienter's last column)
        text = (folder / "index.html").read_text().replace(str(folder), "OUT")
        text = re.sub(r"total [0-9.e+-]+ s", "total T s", text)
        text = re.sub(r"<td>[0-9.e+-]+</td></tr>", "<td>T</td></tr>", text)
        return text
    assert page_of(tmp_path / "py") == page_of(tmp_path / "cli")
    assert "orient 2" in page_of(tmp_path / "py")
    with pytest.raises(ValueError, match="sections: 'nope' is not a section"):
        plate.report(tmp_path / "bad", sections=["nope"])
    with pytest.raises(ValueError, match="has no scenes/"):
        plate.report(tmp_path / "bad", source=tmp_path)
    assert not (tmp_path / "bad").exists()


def test_paths_may_be_pathlike():
    p = pathlib.Path(scene_path("fig4"))
    assert plate.load_scene(p) == plate.load_scene(str(p))
    with pytest.raises(TypeError):
        plate.load_scene(42)


def test_the_fields_stops_lie_on_its_grid():
    sc = plate.load_scene(scene_path("heave_yaw"))
    f = plate.field(sc, grid=3)
    assert f.stops.shape == f.converged.shape == (3, 3, 3)
    # A configuration has a twist exactly where its cycle converged; elsewhere the stop says why.
    assert ((f.stops == "none") == f.converged).all()
    assert np.isnan(f.twist[~f.converged]).all()


def test_results_pickle_and_deepcopy_to_the_bit(tmp_path):
    """A field, a trajectory through stick-slip, a cycle and a camera track come back from pickle (and deepcopy,
    and across processes as multiprocessing sends them) with every number, mode and stop the same."""
    import copy
    import pickle
    sc = plate.load_scene(scene_path("heave_yaw"))   # sticks over part of its field and of its runs
    f = plate.field(sc, grid=3)
    tr = plate.simulate(sc, [0.02, 0.01, 0.3], 2.0)
    assert "stuck" in tr.mode or any("pivot" in m for m in tr.mode)
    tk = plate.observe(sc, {"rate_hz": 100, "noise": {"xy_mm": 0.1, "theta_mrad": 5}, "seed": 3, "frame": "plate"}, [0.02, 0.01, 0.3], 1.0)
    for g in (pickle.loads(pickle.dumps(f)), copy.deepcopy(f)):
        assert repr(g) == repr(f) and g.summary == f.summary
        assert np.array_equal(g.twist, f.twist, equal_nan=True) and (g.stops == f.stops).all()
    for u in (pickle.loads(pickle.dumps(tr)), copy.deepcopy(tr)):
        assert np.array_equal(u.q, tr.q) and np.array_equal(u.qd, tr.qd) and np.array_equal(u.normal_forces, tr.normal_forces)
        assert u.mode == tr.mode and u.events == tr.events and u.held_time == tr.held_time
        assert repr(u.stop) == repr(tr.stop) and u.dynamics == tr.dynamics
    for k in (pickle.loads(pickle.dumps(tk)), copy.deepcopy(tk)):
        assert np.array_equal(k.t, tk.t) and np.array_equal(k.q, tk.q) and k.scene_id == tk.scene_id
        assert repr(k.stop) == repr(tk.stop)   # (the run's stop, an attribute observe gave it)
        assert plate.check_track_scene(k, sc) is None
    cy = plate.twist(sc, at=[0.04, -0.02, 1.0])   # a cycle that pivots on contact 1, the others part held
    assert cy.stick_fraction[0] == 1 and 0 < cy.stick_fraction[1] < 1
    for c in (pickle.loads(pickle.dumps(cy)), copy.deepcopy(cy)):
        assert c.summary == cy.summary and np.array_equal(c.twist, cy.twist) and c.report() == cy.report()
        assert (c.monodromy is None) == (cy.monodromy is None) and c.mode_sequence == cy.mode_sequence
    for c in (pickle.loads(pickle.dumps(tk.camera)), copy.deepcopy(tk.camera)):
        assert c.to_json() == tk.camera.to_json() and repr(c) == repr(tk.camera)
    # A pickled field that does not fill its grid is refused, not half read.
    state = f.__getstate__()
    with pytest.raises(ValueError, match="do not fill its grid"):
        plate.Field.__new__(plate.Field).__setstate__((state[0], state[1], state[2], state[3][:-1], state[4]))
