"""The Python module asserts physics, with expected values worked out here, independently of the C++.

Closed forms (a block's deceleration, a circular translation's steady circle, a 1-D stick-slip cycle
integrated piecewise in closed form below), exact symmetries of the model (isotropic friction disks:
a rotated plate motion rotates the field; a shifted rotation centre shifts it), and the paper's
published claims (Fig. 4's fixed points). Tolerances follow from the method's settings: a cycle at
tol/rtol 1e-9/1e-10 is within ~6e-9 v_ref of the exact one (the C++ tests measure 60 rtol v_ref), one
at 1e-10/1e-11 within ~6e-10 v_ref: the symmetry identities are asked to 1e-8 v_ref.
"""
import math
import os

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
G = 9.81


def scene_path(name):
    return os.path.join(SOURCE, "scenes", name + ".json")


def point_scene(harmonics, mu=0.3, period=0.05, name="point"):
    return plate.scene_from_dict({
        "name": name, "gravity": G,
        "part": {"mass": 0.02, "friction": mu},
        "plate": {"period": period, "harmonics": harmonics}})


# --- closed forms ----------------------------------------------------------------------------------

def test_a_block_sliding_on_a_resting_plate_stops_at_v0_over_mu_g_after_v0_squared_over_2_mu_g():
    mu, v0 = 0.3, 0.1
    sc = point_scene([], mu=mu)
    tr = plate.simulate(sc, start=(0, 0), twist=(v0, 0), time=0.2, sample=0.01, dynamics="u")
    assert not tr.stop
    # Uniform deceleration mu g: exact for any integrator of order >= 1, up to rounding.
    assert [(e[1], e[2]) for e in tr.events] == [("slide", "stuck")]
    assert tr.events[0][0] == pytest.approx(v0 / (mu * G), rel=1e-10)
    assert tr.q[-1, 0] == pytest.approx(v0 ** 2 / (2 * mu * G), rel=1e-10)
    assert tr.mode[-1] == "stuck" and np.all(tr.qd[-1] == 0)


def test_circular_plate_translation_drives_a_circle_of_speed_mu_g_over_omega():
    # Steady state of e^{i psi}(mu g + i V w) = A w^2: the part's absolute velocity has constant speed
    # mu g / w and lags the plate's velocity by arccos(mu g / (A w^2)); its mean is zero.
    mu, T, Aw2 = 0.3, 0.05, 20.0
    w = 2 * math.pi / T
    sc = point_scene([{"axis": "x", "n": 1, "amp": Aw2, "phase": -math.pi / 2},
                      {"axis": "y", "n": 1, "amp": Aw2, "phase": math.pi}], mu=mu)
    tr = plate.simulate(sc, start=(0.01, -0.02), twist=(0.05, -0.02), time=60 * T, sample=T / 40,
                        dynamics="u", rtol=1e-11)
    assert not tr.stop
    last = tr.t >= 59 * T - 1e-12
    t = tr.t[last]
    # The plate's zero-mean velocity: the integral of A w^2 sin(wt + phi) is -A w cos(wt + phi).
    plate_v = np.stack([-Aw2 / w * np.cos(w * t - math.pi / 2), -Aw2 / w * np.cos(w * t + math.pi)], axis=1)
    v = tr.qd[last, :2] + plate_v
    speed, lag = mu * G / w, math.acos(mu * G / Aw2)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), speed, rtol=1e-6)
    dphi = np.remainder(np.arctan2(plate_v[:, 1], plate_v[:, 0]) - np.arctan2(v[:, 1], v[:, 0]) + math.pi,
                        2 * math.pi) - math.pi
    np.testing.assert_allclose(dphi, lag, rtol=1e-6)
    c = plate.twist(sc, at=(0, 0), tol=1e-9, rtol=1e-10)
    assert np.linalg.norm(c.twist[:2]) < 1e-6 * speed


