"""The module's contract: scenes from files and dicts, errors with the command line's messages,
numpy results on their grid, and the GIL released while the library works."""
import json
import math
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")


def scene_path(name):
    return os.path.join(SOURCE, "scenes", name + ".json")


def test_a_scene_round_trips_through_a_dict_and_gives_the_same_twist():
    sc = plate.load_scene(scene_path("fig4"))
    d = sc.to_dict()
    assert d["part"]["mass"] == 0.0216 and len(d["plate"]["harmonics"]) == 4
    again = plate.scene_from_dict(d)
    q = (0.03, -0.02, 1.0)
    assert np.array_equal(plate.twist(sc, at=q).twist, plate.twist(again, at=q).twist)
    assert again.to_dict() == d


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
@pytest.mark.parametrize("edit, field", [
    (lambda d: d["part"].pop("mass"), "mass"),
    (lambda d: d["part"].__setitem__("friction", -0.3), "friction"),
    (lambda d: d["plate"].__setitem__("period", 0), "period"),
    (lambda d: d["plate"]["harmonics"][0].__setitem__("axis", "w"), "axis"),
])
def test_a_bad_scene_raises_InputError_with_the_command_lines_message(tmp_path, edit, field):
    d = plate.load_scene(scene_path("fig4")).to_dict()
    edit(d)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(plate.InputError) as err:
        plate.load_scene(str(path))
    message = str(err.value)
    assert str(path) in message and field in message
    cli = subprocess.run([EXE, "twist", str(path), "--at", "0", "0", "0"], capture_output=True, text=True)
    assert cli.returncode == 2
    assert cli.stderr.strip() == "plate twist: " + message          # the same words, word for word
    with pytest.raises(plate.InputError) as err2:                   # and from a dict, named as given
        plate.scene_from_dict(d, source="my dict")
    assert str(err2.value).startswith("my dict") and field in str(err2.value)
    assert isinstance(err.value, ValueError)


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
@pytest.mark.parametrize("scene, words", [
    ("fig1_point", "wobble 0 0"), ("fig1_point", "sink 0.02"), ("fig4", "fixed-point 0.02 -0.01"),
    ("fig1_point", "transport 1 2 3 4"), ("fig1_point", "sink 0.2 0"), ("fig4", "line-sink 0 0 0.5"),
    ("fig1_point", "orient 1"), ("fig1_point", "transport 0.01 0 0.5"), ("fig1_point", "line-sink 0 0"),
    ("fig1_point", "transport 0 0"), ("fig4", "orient"),
])
def test_a_target_the_command_line_refuses_python_refuses_with_the_same_message(tmp_path, scene, words):
    # One parser, in the library: target='KIND NUMBERS' and the keywords alike.
    part = plate.load_scene(scene_path(scene))
    with pytest.raises(ValueError) as err:
        plate.design(part, target=words, verify_starts=1)
    message = str(err.value)
    cli = subprocess.run([EXE, "design", scene_path(scene), "--target", *words.split(), "--out",
                          str(tmp_path / "x.json")], capture_output=True, text=True)
    assert cli.returncode == 2 and not (tmp_path / "x.json").exists()
    assert message and message in cli.stderr
    if words == "sink 0.2 0":   # (the keyword form is the same target)
        with pytest.raises(ValueError, match="outside the plate region"):
            plate.design(part, sink=(0.2, 0), verify_starts=1)


def test_bad_options_raise_ValueError_naming_the_option():
    sc = plate.load_scene(scene_path("fig4"))
    for call, name in [(lambda: plate.twist(sc, at=(0, 0)), "at"),
                       (lambda: plate.twist(sc, at=(0, 0, 0), tol=-1), "tol"),
                       (lambda: plate.twist(sc, at=(0, 0, 0), solver="magic"), "solver"),
                       (lambda: plate.field(sc, grid=0), "grid"),
                       (lambda: plate.field(sc, x=(0.1, -0.1)), "x"),
                       (lambda: plate.simulate(sc, start=(0, 0, 0), time=1, dynamics="rk4"), "dynamics"),
                       (lambda: plate.simulate(sc, start=(0, 0, 0), time=-1), "time")]:
        with pytest.raises(ValueError, match=name):
            call()


