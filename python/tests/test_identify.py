"""Identification from Python: a point part's kinetic friction recovered from one filmed track within its
interval, the command line's estimate to the bit, coarse steps asked by keyword, a static coefficient the
track cannot show reported as such, and tracks from another set-up refused with the file and the line."""
import json
import os
import subprocess

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")
CAMERA = os.path.join(SOURCE, "scenes", "cameras", "stroboscopic.json")   # one frame a period, 0.1 mm


def point_scene(mu_k, mu_s=None, phase=0.0):
    d = plate.scene_to_dict(plate.load_scene(os.path.join(SOURCE, "scenes", "fig1_point.json")))
    d["part"]["friction"] = mu_k if mu_s is None else {"static": mu_s, "kinetic": mu_k}
    d["plate"]["harmonics"][0]["phase"] = phase
    return plate.scene_from_dict(d)


def filmed(tmp_path, truth, name="track.csv", start=(0.01, 0.02), time=10.0):
    tk = plate.observe(truth, CAMERA, start=start, time=time)
    path = str(tmp_path / name)
    plate.write_track_csv(tk, path)
    return path


def test_a_point_parts_kinetic_friction_from_one_track(tmp_path):
    # fig1's point part slides all the time under fig1's plate: one 10 s track of 200 frames at 0.1 mm
    # places mu_k to sd ~0.0014 (the helper's 20 seeds: largest error 0.0042). The nominal guess is 0.03 off.
    path = filmed(tmp_path, point_scene(0.27))
    r = plate.identify(point_scene(0.30), [path], ["mu_k"])
    assert r.converged and r.names == ["mu_k"]
    lo, hi = r.intervals[0]
    assert abs(r.estimates[0] - 0.27) < 0.005 and lo < 0.27 < hi
    assert 0.7 < r.reduced_chi2 < 1.3   # chi2 / dof within ~3 sd (sqrt(2 / dof)) of 1
    assert r.explains_tracks and r.p_value > 1e-3 and r.summary["goodness_of_fit"]["p_value"] == r.p_value
    assert r.summary["parameters"][0]["estimate"] == r.estimates[0]
    # The interval checked at its ends: the chi-square rises by 3.84 (+-5 %) there on this sliding part.
    check = r.interval_check[0]
    assert check["verdict"] == "holds" and all(abs(d - 3.84) < 0.2 for d in check["dchi2_at_ends"])
    assert r.fitted.to_dict()["part"]["friction"] == r.estimates[0]
    # A wrong noise model fails the chi-square check above: the same track declaring 0.01 mm of noise
    # (ten times too little) gives reduced chi2 near 100.
    text = open(path).read()
    assert '"xy_mm":0.1' in text
    wrong = tmp_path / "wrong_noise.csv"
    wrong.write_text(text.replace('"xy_mm":0.1', '"xy_mm":0.01'))
    bad = plate.identify(point_scene(0.30), [str(wrong)], ["mu_k"])
    assert bad.reduced_chi2 > 50 and not bad.explains_tracks and bad.p_value < 1e-100


def test_a_static_coefficient_the_track_cannot_show(tmp_path):
    # fig1's plate started at its peak, 20 m/s^2 along x against mu_s g = 3.5 m/s^2: the part at rest breaks
    # away at once and slides throughout (as in tests/test_identify.cpp), so mu_s is not identifiable.
    path = filmed(tmp_path, point_scene(0.27, 0.36, np.pi / 2), start=(0.005, -0.02), time=3.0)
    r = plate.identify(point_scene(0.30, 0.40, np.pi / 2), [path], ["mu_k", "mu_s"])
    assert r.identifiable == [True, False]
    assert np.isnan(r.sd[1]) and np.all(np.isnan(r.intervals[1]))
    assert "not identifiable" in repr(r)