class StickSlip1D:
    """A point part on a plate shaken along x with a(t) = sum A_j sin(k_j w t + phi_j), in closed form.

    Relative velocity v: v' = -a(t) - mu g sign(v) while sliding, so between events
    v(t) = v0 - (P(t) - P(t0)) - s mu g (t - t0) with P' = a, and its integral uses Q' = P. At v = 0 the
    part sticks while |a| <= mu g and breaks away opposite a when |a| reaches mu g. Events are roots
    of these closed forms, bracketed on a fine grid and bisected to rounding.
    """

    def __init__(self, terms, w, mug):
        self.terms, self.w, self.mug = terms, w, mug

    def a(self, t):
        return sum(A * math.sin(k * self.w * t + p) for A, k, p in self.terms)

    def P(self, t):
        return sum(-A / (k * self.w) * math.cos(k * self.w * t + p) for A, k, p in self.terms)

    def Q(self, t):
        return sum(-A / (k * self.w) ** 2 * math.sin(k * self.w * t + p) for A, k, p in self.terms)

    @staticmethod
    def root(f, lo, hi, n=400):
        """First sign change of f on [lo, hi] (grid of n), bisected; None if none."""
        x0, f0 = lo, f(lo)
        for i in range(1, n + 1):
            x1 = lo + (hi - lo) * i / n
            f1 = f(x1)
            if f0 == 0 or (f0 < 0) != (f1 < 0):
                a, b, fa = x0, x1, f0
                for _ in range(200):
                    m = 0.5 * (a + b)
                    fm = f(m)
                    if (fa < 0) == (fm < 0):
                        a, fa = m, fm
                    else:
                        b = m
                    if b - a <= 4e-16 * max(1.0, abs(b)):
                        break
                return 0.5 * (a + b)
            x0, f0 = x1, f1
        return None

    def run(self, T, periods):
        """Mean relative velocity and time stuck over the last of `periods` periods, from rest at t = 0."""
        t, v, end = 0.0, 0.0, periods * T
        mean_start, integral, stuck = end - T, 0.0, 0.0
        while t < end:
            if v == 0 and abs(self.a(t)) <= self.mug:        # stuck until |a| reaches mu g
                t1 = self.root(lambda x: abs(self.a(x)) - self.mug, t + 1e-13, min(t + T, end)) or end
                stuck += max(0.0, min(t1, end) - max(t, mean_start))
                t = t1
                s = -math.copysign(1.0, self.a(t)) if t < end else 0.0
            else:
                s = math.copysign(1.0, v) if v != 0 else -math.copysign(1.0, self.a(t))
            if t >= end:
                break
            t0, v0 = t, v

            def vel(x, t0=t0, v0=v0, s=s):
                return v0 - (self.P(x) - self.P(t0)) - s * self.mug * (x - t0)

            t1 = self.root(lambda x: s * vel(x), t0 + 1e-13, min(t0 + T, end))
            t1 = end if t1 is None else t1
            lo, hi = max(t0, mean_start), t1
            if hi > lo:   # the closed-form integral of v over [lo, hi]
                integral += ((v0 + self.P(t0) + s * self.mug * t0) * (hi - lo) - (self.Q(hi) - self.Q(lo))
                             - s * self.mug * (hi * hi - lo * lo) / 2)
            t, v = t1, (0.0 if t1 < end else vel(t1))
        return integral / T, stuck


# (amplitude of the first harmonic, friction, second harmonic): mu = 0.29 under 1.5 (0.3 g) runs away
# (relative speed growing by mu g T per period) if a point part's unused contacts hold garbage.
@pytest.mark.parametrize("A1, mu, A2", [(1.5 * 0.3 * G, 0.3, 0.0), (1.5 * 0.3 * G, 0.3, 2.0), (1.5 * 0.3 * G, 0.29, 2.0)])
def test_a_point_part_shaken_above_mu_g_follows_the_piecewise_closed_form_stick_slip_cycle(A1, mu, A2):
    T = 0.05
    mug, w = mu * G, 2 * math.pi / T
    harmonics = [{"axis": "x", "n": 1, "amp": A1, "phase": 0.0}]
    terms = [(A1, 1, 0.0)]
    if A2:
        harmonics.append({"axis": "x", "n": 2, "amp": A2, "phase": 0.7})
        terms.append((A2, 2, 0.7))
    sc = point_scene(harmonics, mu=mu)
    mean_v, stuck = StickSlip1D(terms, w, mug).run(T, 40)
    c = plate.twist(sc, at=(0, 0), tol=1e-9, rtol=1e-10)
    assert c.converged
    assert stuck > 0.05 * T                                  # it really sticks for part of the period
    assert abs(c.twist[0] - mean_v) < 2e-8 * sc.v_ref   # the cycle's error ~60 rtol v_ref = 6e-9 v_ref
    assert abs(c.twist[1]) < 1e-12
    assert c.stick_fraction[0] == pytest.approx(stuck / T, abs=1e-7)
    assert "stuck" in [m for _, m in c.mode_sequence] and "slide" in [m for _, m in c.mode_sequence]
    if A2:
        assert abs(mean_v) > 1e-3                            # the second harmonic drives it
    else:
        assert abs(mean_v) < 1e-12                           # a(t + T/2) = -a(t): no drift
    # The trajectory from rest reaches the same cycle: its relative speed stays within the plate's
    # velocity amplitude plus mu g T (it cannot gain more than that in a period).
    tr = plate.simulate(sc, start=(0, 0), time=20 * T, sample=T / 8, dynamics="u")
    assert np.max(np.abs(tr.qd[:, 0])) < sum(A / (k * w) for A, k, _ in terms) * 2 + mug * T


