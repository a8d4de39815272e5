"""Every result pickles and deep-copies to the bit (issue 54): fixed points with their lines, stuck regions and
rotating attractors, a design, a robustness study, an identification with its profiles, a closed-loop run.
Each comes back with every property equal -- numbers bit for bit, NaN where NaN, nested results property by
property -- and a state cut short, run on, or of another kind is refused rather than half read.
(Field, Trajectory, Cycle, Track and Camera: test_commands.py.)"""
import copy
import math
import os
import pickle
import struct

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def scene(name):
    return plate.load_scene(os.path.join(SOURCE, "scenes", name + ".json"))


def properties(x):
    return sorted(n for n in dir(type(x)) if not n.startswith("_") and isinstance(getattr(type(x), n), property))


def bits(v):
    return struct.pack("<d", v)


def assert_same(a, b, where):
    """a and b equal to the bit, recursing into containers and into plate's own classes by their properties."""
    assert type(a) is type(b), (where, type(a), type(b))
    if isinstance(a, np.ndarray):
        assert a.shape == b.shape and a.dtype == b.dtype, where
        if a.dtype.kind in "fc":
            assert a.tobytes() == b.tobytes(), where
        else:
            assert np.array_equal(a, b), where
    elif isinstance(a, float):
        assert bits(a) == bits(b), (where, a, b)
    elif isinstance(a, complex):
        assert bits(a.real) == bits(b.real) and bits(a.imag) == bits(b.imag), (where, a, b)
    elif isinstance(a, dict):
        assert list(a) == list(b), where
        for k in a:
            assert_same(a[k], b[k], where + "[" + repr(k) + "]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (u, v) in enumerate(zip(a, b)):
            assert_same(u, v, where + "[" + str(i) + "]")
    elif type(a).__module__.startswith("plate") and not isinstance(a, plate.Scene):
        assert repr(a) == repr(b), where
        names = properties(a)
        assert names, where
        for n in names:
            assert_same(getattr(a, n), getattr(b, n), where + "." + n)
    else:
        assert a == b, (where, a, b)


def round_trips(x, kind):
    """pickle (every protocol from 2) and deepcopy give x back; returns the pickled bytes of protocol 5."""
    for y in [pickle.loads(pickle.dumps(x, protocol=p)) for p in range(2, pickle.HIGHEST_PROTOCOL + 1)] + [copy.deepcopy(x)]:
        assert_same(x, y, kind)
    return x.__getstate__()


def test_fixed_points_and_their_parts_come_back_to_the_bit():
    lines = plate.fixed_points(plate.field(scene("fig1_point"), grid=5))   # stable lines
    stuck = plate.fixed_points(plate.field(scene("heave_yaw_point")))     # a stuck region
    spin = plate.fixed_points(plate.field(plate.load_scene(os.path.join(SOURCE, "tests", "data", "fixed_points",
                                                                        "spin_symmetric.json"))))   # a rotating orbit
    assert lines.lines and stuck.stuck_regions and spin.rotating
    for fp in (lines, stuck, spin):
        round_trips(fp, "FixedPoints")
    for part in (lines.lines[0], stuck.stuck_regions[0], spin.rotating[0]):
        round_trips(part, type(part).__name__)
    complete = plate.fixed_points(plate.field(scene("fig4"), grid=5))
    assert complete.points
    round_trips(complete, "FixedPoints")
    round_trips(complete.points[0], "FixedPoint")
    # The counters: a grid too coarse (fig1 on 4 points: a finer grid suggested), a search cut short by its
    # budget (cells left unsearched) -- each non-zero before the round trip.
    coarse = plate.fixed_points(plate.field(scene("fig1"), grid=4))
    assert coarse.grid_too_coarse and coarse.summary["suggested_grid"] > 0
    round_trips(coarse, "FixedPoints")
    cut = plate.fixed_points(plate.field(scene("fig4"), grid=5), max_rhs=1000)
    assert cut.summary["unsearched_cells"] > 0
    round_trips(cut, "FixedPoints")


def test_a_design_a_robustness_study_and_an_identification_come_back_to_the_bit(tmp_path):
    d = plate.design(scene("fig1_point"), sink=(0.02, -0.01), starts=1, evaluations=30, verify_starts=2, hold=1.0)
    assert d.verified and d.summary and d.held[0] > 0
    round_trips(d, "Design")
    # A rigid part's sink (pulls per orientation) and a transport (its mean and spread): members the point
    # sink leaves at their defaults.
    rigid = plate.design(scene("fig4"), sink=(0.02, -0.01), starts=1, evaluations=20, verify_starts=2, hold=0)
    assert rigid.pulls
    round_trips(rigid, "Design")
    carry = plate.design(scene("fig1_point"), transport=(0.01, 0.0), starts=1, evaluations=20, verify_starts=2)
    assert carry.transport_spread > 0 and carry.transport_mean[0] != 0
    round_trips(carry, "Design")
    r = plate.robustness(scene("designs/point_sink"), os.path.join(SOURCE, "scenes", "uncertainty", "ppod.json"), draws=3)
    assert len(r.outcome) == 3
    round_trips(r, "Robustness")
    # Identification, profiled: a point part's mu_k from one stroboscopic track (as test_identify.py).
    d = plate.scene_to_dict(scene("fig1_point"))
    d["part"]["friction"] = 0.27
    truth = plate.scene_from_dict(d)
    d["part"]["friction"] = 0.30
    tk = plate.observe(truth, os.path.join(SOURCE, "scenes", "cameras", "stroboscopic.json"), start=(0.01, 0.02), time=3.0)
    est = plate.identify(plate.scene_from_dict(d), [tk], ["mu_k"], profile="all")
    assert est.profiles and est.summary["profiles"]
    round_trips(est, "Identification")


def test_a_closed_loop_run_comes_back_to_the_bit_with_its_nan_frames():
    lib = os.path.join(SOURCE, "scenes", "control", "fig1_point", "library.json")
    cam = {"stroboscopic": {"phase": 0}, "noise": {"xy_mm": 0.1}, "latency_s": 0.05, "seed": 3, "frame": "world"}
    run = plate.control(scene("fig1_point"), (0.02, -0.01), library=lib, time=1.0, start=(-0.04, 0.03), camera=cam)
    assert np.isnan(run.observed[0]).all()   # (no frame before the first: NaN must come back NaN)
    round_trips(run, "ControlRun")


def test_a_state_cut_short_run_on_or_of_another_kind_is_refused():
    fp = plate.fixed_points(plate.field(scene("fig1_point"), grid=5))
    state = fp.__getstate__()
    for bad, says in ((state[:-1], "ends early"), (state + b"\0", "beyond its last member"),
                      (plate.FixedLine.__getstate__(fp.lines[0]), "expected 'plate.FixedPoints")):
        with pytest.raises(ValueError, match=says):
            plate.FixedPoints.__new__(plate.FixedPoints).__setstate__(bad)