def test_point_part_fields_are_velocity_fields_on_a_plane():
    sc = plate.load_scene(scene_path("fig1_point"))
    assert sc.point_part
    f = plate.field(sc, grid=5)
    assert f.twist.shape == (5, 5, 1, 3) and f.theta.shape == (1,)
    assert np.all(f.twist[..., 2] == 0)                 # no rotation for a point part
    c = plate.twist(sc, at=tuple(f.q[1, 3, 0, :2]))
    np.testing.assert_allclose(f.twist[1, 3, 0], c.twist, atol=1e-5 * sc.v_ref)
    assert f.summary["grid"]["nx"] == 5


def plate_acceleration(d, t):
    """u(t) from the scene's harmonics: p'' and omega1' (world frame)."""
    w = 2 * math.pi / d["plate"]["period"]
    acc = {"x": 0.0, "y": 0.0, "z": 0.0, "rx": 0.0, "ry": 0.0, "rz": 0.0}
    for h in d["plate"]["harmonics"]:
        acc[h["axis"]] += h["amp"] * math.sin(h["n"] * w * t + h["phase"])
    return np.array([acc["x"], acc["y"], acc["z"]]), np.array([acc["rx"], acc["ry"], acc["rz"]])


def rigid_gauge(d, q, t):
    """How much of its friction a rigid part at rest at q needs at t (U-dynamics; held while <= 1).
    Riding the plate, its centre s = (s_x, s_y, -c_z) accelerates as a = p'' + omega1' x s and it turns
    at omega1' (33)-(34): in its frame S (R2 = R_z(theta)) friction supplies F = R2^T m a_xy and the
    torque tau = J R2^T omega1' about z; with every contact at height c_z the normal forces follow from
    the vertical force and the torques about x and y alone:
        sum N_i = m (g + a_z),  sum c_iy N_i = tau_x + c_z F_y,  -sum c_ix N_i = tau_y - c_z F_x.
    Contact i's friction f_i (|f_i| <= mu_i N_i) gives (f_i, c_ix f_iy - c_iy f_ix); the set of their
    sums has the support function h(e) = sum mu_i N_i |(e_x - e_z c_iy, e_y + e_z c_ix)|, and the
    gauge is max over directions e of e . (F, tau_z) / h(e): here on a grid over the sphere, zoomed in
    on its maximum eight times by ten (the last step ~3e-9 rad: the value to ~1e-16)."""
    part = d["part"]
    m, mu, c = part["mass"], np.array(part["friction"]), np.array(part["contacts"])
    J = np.array(part["inertia"])
    th = q[2]
    R2T = np.array([[math.cos(th), math.sin(th), 0], [-math.sin(th), math.cos(th), 0], [0, 0, 1]])
    pdd, wd = plate_acceleration(d, t)
    a = pdd + np.cross(wd, [q[0], q[1], -c[0, 2]])
    F = R2T @ np.array([m * a[0], m * a[1], 0.0])
    tau = J @ (R2T @ wd)
    cz = c[0, 2]
    N = np.linalg.solve(np.array([[1.0, 1.0, 1.0], c[:, 1], -c[:, 0]]),
                        [m * (d["gravity"] + a[2]), tau[0] + cz * F[1], tau[1] - cz * F[0]])
    L = 0.03   # (the torque's direction scaled by a length of the part's size: a round sphere to search)
    w = np.array([F[0], F[1], tau[2] / L])

    def ratio(phi, z):
        r = np.sqrt(np.maximum(1 - z * z, 0.0))
        ex, ey, ez = r * np.cos(phi), r * np.sin(phi), z / L
        h = sum(mu[i] * N[i] * np.hypot(ex - ez * c[i, 1], ey + ez * c[i, 0]) for i in range(3))
        return (ex * w[0] + ey * w[1] + ez * tau[2]) / h

    phi, z = np.meshgrid(np.linspace(0, 2 * math.pi, 181), np.linspace(-1, 1, 91))
    step = np.array([2 * math.pi / 180, 2 / 90])
    for _ in range(8):
        g = ratio(phi, z)
        k = np.unravel_index(np.argmax(g), g.shape)
        best = np.array([phi[k], z[k]])
        phi, z = np.meshgrid(best[0] + np.linspace(-2, 2, 41) * step[0], np.clip(best[1] + np.linspace(-2, 2, 41) * step[1], -1, 1))
        step = step / 10
    return float(np.max(g))