def test_a_point_part_shaken_below_mu_g_rides_the_plate_twist_exactly_zero():
    sc = point_scene([{"axis": "x", "n": 1, "amp": 0.9 * 0.3 * G, "phase": 0.0}])
    c = plate.twist(sc, at=(0.01, 0.02))
    assert c.converged and c.stuck_all_period
    assert np.all(c.twist[:2] == 0) and c.stick_fraction == [1.0]
    assert "exactly zero" in c.summary["stuck_note"]


def test_vertical_acceleration_beyond_g_loses_contact_when_the_plate_falls_at_g():
    # u_z = A sin(w t): the normal force m (g + u_z) reaches zero first at w t = pi + asin(g / A).
    T, A = 0.05, 2 * G
    sc = plate.load_scene(scene_path("fig4"))
    d = sc.to_dict()
    d["plate"]["harmonics"] = [{"axis": "z", "n": 1, "amp": A, "phase": 0.0}]
    tr = plate.simulate(plate.scene_from_dict(d), start=(0, 0, 0), time=T, dynamics="u")
    assert tr.stop.reason == "contact_lost" and 1 <= tr.stop.contact <= 3
    assert tr.stop.t == pytest.approx((math.pi + math.asin(G / A)) / (2 * math.pi / T), abs=1e-6 * T)
    assert tr.t[-1] == pytest.approx(tr.stop.t)             # the trajectory ends there


# --- exact symmetries ------------------------------------------------------------------------------

def rotate_motion(d, a):
    """The plate motion rotated by a about z: (x, y) and (rx, ry) harmonics turn, z and rz stay."""
    out = []
    for h in d["plate"]["harmonics"]:
        pair = {"x": ("x", "y", 1), "y": ("x", "y", 2), "rx": ("rx", "ry", 1), "ry": ("rx", "ry", 2)}.get(h["axis"])
        if pair is None:
            out.append(dict(h))
            continue
        ex = (math.cos(a), math.sin(a)) if pair[2] == 1 else (-math.sin(a), math.cos(a))
        out.append({**h, "axis": pair[0], "amp": h["amp"] * ex[0]})
        out.append({**h, "axis": pair[1], "amp": h["amp"] * ex[1]})
    r = dict(d)
    r["plate"] = {**d["plate"], "harmonics": out}
    return r


def shift_centre(d, D):
    """Adds -alpha x D to the linear acceleration, harmonic by harmonic (alpha: angular acceleration)."""
    out = [dict(h) for h in d["plate"]["harmonics"]]
    for h in d["plate"]["harmonics"]:
        if h["axis"] not in ("rx", "ry", "rz"):
            continue
        alpha = np.zeros(3)
        alpha[("rx", "ry", "rz").index(h["axis"])] = h["amp"]
        for axis, c in zip(("x", "y", "z"), -np.cross(alpha, D)):
            if c != 0:
                out.append({**h, "axis": axis, "amp": float(c)})
    r = dict(d)
    r["plate"] = {**d["plate"], "harmonics": out}
    return r


def test_rotating_the_plate_motion_about_z_rotates_the_twist_field():
    # Friction disks are isotropic: a pyramid would break this (issue 19's pitfall).
    d = plate.load_scene(scene_path("fig4")).to_dict()
    a = 0.7
    sc, rot = plate.scene_from_dict(d), plate.scene_from_dict(rotate_motion(d, a))
    R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    for q in [(0.03, -0.02, 1.0), (-0.01, 0.02, 2.5)]:
        xi = plate.twist(sc, at=q, tol=1e-9, rtol=1e-10).twist
        s = R @ np.array(q[:2])
        xi_rot = plate.twist(rot, at=(s[0], s[1], q[2] + a), tol=1e-9, rtol=1e-10).twist
        np.testing.assert_allclose(xi_rot[:2], R @ xi[:2], atol=1e-8 * sc.v_ref)
        assert abs(xi_rot[2] - xi[2]) < 1e-8 * sc.v_ref / sc.rho
        assert np.linalg.norm(xi[:2] - xi_rot[:2]) > 1e-3 * sc.v_ref   # (the check is not vacuous)