def test_profile_likelihood_of_a_static_coefficient_the_track_cannot_show(tmp_path):
    # The same track, profiled: mu_s's chi-square stays at its minimum from its kinetic base to the bound 1.5
    # (not identifiable, no interval reported), while mu_k's profile crosses 3.84 on both sides. A profile
    # that did not reach the bound (a cap on its steps of 1) is reported cut short.
    path = filmed(tmp_path, point_scene(0.27, 0.36, np.pi / 2), start=(0.005, -0.02), time=3.0)
    r = plate.identify(point_scene(0.30, 0.40, np.pi / 2), [path], ["mu_k", "mu_s"], profile="all")
    k, s = r.profiles
    assert k["ends"] == ("crossed", "crossed") and k["interval"][0] < 0.27 < k["interval"][1]
    assert s["ends"] == ("at bound", "at bound") and not s["identifiable"]
    assert s["points"].shape[1] == 2 and np.all(np.abs(s["points"][:, 1]) < 0.01)
    assert s["bounds"][1] == 1.5 and abs(s["bounds"][0] - r.estimates[0]) < 1e-9
    assert r.summary["parameters"][1]["interval95"] is None
    assert r.summary["profiles"][1]["interval95"]["hi_end"] == "at bound"
    short = plate.identify(point_scene(0.30, 0.40, np.pi / 2), [path], ["mu_k", "mu_s"], profile=["mu_s"], profile_steps=1)
    assert [p["name"] for p in short.profiles] == ["mu_s"] and "cut short" in short.profiles[0]["ends"]
    with pytest.raises(ValueError, match="com_x"):
        plate.identify(point_scene(0.30), [path], ["mu_k"], profile=["com_x"])