def rigid_breakaway(d, q):
    """The first t > 0 where rigid_gauge reaches 1 (searched in steps of 0.1 ms), by bisection to 1e-16 s."""
    lo, hi = 0.0, 0.0
    while rigid_gauge(d, q, hi) < 1:
        hi += 1e-4
    lo = hi - 1e-4
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rigid_gauge(d, q, mid) < 1 else (lo, mid)
    return hi


def test_a_trajectory_has_a_mode_per_sample_and_fig1_sticks_then_breaks_away():
    sc = plate.load_scene(scene_path("fig1"))
    tr = plate.simulate(sc, start=(-0.04, 0.03, 1.2), time=0.02, sample=0.001, dynamics="u")
    assert not tr.stop
    assert tr.q.shape == (len(tr.t), 3) and len(tr.mode) == len(tr.t)
    # fig1 released at rest rides the plate, breaks away where the wrench it needs leaves the friction
    # set (rigid_breakaway above: 7.7306e-4 s), then slides.
    assert [e[1:] for e in tr.events] == [("slide", "stuck"), ("stuck", "slide")]
    assert tr.events[0][0] == 0
    # (The engine locates it to rounding: measured 3e-15 relative.)
    assert tr.events[1][0] == pytest.approx(rigid_breakaway(sc.to_dict(), (-0.04, 0.03, 1.2)), rel=1e-14, abs=0)
    assert tr.mode[0] == "stuck" and set(tr.mode[1:]) == {"slide"}
    assert np.all(tr.normal_forces > 0)


def test_the_point_part_breaks_away_when_the_needed_force_reaches_mu_N():
    # Held while |F| <= mu N with F = m (p'' + alpha x s)_xy, N = m (g + (p'' + alpha x s)_z) (33), from
    # fig1_point's harmonics alone; its root, bisected here, is the break-away time.
    d = plate.load_scene(scene_path("fig1_point")).to_dict()
    w, mu, g = 2 * math.pi / d["plate"]["period"], d["part"]["friction"], d["gravity"]
    s = np.array([-0.04, 0.03, 0.0])

    def margin(t):
        acc = {"x": 0.0, "y": 0.0, "z": 0.0, "rx": 0.0, "ry": 0.0, "rz": 0.0}
        for h in d["plate"]["harmonics"]:
            acc[h["axis"]] += h["amp"] * math.sin(h["n"] * w * t + h["phase"])
        a = np.array([acc["x"], acc["y"], acc["z"]]) + np.cross([acc["rx"], acc["ry"], acc["rz"]], s)
        return mu * (g + a[2]) - math.hypot(a[0], a[1])

    assert margin(0) > 0
    lo, hi = 0.0, 0.0
    while margin(hi) > 0:
        hi += 1e-5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if margin(mid) > 0 else (lo, mid)
    tr = plate.simulate(plate.scene_from_dict(d), start=(-0.04, 0.03), time=0.01, sample=0.001, dynamics="u")
    assert tr.events[0][1:] == ("slide", "stuck") and tr.events[1][1:] == ("stuck", "slide")
    assert tr.events[1][0] == pytest.approx(hi, rel=1e-9)


def control_run():
    # A long loop (6000 periods, about 0.5 s) on a library whose model is built in a millisecond.
    lib = {"motions": [{"name": "e", "scene": os.path.join(SOURCE, "scenes", "control", "fig1_point", "e_slow.json")},
                       {"name": "still", "still": True}]}
    plate.control(plate.load_scene(scene_path("fig1_point")), (0.02, -0.01), library=lib, time=300.0)


@pytest.mark.parametrize("call", [lambda: plate.field(plate.load_scene(scene_path("fig4")), grid=9, threads=1), control_run],
                         ids=["field", "control"])