@pytest.mark.parametrize("name", ["fig4", "heave_yaw"])   # (heave_yaw has rz: the shift's x, y parts too)
def test_adding_minus_alpha_cross_D_to_the_linear_acceleration_shifts_the_field_by_D(name):
    d = plate.load_scene(scene_path(name)).to_dict()
    D = np.array([0.02, -0.01, 0.0])
    sc, shifted = plate.scene_from_dict(d), plate.scene_from_dict(shift_centre(d, D))
    for q in [(0.03, -0.02, 1.0), (0.0, 0.0, 0.3)]:
        xi = plate.twist(sc, at=q, tol=1e-9, rtol=1e-10).twist
        moved = plate.twist(shifted, at=(q[0] + D[0], q[1] + D[1], q[2]), tol=1e-9, rtol=1e-10).twist
        np.testing.assert_allclose(moved[:2], xi[:2], atol=1e-8 * sc.v_ref)
        assert abs(moved[2] - xi[2]) < 1e-8 * sc.v_ref / sc.rho
        unmoved = plate.twist(sc, at=(q[0] + D[0], q[1] + D[1], q[2]), tol=1e-9, rtol=1e-10).twist
        assert np.linalg.norm(unmoved - xi) > 1e-3 * sc.v_ref      # the field really varies over D


# --- the paper's claims ----------------------------------------------------------------------------

def test_fig4_field_has_stable_fixed_points_at_the_centre_at_theta_0_and_pi():
    sc = plate.load_scene(scene_path("fig4"))
    f = plate.field(sc, grid=7)
    assert f.twist.shape == (7, 7, 7, 3) and f.converged.all()
    np.testing.assert_allclose(f.x, np.linspace(-0.05, 0.05, 7))
    np.testing.assert_allclose(f.theta, 2 * math.pi * np.arange(7) / 7)
    # One configuration of the field equals a single cycle there (warm starts change nothing beyond tol).
    one = plate.twist(sc, at=tuple(f.q[2, 5, 3])).twist
    np.testing.assert_allclose(f.twist[2, 5, 3], one, atol=1e-5 * sc.v_ref)
    fp = plate.fixed_points(f)
    stable = [p.q for p in fp.points if p.stability == "stable"]
    assert len(stable) == 2
    for target in (0.0, math.pi):
        best = min(stable, key=lambda q: abs(math.remainder(q[2] - target, 2 * math.pi)))
        assert np.hypot(best[0], best[1]) < 1e-3                     # at the plate's centre
        assert abs(math.remainder(best[2] - target, 2 * math.pi)) < 0.05
    for p in fp.points:
        if p.stability == "stable":
            assert np.all(p.eigenvalues.real < 0)


def test_a_designed_sink_gathers_parts_released_anywhere_on_the_plate():
    # Checked here with the module's own full dynamics from starts of our choosing (not the design's).
    part = plate.load_scene(scene_path("fig1_point"))
    d = plate.design(part, sink=(0.02, -0.01), limits=(15, 100), starts=8, evaluations=200)
    assert d.verified, d.failure
    sc = d.scene
    # The limits bound each axis' summed signal: its peak, sampled here at 10^5 points (never above the
    # true peak; within 5e-9 of the amplitudes' sum below it), within them, and the design's `peaks` and
    # plate.axis_peaks the same.
    plate_motion = sc.to_dict()["plate"]
    t = np.linspace(0, plate_motion["period"], 100000, endpoint=False)
    axes = ("x", "y", "z", "rx", "ry", "rz")
    for a, axis in enumerate(axes):
        u = sum(h["amp"] * np.sin(h["n"] * 2 * np.pi * t / plate_motion["period"] + h["phase"])
                for h in plate_motion["harmonics"] if h["axis"] == axis)
        peak = float(np.max(np.abs(u))) if np.ndim(u) else 0.0
        limit = 15 if a < 3 else 100
        assert peak <= limit * (1 + 1e-9)
        assert d.peaks[a] == pytest.approx(peak, abs=1e-6 * limit)
        assert plate.axis_peaks(sc)[a] == d.peaks[a]
    # e^-6 (7 cm to 0.2 mm) at the centre's rate would be 6 / rate, 8 s; the field weakens away from
    # its sink (far starts take about twice that).
    T_end = 12 / d.rate
    for start in [(-0.045, 0.045), (0.045, 0.045), (-0.045, -0.045), (0.0, 0.04)]:
        tr = plate.simulate(sc, start=start, time=T_end, sample=T_end, dynamics="full")
        assert not tr.stop
        assert np.hypot(tr.q[-1, 0] - 0.02, tr.q[-1, 1] + 0.01) < 0.005
    assert np.hypot(*(d.fixed_point[:2] - np.array([0.02, -0.01]))) < 0.002
    # The hold: coning within 5 mm / (2 |D| 120 s), and released at the target the part stays.
    seconds, end, held = d.held
    assert seconds == 120 and held <= 0.005
    assert abs(d.coning) <= 0.005 / (2 * math.hypot(0.02, -0.01) * 120) * (1 + 1e-6)
    assert d.coning == pytest.approx(plate.coning_rate(sc), rel=1e-12)
    tr = plate.simulate(sc, start=(0.02, -0.01), time=120, sample=120, dynamics="full")
    assert not tr.stop
    assert np.hypot(tr.q[-1, 0] - 0.02, tr.q[-1, 1] + 0.01) < 0.005
    assert np.hypot(*(tr.q[-1, :2] - end[:2])) < 1e-4     # the design's own hold, at rtol 1e-7


