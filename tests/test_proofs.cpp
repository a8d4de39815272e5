// Small, seeded versions of the Theorem 1 checks, each with a deliberately broken case that it
// must catch.
#include "theorem1.hpp"

#include "plate/dynamics.hpp"
#include "plate/scene_io.hpp"

#include <catch2/catch.hpp>

using namespace plate;
using namespace plate::proofs;

TEST_CASE("Theorem 1: the relative twist of thin parts contracts (V never rises beyond its error bound)",
          "[proofs][contraction]") {
    ContractionOptions o;
    o.cases = 12;
    o.seed = 100;
    const ContractionSummary s = check_contraction(o);
    INFO("valid " << s.valid << ", worst rise/bound " << s.worst_increase << " (seed " << s.worst_seed << "), median rate "
                  << s.median_rate << ", max Floquet " << s.max_spectral_radius);
    CHECK(s.valid >= 8);
    CHECK(s.monotone == s.valid);
    CHECK(s.converged == s.valid);
    CHECK(s.floquet_below_one == s.valid);
    CHECK(s.unique == s.valid);
    CHECK(s.max_rate < 1);
    CHECK(s.tie.samples == 120);   // and tied to the dynamics (statics, limit surface) at every case
    CHECK(s.tie.passed());
    CHECK(s.passed());
    CHECK(s.counterexamples.empty());
    // Signed margins: V fell at every accepted step of every case, so the worst change of V over its
    // error bound is below 0 (measured -7e-4 for these seeds: the closest step, near convergence); the
    // other checks' margins as measured: V_end / V0 9e-13 (<= 1e-12), cycle spread 4e-10 (< 1e-6).
    CHECK(s.worst_increase < 0);
    CHECK(s.worst_V_end <= 1e-12);
    CHECK(s.max_cycle_spread < 1e-8);
    for (const auto& c : s.details) {   // each uniqueness verdict rests on all four further starts
        INFO("seed " << c.seed);
        CHECK(c.starts_reached == o.starts);
    }
}

TEST_CASE("Observation 1's uniqueness needs every further start to reach the same cycle", "[proofs][contraction]") {
    CHECK(unique_cycle(4, 4, 1e-9));
    CHECK_FALSE(unique_cycle(1, 4, 0));      // one start reached the cycle, three left the model: no evidence
    CHECK_FALSE(unique_cycle(3, 4, 1e-9));   // one short
    CHECK_FALSE(unique_cycle(4, 4, 2e-6));   // a start reached another cycle
    CHECK_FALSE(unique_cycle(0, 0, 0));
}

TEST_CASE("beyond Theorem 1: thick parts, seeded search for counter-examples", "[proofs][contraction][thick]") {
    ContractionOptions o;
    o.cases = 8;
    o.seed = 500;
    o.thin = false;
    const ContractionSummary s = check_contraction(o);
    INFO("thick: valid " << s.valid << ", monotone " << s.monotone << ", unique " << s.unique << ", worst rise/bound "
                         << s.worst_increase << ", max Floquet " << s.max_spectral_radius);
    CHECK(s.valid >= 4);
    // Observation 1 (not a theorem for thick parts): the cycles found are unique and attracting.
    CHECK(s.unique == s.valid);
    CHECK(s.floquet_below_one == s.valid);
}

TEST_CASE("the contraction check catches an expanding map (negative friction)", "[proofs][contraction][broken]") {
    ContractionOptions o;
    o.cases = 4;
    o.seed = 100;
    o.periods = 6;
    o.modify = [](Scene& sc) { sc.part.mu = -sc.part.mu; };   // friction that pushes: energy grows
    const ContractionSummary s = check_contraction(o);
    REQUIRE(s.valid > 0);
    CHECK(s.monotone < s.valid);
    CHECK(s.worst_increase > 1e3);
    CHECK_FALSE(s.passed());
    CHECK_FALSE(s.counterexamples.empty());
}

