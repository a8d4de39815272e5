// The second stick-slip reference (issue 14, point 6): Moreau-Jean time stepping with Siconos'
// frictional contact solver (moreau_jean.hpp), which shares no equation, mode or event with the
// engine (only the scene and u(t)), against the engine's U-dynamics trajectories through sticking,
// pivoting and sliding. The reference keeps the part's gyroscopic term, which the engine's U-dynamics
// drop: the scenes here have J_xz = J_yz = 0, where it vanishes (checked).
//
// Expected values: the engine at rtol 1e-11 (its trajectories' error there is below 1e-9 rho,
// the regularised-reference tests). The time stepper is first order, but not smoothly so: a stick's
// start or end, or a slip's reversal, falls anywhere within a step, so the error at step h is bounded by C h while its size
// and even its sign jump from one h to the next (fig1's point part: +5.0e-6, -5.0e-6, -1.9e-6,
// +8.7e-7 rho at T/1000 ... T/8000). Two checks:
// - the bound itself: with C from the two coarsest runs, C = max(e(T/1000), 2 e(T/2000)), every finer
//   run to T/32000 must be within 2 C h / (T/1000) of the engine. An engine whose answer is off by b
//   fails once b exceeds about C/16 to C/28 (by the sign of the step error; 1e-5 rho or less here): the
//   engine with mu 0.1 % off levels off at 9.4e-6 (fig1's point part) to 5.3e-4 rho (fig1) and fails;
// - where the errors do halve with h (every ratio e(h)/e(h/2) from T/2000 on within 5 % of 2: fig6
//   and fig1, required of fig6), Richardson's extrapolant 2 q(T/32000) - q(T/16000) must agree with
//   the engine within twice its change from the previous halving's, plus 1e-8 rho (the engine's
//   rtol-1e-11 error, and the solver's: residuals below 1e-11 of Siconos' relative measure, measured
//   5e-14, move a step's velocities by that fraction of v_ref).
#include "plate/moreau_jean.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

using plate_tests::scene;

// Distance between two configurations in units of rho (theta scaled by rho; a point part's rho is 1 m
// and its theta 0).
double dist(const Scene& sc, const Vec3& a, const Vec3& b) {
    Vec3 d = a - b;
    d[2] *= sc.part.rho();
    return d.norm() / sc.part.rho();
}

// Does the mode change hold a contact that slid before (enters_hold), or release one (breaks_away)?
bool enters_hold(const ModeEvent& ev) {
    for (int i = 0; i < 3; ++i)
        if (!ev.from.holds(i) && ev.to.holds(i)) return true;
    return false;
}
bool breaks_away(const ModeEvent& ev) {
    for (int i = 0; i < 3; ++i)
        if (ev.from.holds(i) && !ev.to.holds(i)) return true;
    return false;
}

// `sticks_from_sliding`: the engine's run must enter a hold from sliding at least once (else it would
// test a break-away only); `halving`: the errors must halve with h (then Richardson's check applies).
void check_against_engine(const Scene& sc, const Vec3& q0, double duration, bool sticks_from_sliding, bool halving = false) {
    INFO(sc.name << " from (" << q0.transpose() << ") for " << duration << " s");
    REQUIRE(sc.part.J(0, 2) == 0);
    REQUIRE(sc.part.J(1, 2) == 0);
    IntegrationOptions io;
    io.rtol = 1e-11;
    const Trajectory tr = simulate(sc, Dynamics::U, q0, Vec3::Zero(), duration, duration, io);
    REQUIRE(tr.stop.reason == StopReason::None);
    const Vec3 qe = tr.samples.back().q;
    // Stick-slip on the way: a contact that breaks away, and (where asked) one that slid and is held
    // (after t = 0, where a start from rest enters its hold).
    int holds_entered = 0, breakaways = 0;
    for (const ModeEvent& ev : tr.events) {
        holds_entered += ev.t > 0 && enters_hold(ev);
        breakaways += breaks_away(ev);
    }
    CHECK(breakaways >= 1);
    if (sticks_from_sliding) CHECK(holds_entered >= 1);

    double C = 0, e[6];
    Vec3 q[6];
    for (int k = 0; k < 6; ++k) {
        const long n = 1000L << k;
        MoreauJeanOptions opt;
        opt.steps_per_period = n;
        const MoreauJeanSummary s = moreau_jean_u(sc, q0, duration, opt);
        INFO("T/" << n << ": " << s.solver_failures << " solves of " << s.steps << " short of 1e-13, the largest error "
                  << s.max_residual);
        CHECK(s.max_residual < 1e-11);
        CHECK(s.max_gap < 1e-9);   // the part stays on its three contacts
        q[k] = s.q;
        e[k] = dist(sc, s.q, qe);
        const double scaled = e[k] * static_cast<double>(n) / 1000;   // e / (h / (T/1000))
        if (k < 2) {
            C = std::max(C, scaled);
            continue;
        }
        INFO("T/" << n << ": " << e[k] << " rho off the engine, C = " << C);
        CHECK(scaled <= 2 * C);
    }
    bool halves = true;
    for (int k = 1; k < 5; ++k) halves = halves && std::abs(e[k] / e[k + 1] - 2) <= 0.1;
    if (halving) CHECK(halves);
    if (halves) {
        const Vec3 r32 = 2 * q[5] - q[4], r16 = 2 * q[4] - q[3];
        INFO("Richardson: " << dist(sc, r32, qe) << " rho off the engine, previous " << dist(sc, r16, qe));
        CHECK(dist(sc, r32, qe) <= 2 * dist(sc, r32, r16) + 1e-8);
    }
}

}   // namespace

TEST_CASE("Siconos: Moreau-Jean converges at first order to the engine's U-dynamics through stick-slip", "[siconos]") {
    SECTION("fig6's sticking configuration (0.0167, 0, 2.693): slides, stuck, slides every period") {
        check_against_engine(scene("fig6"), Vec3(0.0167, 0, 2.693), 0.2, true, true);
    }
    SECTION("fig1 from rest: stuck at t = 0, breaks away at 0.77 ms, then slides") {
        check_against_engine(scene("fig1"), Vec3(-0.04, 0.03, 1.2), 0.2, false);
    }
    SECTION("heave_yaw at a corner of its field: pivots about contact 1, stuck, pivots, every period") {
        check_against_engine(scene("heave_yaw"), Vec3(-0.05, -0.05, 5.3856), 0.3, true);
    }
    SECTION("the point part of fig1 from rest: stuck, breaks away at 1.3 ms, its slip reverses twice a period") {
        check_against_engine(scene("fig1_point"), Vec3(0.01, 0.02, 0), 0.2, false);
    }
}