def test_a_sink_designed_under_corner_limits_keeps_the_plate_corners_within_them():
    # The plate's corners at +-(0.05, 0.05) m (the flight check's square), sampled here at 2 10^4 points
    # from the scene's harmonics: displacement p + phi x r and velocity p' + omega x r, to first order in
    # the rotation (the sampling is never above the true peak, and within 1e-6 of it for n <= 3).
    part = plate.load_scene(scene_path("fig1_point"))
    d = plate.design(part, sink=(0.02, -0.01), corner_limits=(0.0005, 0.07), starts=4, evaluations=400)
    assert d.verified, d.failure
    assert tuple(d.corner_half_size) == (0.05, 0.05)
    m = d.scene.to_dict()["plate"]
    T = m["period"]
    t = np.linspace(0, T, 20000, endpoint=False)
    disp = {a: np.zeros_like(t) for a in ("x", "y", "z", "rx", "ry", "rz")}
    vel = {a: np.zeros_like(t) for a in disp}
    for h in m["harmonics"]:
        k = h["n"] * 2 * np.pi / T
        disp[h["axis"]] += -h["amp"] / k**2 * np.sin(k * t + h["phase"])
        vel[h["axis"]] += -h["amp"] / k * np.cos(k * t + h["phase"])
    peaks = []
    for s in (disp, vel):
        worst = 0.0
        for x in (-0.05, 0.05):
            for y in (-0.05, 0.05):
                p = np.stack([s["x"], s["y"], s["z"]]) + np.cross(np.stack([s["rx"], s["ry"], s["rz"]]).T, [x, y, 0]).T
                worst = max(worst, float(np.max(np.linalg.norm(p, axis=0))))
        peaks.append(worst)
    assert peaks[0] <= 0.0005 * (1 + 1e-9) and peaks[1] <= 0.07 * (1 + 1e-9)
    assert d.corner_peaks == pytest.approx(peaks, rel=1e-6)
    assert plate.corner_peaks(d.scene, (0.05, 0.05)) == d.corner_peaks
    # Unlimited, the same sink moves its corners by 1.1 mm at 0.14 m/s: the limits bound the design.
    free = plate.design(part, sink=(0.02, -0.01), starts=4, evaluations=400)
    assert free.corner_peaks[0] > 0.001 and free.corner_peaks[1] > 0.1
    with pytest.raises(ValueError, match="corner_limits"):
        plate.design(part, sink=(0.02, -0.01), corner_limits=(-1, 0))


def test_coning_turns_the_part_at_the_closed_form_rate():
    # fig4: rx, ry 100 rad/s^2 a quarter period apart turn the plate about z at -1e4 / (2 (40 pi)^3)
    # rad/s; the part, at the field's stable fixed point (0, 0, 0), turns with it in the full dynamics.
    sc = plate.load_scene(scene_path("fig4"))
    expected = -1e4 / (2 * (40 * math.pi) ** 3)
    assert plate.coning_rate(sc) == pytest.approx(expected, rel=1e-12)
    tr = plate.simulate(sc, start=(0.0, 0.0, 0.0), time=200, sample=50, dynamics="full")
    assert not tr.stop
    assert (tr.q[-1, 2] - tr.q[1, 2]) / 150 == pytest.approx(expected, rel=0.01)