def test_tracks_from_another_set_up_are_refused(tmp_path):
    path = filmed(tmp_path, point_scene(0.27))
    other = plate.scene_to_dict(point_scene(0.27))
    other["plate"]["harmonics"][0]["amp"] *= 1.01
    with pytest.raises(plate.InputError, match=r"track\.csv:3: tracks from another scene"):
        plate.identify(plate.scene_from_dict(other), [path], ["mu_k"])
    with pytest.raises(ValueError, match="mu_k2"):
        plate.identify(point_scene(0.27), [path], ["mu_k2"])


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
def test_the_command_lines_estimate_to_the_bit(tmp_path):
    path = filmed(tmp_path, point_scene(0.27))
    scene_file = tmp_path / "nominal.json"
    scene_file.write_text(json.dumps(plate.scene_to_dict(point_scene(0.30))))
    out = tmp_path / "est.json"
    cli = subprocess.run([EXE, "identify", str(scene_file), "--tracks", path, "--params", "mu_k", "--out", str(out)],
                         capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    r = plate.identify(point_scene(0.30), [path], ["mu_k"])
    assert json.loads(out.read_text())["parameters"][0]["estimate"] == r.estimates[0]


def test_coarse_steps_are_asked_by_keyword(tmp_path):
    # The guess 0.03 off: the default takes its coarse steps (the JSON counts them), coarse=0 takes none,
    # and both reach the same estimate within its sd; out of range raises naming the option.
    path = filmed(tmp_path, point_scene(0.27))
    with_steps = plate.identify(point_scene(0.30), [path], ["mu_k"])
    without = plate.identify(point_scene(0.30), [path], ["mu_k"], coarse=0)
    assert with_steps.summary["solver"]["coarse_iterations"] >= 1
    assert without.summary["solver"]["coarse_iterations"] == 0
    assert abs(with_steps.estimates[0] - without.estimates[0]) < with_steps.sd[0]
    with pytest.raises(ValueError, match="coarse_iterations"):
        plate.identify(point_scene(0.30), [path], ["mu_k"], coarse=-1)


def test_the_cells_spread_is_asked_by_keyword(tmp_path):
    # A part sliding throughout has no cells: the default's spread over them is a small part of the sd (its
    # own, in .sd_cells and the JSON), cells=0 leaves none and the within-cell sd alone; out of range raises.
    # (The envelope, which also counts in sd_cells, is left out here: its own test follows.)
    path = filmed(tmp_path, point_scene(0.27))
    with_cells = plate.identify(point_scene(0.30), [path], ["mu_k"], envelope=False)
    without = plate.identify(point_scene(0.30), [path], ["mu_k"], cells=0, envelope=False)
    assert 0 < with_cells.sd_cells[0] < 0.1 * with_cells.sd[0]
    assert with_cells.summary["parameters"][0]["sd_cells"] == with_cells.sd_cells[0]
    assert with_cells.summary["options"]["cell_samples"] == 32
    assert without.sd_cells[0] == 0
    assert without.sd[0] ** 2 == pytest.approx(with_cells.sd[0] ** 2 - with_cells.sd_cells[0] ** 2, rel=1e-9)
    with pytest.raises(ValueError, match="cell_samples"):
        plate.identify(point_scene(0.30), [path], ["mu_k"], cells=-1)


def test_the_envelope_is_asked_by_keyword(tmp_path):
    # A part sliding throughout: its chi-square is smooth, so the secants over 3, 10 and 30 times the fine steps
    # are its tangent and widen nothing beyond 1 %; envelope=False: none, the options say so (an empty list of
    # factors) and the solver's report spends no time on it; the default's factors are the library's.
    path = filmed(tmp_path, point_scene(0.27))
    on = plate.identify(point_scene(0.30), [path], ["mu_k"], cells=0)
    off = plate.identify(point_scene(0.30), [path], ["mu_k"], cells=0, envelope=False)
    assert on.summary["options"]["envelope_factors"] == [3, 10, 30]
    assert on.summary["solver"]["envelope_seconds"] > 0
    assert off.summary["options"]["envelope_factors"] == []
    assert off.summary["solver"]["envelope_seconds"] == 0
    assert off.sd_cells[0] == 0 and off.sd_envelope[0] == 0
    assert off.sd[0] <= on.sd[0] < 1.01 * off.sd[0]
    assert on.sd_cells[0] == 0
    assert on.summary["parameters"][0]["sd_envelope"] == on.sd_envelope[0]
    assert on.sd[0] ** 2 - on.sd_envelope[0] ** 2 == pytest.approx(off.sd[0] ** 2, rel=1e-9)


def test_the_wide_steps_are_asked_by_keyword(tmp_path):
    # wide=0: none taken, the options and the solver's report say so; the default's count is the library's;
    # out of range raises.
    path = filmed(tmp_path, point_scene(0.27))
    without = plate.identify(point_scene(0.30), [path], ["mu_k"], wide=0)
    assert without.summary["options"]["wide_iterations"] == 0
    assert without.summary["solver"]["wide_iterations"] == 0
    assert without.summary["solver"]["wide_seconds"] == 0
    assert plate.identify(point_scene(0.30), [path], ["mu_k"]).summary["options"]["wide_iterations"] == 4
    with pytest.raises(ValueError, match="wide_iterations"):
        plate.identify(point_scene(0.30), [path], ["mu_k"], wide=1001)


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
def test_the_command_lines_cells_option(tmp_path):
    # --cells 0: no spread over the cells, the JSON says so; the default's equals the module's to the bit.
    path = filmed(tmp_path, point_scene(0.27))
    scene_file = tmp_path / "nominal.json"
    scene_file.write_text(json.dumps(plate.scene_to_dict(point_scene(0.30))))
    for cells in ("0", None):
        out = tmp_path / "est.json"
        args = [EXE, "identify", str(scene_file), "--tracks", path, "--params", "mu_k", "--out", str(out)]
        cli = subprocess.run(args + (["--cells", cells, "--no-envelope"] if cells else []), capture_output=True, text=True)
        assert cli.returncode == 0, cli.stderr
        est = json.loads(out.read_text())
        if cells:
            assert est["options"]["cell_samples"] == 0
            assert est["options"]["envelope_factors"] == []
            assert est["parameters"][0]["sd_cells"] == 0
        else:
            assert est["parameters"][0]["sd_cells"] == plate.identify(point_scene(0.30), [path], ["mu_k"]).sd_cells[0]