TEST_CASE("limit surface of a thin part: convex, twist normal to it, (40) holds, no vertices", "[proofs][limit_surface]") {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        const Scene sc = random_scene(seed, RandomSceneOptions{true});
        double scale = 0;
        const WrenchMap w = thin_wrench_map(sc, Vec3(0.01, -0.01, 0.5), 0.01, &scale);
        const LimitSurfaceResult r = check_limit_surface(w, scale, 300);
        INFO("seed " << seed << ": max-work margin " << r.max_work_margin << ", (40) " << r.monotonicity_margin << ", separation "
                     << r.min_separation);
        CHECK(r.convex_and_normal());
        // Signed margins: held with room at the closest pair of the 300 directions (measured 2e-3 and
        // 4e-3 of sum mu N for random thin parts; neighbouring directions are ~0.2 apart).
        CHECK(r.max_work_margin > 0);
        CHECK(r.monotonicity_margin > 0);
        CHECK(r.strictly_convex());   // no flat faces, no vertices
        CHECK(r.min_separation > 1e-3);
    }
}

TEST_CASE("the limit-surface check catches a non-convex surface (the wrench's sign flipped)", "[proofs][limit_surface][broken]") {
    const Scene sc = random_scene(2, RandomSceneOptions{true});
    double scale = 0;
    const WrenchMap w = thin_wrench_map(sc, Vec3::Zero(), 0.0, &scale);
    const LimitSurfaceResult r = check_limit_surface([&](const Vec3& xi) { return Vec3(-w(xi)); }, scale, 200);
    CHECK_FALSE(r.convex_and_normal());
    CHECK(r.max_work_margin < -0.1);   // signed: violated by more than a tenth of sum mu N
    CHECK(r.monotonicity_margin < -0.1);
}

TEST_CASE("as contacts approach collinear the limit surface gets a vertex and A becomes singular",
          "[proofs][limit_surface][collinear]") {
    // Contacts (-L, 0), (L, 0), (0, e) (centre of mass at the centroid). With e = 0 every twist
    // (0, v_y, rho omega) with |omega| L < v_y moves all contacts along +y: they all get the same
    // wrench, so one wrench has many normals -- a vertex. Two such twists' wrenches approach each
    // other like e, while the surface stays convex; and A's condition number grows like 1/e.
    double last_gap = 1e9, last_cond = 0;
    const double L = 0.03;
    for (double e : {2e-2, 2e-3, 2e-4}) {
        Scene sc = random_scene(3, RandomSceneOptions{true});
        sc.part.c = {Vec3(-L, -e / 3, 0), Vec3(L, -e / 3, 0), Vec3(0, 2 * e / 3, 0)};
        sc.part.mu.setConstant(0.3);
        sc.plate.harmonics.clear();
        double scale = 0;
        const WrenchMap w = thin_wrench_map(sc, Vec3::Zero(), 0, &scale);
        const LimitSurfaceResult r = check_limit_surface(w, scale, 300);
        const double rho = sc.part.rho();
        const double gap = (w(Vec3(0, 1, 0)) - w(Vec3(0, 1, rho * 0.5 / L).normalized())).norm() / scale;
        const Conditioning c = condition_of_A(sc, 20, 5);
        INFO("e = " << e << ": wrench gap " << gap << ", cond(A) " << c.max_condition);
        CHECK(r.convex_and_normal());   // still convex ...
        CHECK(gap < 0.2 * last_gap);    // ... but two distinct twists share ever closer wrenches
        CHECK(c.max_condition > 5 * last_cond);
        last_gap = gap;
        last_cond = c.max_condition;
    }
    CHECK(last_gap < 0.01);
    CHECK(last_cond > 100);
}