def test_a_rubber_footed_part_is_oriented_by_a_plate_that_only_translates():
    # The module's own full dynamics from orientations of our choosing (not the design's): every one
    # ends at THETA, wherever the transport has carried the part.
    part = plate.load_scene(scene_path("foot"))
    d = plate.design(part, orient=-1.0, starts=2, evaluations=80, verify_starts=4)
    assert d.verified, d.failure
    assert d.unique
    harmonics = d.scene.to_dict()["plate"]["harmonics"]
    assert all(h["axis"] in ("x", "y", "z") for h in harmonics)
    ring = d.ring
    assert len(ring) == 72
    stable = sum(1 for k in range(72) if ring[k][1][2] > 0 >= ring[(k + 1) % 72][1][2])
    assert stable == 1
    T_end = 8 / d.rate + 5
    for theta0 in (-3.0, 0.0, 1.5, 2.8):
        tr = plate.simulate(d.scene, start=(0.0, 0.0, theta0), time=T_end, sample=T_end, dynamics="full")
        assert not tr.stop
        assert abs(math.remainder(tr.q[-1, 2] + 1.0, 2 * math.pi)) < 0.05


def test_a_line_sink_gathers_parts_onto_the_line_and_leaves_them_where_they_arrive():
    part = plate.load_scene(scene_path("fig1_point"))
    d = plate.design(part, line_sink=(0.01, -0.02, 0.6), limits=(15, 100), starts=2,
                     evaluations=60, verify_starts=4)
    assert d.verified, d.failure
    n = np.array([-math.sin(0.6), math.cos(0.6)])
    T_end = 8 / d.rate
    ends = []
    for start in [(-0.045, 0.045), (0.045, -0.045), (0.04, 0.04)]:
        tr = plate.simulate(d.scene, start=start, time=T_end, sample=T_end, dynamics="full")
        assert not tr.stop
        end = tr.q[-1, :2]
        assert abs((end - np.array([0.01, -0.02])) @ n) < 0.005     # on the line
        ends.append(end)
    assert np.linalg.norm(ends[0] - ends[1]) > 0.02                  # at different places along it


def test_orientation_harmonics_follow_the_exact_symmetries():
    # One friction coefficient on a plate that only translates: nothing turns the part (theta' = 0 is
    # invariant). The rubber foot on the same plate: a weathervane, the same at every position. fig4's
    # own plate (odd harmonics, no z or rz): at the centre theta'(theta + pi) = theta'(theta), no B_1.
    foot = plate.load_scene(scene_path("foot"))
    fig4 = plate.load_scene(scene_path("fig4"))
    plain = plate.scene_from_dict({**fig4.to_dict(), "plate": foot.to_dict()["plate"]})
    tight = dict(tol=1e-10, rtol=1e-11)
    none = plate.orientation_harmonics(plain, **tight)
    assert none["defined"] and none["first"] + none["rest"] < 1e-6
    vane = plate.orientation_harmonics(foot, **tight)
    there = plate.orientation_harmonics(foot, at=(0.03, -0.02), **tight)
    assert vane["first"] > 0.1 and vane["first"] > vane["rest"]
    assert np.allclose(vane["amplitude"], there["amplitude"], atol=1e-6)
    odd = plate.orientation_harmonics(fig4, **tight)
    assert odd["amplitude"][1] < 1e-6 and odd["amplitude"][3] < 1e-6 and odd["amplitude"][2] > 0.05
    with pytest.raises(ValueError):
        plate.orientation_harmonics(fig4, n=3)


def test_axes_and_harmonics_narrow_a_design_to_those_harmonics():
    # A transport along x from a plate shaken along x alone (its second harmonic skews the shake):
    # the designed scene has nothing else, and a family left empty is a ValueError.
    part = plate.load_scene(scene_path("fig1_point"))
    d = plate.design(part, transport=(0.02, 0.0), limits=(15, 150), starts=4, evaluations=150, verify_starts=4,
                     axes=["x"], harmonics=2)
    assert d.verified, d.failure
    harmonics = d.scene.to_dict()["plate"]["harmonics"]
    assert harmonics and all(h["axis"] == "x" and h["n"] <= 2 for h in harmonics)
    with pytest.raises(ValueError, match="nothing to move"):
        plate.design(part, sink=(0.0, 0.0), axes=["z"], verify_starts=2)
    with pytest.raises(ValueError, match="axes"):
        plate.design(part, sink=(0.0, 0.0), axes=["w"], verify_starts=2)
