// The second stick-slip reference (issue 14, point 6): Moreau-Jean time stepping with Siconos'
// frictional contact solver (moreau_jean.hpp), which shares no equation, mode or event with the
// engine, against the engine's U-dynamics trajectories through sticking, pivoting and sliding.
//
// Expected values: the engine at rtol 1e-11 (its trajectories' error there is below 1e-9 rho,
// the regularised-reference tests). The time stepper is first order, but not smoothly so: a stick's
// start or end falls anywhere within a step, so the error at step h is bounded by C h while its size
// and even its sign jump from one h to the next (fig1's point part: +5.0e-6, -5.0e-6, -1.9e-6,
// +8.7e-7 rho at T/1000 ... T/8000), and Richardson's extrapolation does not apply. The check is the
// bound itself: with C from the two coarsest runs, C = max(e(T/1000), 2 e(T/2000)), every run from
// T/1000 to T/32000 must be within 2 C h / (T/1000) of the engine. An engine whose answer is off by
// b fails once 32 b > 2 C; b is then 1/16 of the coarsest error (1e-5 rho or less here): the engine
// with mu 0.1 % off plateaus at 9e-6 (fig1's point part) and 8.6e-5 rho (heave_yaw) and fails.
#include "plate/moreau_jean.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

Scene scene(const std::string& name) { return load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

// Distance between two configurations in units of rho (theta scaled by rho; a point part's rho is 1 m
// and its theta 0).
double dist(const Scene& sc, const Vec3& a, const Vec3& b) {
    Vec3 d = a - b;
    d[2] *= sc.part.rho();
    return d.norm() / sc.part.rho();
}

void check_against_engine(const Scene& sc, const Vec3& q0, double duration) {
    INFO(sc.name << " from (" << q0.transpose() << ") for " << duration << " s");
    IntegrationOptions io;
    io.rtol = 1e-11;
    const Trajectory tr = simulate(sc, Dynamics::U, q0, Vec3::Zero(), duration, duration, io);
    REQUIRE(tr.stop.reason == StopReason::None);
    const Vec3 qe = tr.samples.back().q;
    // The run must stick somewhere (else this is a sliding test): time held by some contact.
    REQUIRE(std::max({tr.held_time[0], tr.held_time[1], tr.held_time[2]}) > 0);

    double C = 0;
    for (long n = 1000; n <= 32000; n *= 2) {
        MoreauJeanOptions opt;
        opt.steps_per_period = n;
        const MoreauJeanSummary s = moreau_jean_u(sc, q0, duration, opt);
        INFO(s.solver_failures << " solves of " << s.steps << " short of 1e-13, the largest error " << s.max_residual);
        // Siconos' error is relative to |q| (the free contact velocities, at most about v_ref): a step's
        // velocities are off by at most that fraction of v_ref, 1e-9 v_ref x 0.3 s = 5e-11 m in all.
        CHECK(s.max_residual < 1e-9);
        CHECK(s.max_gap < 1e-9);   // the part stays on its three contacts
        const double e = dist(sc, s.q, qe), scaled = e * static_cast<double>(n) / 1000;   // e / (h / (T/1000))
        if (n <= 2000) C = std::max(C, scaled);
        INFO("T/" << n << ": " << e << " rho off the engine, C = " << C);
        CHECK(scaled <= 2 * C);
    }
}

}  // namespace

TEST_CASE("Siconos: Moreau-Jean converges at first order to the engine's U-dynamics through stick-slip",
          "[siconos]") {
    SECTION("fig6's sticking configuration (0.0167, 0, 2.693): slides, stuck, slides every period") {
        check_against_engine(scene("fig6"), Vec3(0.0167, 0, 2.693), 0.2);
    }
    SECTION("fig1 from rest: stuck at t = 0, breaks away at 0.77 ms, then slides") {
        check_against_engine(scene("fig1"), Vec3(-0.04, 0.03, 1.2), 0.2);
    }
    SECTION("heave_yaw at a corner of its field: sticks and slips every period") {
        check_against_engine(scene("heave_yaw"), Vec3(-0.05, -0.05, 5.3856), 0.3);
    }
    SECTION("the point part of fig1 from rest: stuck, then stick-slip") {
        check_against_engine(scene("fig1_point"), Vec3(0.01, 0.02, 0), 0.2);
    }
}