TEST_CASE("collinear contacts make A singular", "[proofs][invertibility][collinear]") {
    Scene sc = random_scene(3, RandomSceneOptions{true});
    sc.part.c = {Vec3(-0.03, 0, 0), Vec3(0.03, 0, 0), Vec3(0.01, 0, 0)};
    const Conditioning c = condition_of_A(sc, 10, 5);
    CHECK(c.min_singular < 1e-12);
}

TEST_CASE("A is invertible and well conditioned for the paper's parts", "[proofs][invertibility]") {
    for (const char* name : {"fig4", "fig5"}) {
        const Scene sc = load_scene(std::string(PLATE_SOURCE_DIR "/scenes/") + name + ".json");
        const Conditioning c = condition_of_A(sc, 200, 1);
        INFO(name << ": cond(A) up to " << c.max_condition);
        CHECK(c.max_condition < 1e3);
    }
}

TEST_CASE("Appendix D: the converged cycle repeats with period T", "[proofs][periodicity]") {
    const Scene sc = random_scene(21, RandomSceneOptions{true});
    LimitCycleOptions lo;
    lo.integration.rtol = 1e-11;
    lo.tol = 1e-10;
    const LimitCycleSummary lc = limit_cycle(sc, Vec3(0.01, 0, 0.3), lo, Vec3(0.05, 0, 1));
    REQUIRE(lc.converged);
    Vec3 next;
    IntegrationOptions io;
    io.rtol = 1e-11;
    REQUIRE(period_map(sc, Vec3(0.01, 0, 0.3), lc.qd_start, next, io));
    Vec3 again;
    REQUIRE(period_map(sc, Vec3(0.01, 0, 0.3), next, again, io));
    const double v = sc.v_ref();
    // P(x*) = x*: the start repeats after one and after two periods, to the cycle tolerance.
    CHECK((next - lc.qd_start).head<2>().norm() < 1e-8 * v);
    CHECK((again - lc.qd_start).head<2>().norm() < 1e-8 * v);
    // Broken case: a state that is not on the cycle does not repeat (the check can fail).
    Vec3 off;
    REQUIRE(period_map(sc, Vec3(0.01, 0, 0.3), lc.qd_start + Vec3(0.3 * v, 0, 0), off, io));
    CHECK((off - (lc.qd_start + Vec3(0.3 * v, 0, 0))).head<2>().norm() > 1e-3 * v);
}

TEST_CASE("the dynamics tie catches a wrong normal force, a swapped lever arm and a wrong mu, and says which check",
          "[proofs][tie]") {
    // Contraction, Floquet and limit-surface checks hold for any Coulomb friction with normal forces
    // >= 0: each of these wrong models passes them. The tie (theorem1.hpp) must not.
    ContractionOptions o;
    o.cases = 6;
    o.seed = 100;
    const ContractionSummary good = check_contraction(o);
    INFO("production: " << good.tie.failure);
    CHECK(good.tie.samples == 60);
    CHECK(good.tie.passed());
    CHECK(good.tie.worst_statics < 1e-13);   // rounding (measured 3e-16), far below kTieTolerance
    CHECK(good.tie.worst_wrench < 1e-13);
    struct Mutation {
        const char* what;
        const char* caught_by;
        DynamicsUnderTest dyn;
    };
    auto with = [](std::function<void(Scene&)> edit, std::function<void(Vec3&)> edit_n) -> DynamicsUnderTest {
        return [edit, edit_n](const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Vec3& qdd, Vec3& n) {
            Scene wrong = sc;
            edit(wrong);
            Workspace ws;
            accelerations(wrong, Dynamics::U, q, qd, ps, ws);
            qdd = ws.qdd;
            n = ws.n;
            edit_n(n);
        };
    };
    const Mutation mutations[] = {
        {"a normal force off by 1e-6", "statics", with([](Scene&) {}, [](Vec3& n) { n[1] *= 1 + 1e-6; })},
        {"contact 1's lever arm with x and y swapped", "statics",
         with([](Scene& s) { s.part.c[0] = Vec3(s.part.c[0].y(), s.part.c[0].x(), s.part.c[0].z()); }, [](Vec3&) {})},
        {"mu of contact 3 scaled by 1.01", "wrench", with([](Scene& s) { s.part.mu[2] *= 1.01; }, [](Vec3&) {})},
    };
    for (const auto& m : mutations) {
        INFO(m.what);
        ContractionOptions bad = o;
        bad.dynamics = m.dyn;
        const ContractionSummary s = check_contraction(bad);
        INFO("failure: " << s.tie.failure);
        CHECK_FALSE(s.passed());
        CHECK(s.tie.failure.rfind(m.caught_by, 0) == 0);   // the message starts with the check's name
        const LimitSurfaceCampaign ls = check_limit_surfaces(5, 1, m.dyn);
        CHECK_FALSE(ls.passed());
        CHECK(ls.convex == ls.parts);   // the surface checks alone pass the wrong model
    }
}