def test_the_gil_is_released_while_the_library_works(call):
    # The main thread counts while a worker thread computes a field (or runs a closed loop). Were the GIL
    # held through the call, the main thread could count for at most about one switch interval of it;
    # released, it counts all along (even sharing the cores with other work: the bound asks for 4
    # intervals' worth while the worker calls for at least 60 intervals, one call after another).
    interval = sys.getswitchinterval()
    state = {"done": False, "count": 0}

    def count_until(stop):
        while not state["done"] and time.perf_counter() < stop:
            state["count"] += 1

    t0 = time.perf_counter()
    count_until(t0 + 0.05)
    rate = state["count"] / (time.perf_counter() - t0)     # turns per second of the loop below
    state["count"] = 0

    def work():
        state["start"] = (time.perf_counter(), state["count"])
        while time.perf_counter() - state["start"][0] < 60 * interval:   # however fast the machine
            call()
        state["end"] = (time.perf_counter(), state["count"])
        state["done"] = True

    t = threading.Thread(target=work)
    t.start()
    count_until(math.inf)
    t.join()
    seconds = state["end"][0] - state["start"][0]
    counted = state["end"][1] - state["start"][1]
    assert seconds > 20 * interval, "the calls must outlast many switch intervals for this test to mean anything"
    assert counted > 4 * interval * rate, (counted, interval * rate)


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
def test_robustness_is_the_command_lines_and_takes_a_spec_as_a_file_or_a_dict(tmp_path):
    scene, spec = scene_path("designs/fig4_fixed_point"), os.path.join(SOURCE, "scenes", "uncertainty", "ppod.json")
    out = tmp_path / "rob.json"
    cli = subprocess.run([EXE, "robustness", scene, "--uncertainty", spec, "--draws", "4", "--starts", "1",
                          "--full-draws", "0", "--out", str(out)], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    with open(spec) as f:
        spec_dict = json.load(f)
    for given in (spec, spec_dict):
        r = plate.robustness(plate.load_scene(scene), given, draws=4, starts=1, full_draws=0)
        got, want = r.summary, json.loads(out.read_text())
        for d in (got, want):
            d.pop("seconds")
            d["sensitivity"].pop("seconds")
            d.pop("uncertainty")          # (the source: the path, or "<dict>")
        assert got == want
        assert sorted(r.outcomes) == sorted(want["outcomes"])
        assert r.fixed_points.shape == (4, 3) and r.deviations.shape[0] == 4
        assert r.deviations.shape[1] == len(plate.uncertain_parameters(plate.load_scene(scene), given))
    bad = dict(spec_dict, friction={"spread": 0.9})
    with pytest.raises(plate.InputError) as err:
        plate.robustness(plate.load_scene(scene), bad, draws=1)
    assert "friction.spread" in str(err.value)


def test_one_vocabulary_a_twist_is_twist_and_the_old_spellings_warn():
    """twist(twist=) is the initial twist (start= is a configuration elsewhere); design's limits=,
    evaluations= and harmonics= are the command line's names. The old spellings do the same with a
    DeprecationWarning; both at once is a ValueError."""
    sc = plate.load_scene(scene_path("fig4"))
    q = (0.02, 0.01, 0.5)
    rest, moving = plate.twist(sc, at=q), plate.twist(sc, at=q, twist=(0.05, 0, 0))
    assert moving.periods != rest.periods  # the initial twist is used (the cycle, not its end, depends on it)
    with pytest.warns(DeprecationWarning, match="start= is deprecated: use twist="):
        old = plate.twist(sc, at=q, start=(0.05, 0, 0))
    assert old.periods == moving.periods and np.array_equal(old.twist, moving.twist)
    with pytest.raises(ValueError, match="twist and start are the same argument"):
        plate.twist(sc, at=q, twist=(0.05, 0, 0), start=(0.05, 0, 0))
    # design: the old names reach the same option, judged by the same check (no search runs).
    part = plate.load_scene(scene_path("fig1_point"))
    with pytest.raises(ValueError) as new_err:
        plate.design(part, sink=(0.02, -0.01), limits=(-1, 150))
    with pytest.warns(DeprecationWarning, match="lin_limit= is deprecated: use limits="):
        with pytest.raises(ValueError) as old_err:
            plate.design(part, sink=(0.02, -0.01), lin_limit=-1)
    assert str(old_err.value) == str(new_err.value)
    for now, old, bad in (("evaluations", "local_evaluations", 0), ("harmonics", "max_harmonic", -1)):
        with pytest.raises(ValueError) as new_err:
            plate.design(part, sink=(0.02, -0.01), **{now: bad})
        with pytest.warns(DeprecationWarning, match=f"{old}= is deprecated: use {now}="):
            with pytest.raises(ValueError) as old_err:
                plate.design(part, sink=(0.02, -0.01), **{old: bad})
        assert str(old_err.value) == str(new_err.value)
        with pytest.raises(ValueError, match="same argument"):
            plate.design(part, sink=(0.02, -0.01), **{now: 5, old: 5})


def test_a_scene_reads_like_its_file_compares_by_content_pickles_and_copies():
    """Scene attributes against the file's own JSON (read here with the json module); equality by content;
    pickle and deepcopy give the same scene, to the bit of a computed twist; the constructor checks as a
    file is."""
    import copy
    import pickle
    path = scene_path("fig4")
    raw = json.load(open(path))
    a, b = plate.load_scene(path), plate.load_scene(path)
    assert a == b and not (a != b)
    assert a.mass == raw["part"]["mass"] and a.period == raw["plate"]["period"]
    assert a.contacts.tolist() == raw["part"]["contacts"]
    assert a.inertia.tolist() == raw["part"]["inertia"]  # (fig4's file gives the whole matrix)
    assert a.friction == {"kinetic": raw["part"]["friction"], "static": raw["part"]["friction"]}  # (one triple: both)
    assert a.harmonics == [{k: float(h[k]) if k in ("amp", "phase") else h[k] for k in ("axis", "n", "amp", "phase")}
                           for h in raw["plate"]["harmonics"]]
    q = (0.03, -0.02, 1.0)
    for c in (pickle.loads(pickle.dumps(a)), copy.deepcopy(a), copy.copy(a)):
        assert c == a and c.source == a.source
        assert np.array_equal(plate.twist(c, at=q).twist, plate.twist(a, at=q).twist)
    # A changed parameter is another scene; the name is part of the content, the source is not.
    d = a.to_dict()
    d["part"]["friction"] = 0.31
    assert plate.scene_from_dict(d) != a
    assert plate.scene_from_dict(a.to_dict(), source="elsewhere") == a
    # The constructor from the file's part and plate is the file's scene.
    made = plate.Scene(part=raw["part"], plate=raw["plate"], name=raw["name"], gravity=raw.get("gravity", 9.81))
    assert made == a
    with pytest.raises(plate.InputError, match=r"plate.Scene\(...\): part.mass"):
        plate.Scene(part=dict(raw["part"], mass=-1), plate=raw["plate"])
    s = plate.Scene(part={"mass": 0.02, "friction": {"static": 0.4, "kinetic": 0.3}},
                    plate={"period": 0.05, "harmonics": [{"axis": "x", "n": 1, "amp": 20, "phase": 0}]})
    assert s.point_part and s.inertia is None and s.contacts is None
    assert s.friction == {"kinetic": [0.3], "static": [0.4]}


def test_fixed_points_name_stuck_regions_and_rotating_orbits():
    """A disk where the point part sticks is a region with its extent (it was 4 points and 2 lines), and a
    symmetric part spun by heave and yaw turns at the field's omega on the axis (issue 54)."""
    s = plate.load_scene(scene_path("heave_yaw_point"))
    fp = plate.fixed_points(plate.field(s))
    assert not fp.points and not fp.lines and not fp.grid_too_coarse
    (r,) = fp.stuck_regions
    assert abs(r.lo[0] + r.hi[0]) < 1e-12 and r.grid_points == 25 and not r.touches_edge
    assert repr(r).startswith("<plate.StuckRegion x in [")
    spin = plate.load_scene(os.path.join(SOURCE, "tests", "data", "fixed_points", "spin_symmetric.json"))
    fs = plate.fixed_points(plate.field(spin))
    # The axis (settled: radius 0), then orbits about contacts held on the axis (neutral to first order).
    o = fs.rotating[0]
    assert abs(o.rate + 0.2197870) < 1e-5 and o.stability == "unstable" and o.radius == 0
    assert repr(o).startswith("<plate.RotatingAttractor unstable at (")
    assert fs.summary["rotating_attractors"][0]["rate"] == o.rate
    contacts = [(0.0, 0.04), (-0.034641016151, -0.02), (0.034641016151, -0.02)]
    for r in fs.rotating[1:]:
        assert r.stability == "centre" and abs(r.radius - 0.04) < 1e-6 and list(r.centre) == [0, 0]
        assert min(np.hypot(r.pivot[0] - cx, r.pivot[1] - cy) for cx, cy in contacts) < 1e-6


def test_every_result_says_what_it_is_when_printed():
    """No '<... object at 0x...>': each result's repr names its kind and its figures (seen failing before
    the reprs: Field, FixedPoints, FixedLine, Trajectory, Camera, Design and Robustness printed addresses)."""
    s = plate.load_scene(scene_path("fig1_point"))
    f = plate.field(s, grid=5)
    fp = plate.fixed_points(f)
    cam = plate.parse_camera('{"stroboscopic": {"phase": 0.25}, "noise": {"xy_mm": 0.1}, "frame": "plate"}', "cam")
    results = {
        "Scene": (s, "fig1_point"),
        "Cycle": (plate.twist(s, at=(0.01, 0.02)), "converged=True"),
        "Field": (f, "5x5 velocity field"),
        "FixedPoints": (fp, fp.sentence),
        "FixedLine": (fp.lines[0], "stable"),
        "Trajectory": (plate.simulate(s, start=(0.01, 0.02), time=0.2, dynamics="u"), "17 samples"),
        "Camera": (cam, "noise 0.1 mm"),
        "Track": (plate.observe(s, cam, start=(0.01, 0.02), time=0.2), "frames"),
        "Design": (plate.design(s, sink=(0.02, -0.01), starts=1, evaluations=30, verify_starts=2, hold=0), "verified"),
        "Robustness": (plate.robustness(plate.load_scene(scene_path("designs/point_sink")),
                                        scene_path("uncertainty/ppod"), draws=3), "3 draws"),
    }
    for kind, (obj, says) in results.items():
        r = repr(obj)
        assert r.startswith("<plate." + kind) and "object at 0x" not in r and says in r, (kind, r)


def test_a_scene_is_edited_by_attribute_and_checked_as_a_file_is():
    """s.friction = ... (and mass, period, harmonics, ...) gives the scene a file with that field would give:
    the same twist to the bit; a value a file may not hold is refused naming the field, the scene unchanged."""
    s = plate.load_scene(scene_path("fig4"))
    d = plate.scene_to_dict(s)
    d["part"]["friction"] = [0.3, 0.35, 0.3]
    d["part"]["mass"] = 0.03
    from_file = plate.scene_from_dict(d)
    s.friction = [0.3, 0.35, 0.3]
    s.mass = 0.03
    assert s == from_file and s.source.endswith("fig4.json")
    at = (0.01, 0.02, 0.3)
    assert np.array_equal(plate.twist(s, at=at).twist, plate.twist(from_file, at=at).twist)
    assert not np.array_equal(plate.twist(s, at=at).twist, plate.twist(plate.load_scene(scene_path("fig4")), at=at).twist)
    with pytest.raises(plate.InputError, match=r"part\.friction: expected friction coefficients >= 0, got -1"):
        s.friction = [0.3, -1, 0.3]
    assert s == from_file
    # Static and kinetic apart, then a plain list: as in a file, it means both (the static ones go too).
    s.friction = {"static": [0.5, 0.5, 0.5], "kinetic": [0.3, 0.35, 0.3]}
    assert s.friction == {"static": [0.5, 0.5, 0.5], "kinetic": [0.3, 0.35, 0.3]} and s != from_file
    s.friction = [0.3, 0.35, 0.3]
    assert s.friction == {"static": [0.3, 0.35, 0.3], "kinetic": [0.3, 0.35, 0.3]} and s == from_file
    first = s.harmonics[:1]
    s.harmonics = first
    assert s.harmonics == first and s.period == 0.05
    s.period = np.float64(0.04)
    assert s.period == 0.04
    # Every settable field, against the dict with the same change.
    for attr, key, value in (("gravity", None, 9.0), ("name", None, "edited"), ("contacts", "part", [[0.01, -0.03, -0.002],
                             [0.0, 0.031, -0.002], [-0.01, -0.03, -0.002]]),
                             ("inertia", "part", [[2e-6, 0, 0], [0, 3e-6, 0], [0, 0, 4e-6]])):
        d = plate.scene_to_dict(s)
        (d if key is None else d[key])[attr] = value
        setattr(s, attr, value)
        assert s == plate.scene_from_dict(d), attr
    point = plate.load_scene(scene_path("fig1_point"))
    with pytest.raises(plate.InputError, match=r"\(part\.contacts set\): part\.contacts: a point part has no contacts"):
        point.contacts = None