TEST_CASE("the limit-surface check against the independent friction set catches kernels the convexity checks pass",
          "[proofs][limit_surface][broken]") {
    // The max-work and (40) checks hold for any wrench -sum c_i G_i v_i/|v_i| with c_i >= 0 (Cauchy-
    // Schwarz): a wrench kernel fed a wrong mu or lever arm passes them. The support point of the
    // friction set built from the part itself (thin_friction_set) does not.
    const Scene sc = random_scene(2, RandomSceneOptions{true});
    const Vec3 q0(0.01, -0.01, 0.5);
    const double t = 0.01;
    const FrictionSet set = thin_friction_set(sc, q0, t);
    double scale = 0;   // set by thin_wrench_map before it is used (not in one call: argument order)
    const WrenchMap kernel_of_part = thin_wrench_map(sc, q0, t, &scale);
    const LimitSurfaceResult good = check_limit_surface(kernel_of_part, scale, 300, 0.2, &set);
    CHECK(good.on_friction_set());
    CHECK(good.convex_and_normal());
    // Signed: the sampled support function h_s underestimates h by at most h (1 - cos(pi/720)) ~ 1e-5 h,
    // so the kernel's support point clears it by a little (measured 6e-9 of sum mu N), and every wrench
    // lies inside the outer bound h_s / cos(pi/720) with room (measured 2e-3).
    CHECK(good.support_margin > 0);
    CHECK(good.support_margin < 1e-4);
    CHECK(good.outside_margin > 0);
    // The generated kernel, fed from the set with one input edited.
    auto kernel = [&](std::function<void(gen::WrenchInput&)> edit) -> WrenchMap {
        gen::WrenchInput in =
            wrench_input(set.r, set.cap.cwiseQuotient(sc.part.friction().kinetic()), sc.part.friction(), set.rho);
        edit(in);
        return wrench_map(in);
    };
    const LimitSurfaceResult same = check_limit_surface(kernel([](gen::WrenchInput&) {}), scale, 300, 0.2, &set);
    CHECK(same.on_friction_set());   // the kernel fed correctly is the set's support point
    const std::pair<const char*, std::function<void(gen::WrenchInput&)>> wrong[] = {
        {"mu of contact 3 x 1.1", [](gen::WrenchInput& in) { in.mu3 *= 1.1; }},
        {"contact 1's lever arm with x and y swapped", [](gen::WrenchInput& in) { std::swap(in.r1x, in.r1y); }},
        {"contact 2's lever arm x 1.1",
         [](gen::WrenchInput& in) {
             in.r2x *= 1.1;
             in.r2y *= 1.1;
         }},
    };
    for (const auto& [what, edit] : wrong) {
        INFO(what);
        const LimitSurfaceResult r = check_limit_surface(kernel(edit), scale, 300, 0.2, &set);
        INFO("support " << r.support_margin << ", outside " << r.outside_margin);
        CHECK(r.convex_and_normal());       // the old checks pass it ...
        CHECK_FALSE(r.on_friction_set());   // ... the friction set does not
    }
}
