// The search's coarse first steps (coarse.cpp, IdentifyOptions::coarse_iterations): under a motion that
// makes fig4's part stick and slip, a search from a guess 0.05 off in the kinetic coefficients could end
// in a local minimum with the static ones bent to fit; Levenberg-Marquardt steps of the kinetic
// coefficients alone on the whole tracks, their starts held at the first frames, reach the chi-square's
// bowl around the truth (docs/decisions/identification.md, "Coarse steps first", with the figures).
#include "identify_fixtures.hpp"
#include "internal.hpp"
#include "plate/random_scene.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

using namespace plate;
using namespace plate::test;
using identify_detail::CoarseResult;
using identify_detail::Layout;
using identify_detail::TrackCost;

namespace {

// fig4's part under the motion `plate identify --suggest` proposes for it (x with its second harmonic, a
// y second harmonic a quarter period later, a yaw; T = 0.1 s, horizontal peak 1.1 mu_s g at mu_s 0.36).
Scene suggested_fig4() {
    Scene s = scene("fig4");
    s.part.mu_static = Vec3(0.36, 0.36, 0.36);
    s.plate.T = 0.1;
    s.plate.harmonics.clear();
    const auto add = [&](Axis axis, int n, double amp, double phase) {
        Harmonic h;
        h.axis = axis;
        h.n = n;
        h.amp = amp;
        h.phase = phase;
        s.plate.harmonics.push_back(h);
    };
    add(Axis::x, 1, 3.2829671187393514, 0);
    add(Axis::x, 2, 1.094322372913117, 0);
    add(Axis::y, 2, 1.094322372913117, kPi / 2);
    add(Axis::rz, 1, 61.42344881557858, kPi / 2);
    return s;
}

}   // namespace

TEST_CASE("coarse steps take the kinetic coefficients from a guess 0.05 off to within 0.005 of the truth", "[identify][coarse]") {
    const Scene nominal = suggested_fig4();
    const std::vector<std::string> names = {"mu_k1", "mu_k2", "mu_k3", "mu_s1", "mu_s2", "mu_s3"};
    const std::vector<double> truth = {0.25, 0.30, 0.35, 0.30, 0.36, 0.42};
    // bench_identify's seed 41 (5 tracks of 10 s from random starts), whose search from the guess ended
    // in a local minimum before coarse steps.
    const int seed = 41;
    Rng rng(1000 + seed);
    std::vector<Track> tracks;
    for (int k = 0; k < 5; ++k) {
        const Vec3 q0(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(-kPi, kPi));
        tracks.push_back(filmed(nominal, names, truth, strobe(0.1, 5, 100 * seed + k), q0, 10.0));
    }
    IdentifyOptions o = options(names);
    o.threads = 2;
    o.coarse_iterations = 2;
    const Layout layout(nominal, names);
    std::vector<std::unique_ptr<TrackCost>> costs;
    std::vector<TrackCost*> ptrs;
    std::vector<std::vector<double>> q0;
    for (const Track& tr : tracks) {
        costs.push_back(std::make_unique<TrackCost>(nominal, layout, tr, 0, o, false));
        ptrs.push_back(costs.back().get());
        q0.push_back({tr.q.front().x() * 1e3, tr.q.front().y() * 1e3, tr.q.front().z()});
    }
    std::vector<double> lo, hi;
    for (int j = 0; j < layout.size(); ++j) {
        lo.push_back(layout.lower(j, o));
        hi.push_back(layout.upper(j, o));
    }
    const std::vector<double> guess = layout.internal(layout.scene_values());   // 0.30 and 0.36 everywhere
    const auto step = [&](double factor, std::vector<double>& natural) {
        std::vector<double> x = guess;
        const CoarseResult c = identify_detail::coarse_steps(ptrs, layout, o, x, q0, {}, lo, hi, 60, factor);
        natural = layout.natural(x);
        return c;
    };
    std::vector<double> coarse;
    const CoarseResult c = step(identify_detail::kCoarseFactor, coarse);
    // Each step: 2 x 3 points (the kinetic coefficients moved both ways), then a trial point at least.
    CHECK(c.simulations >= 5 * (1 + 2 * (6 + 1)));
    REQUIRE(c.iterations == 2);
    CHECK(c.chi2_after < c.chi2_before);
    double coarse_off = 0;
    for (int i = 0; i < 3; ++i) coarse_off = std::max(coarse_off, std::abs(coarse[i] - truth[i]));
    INFO("coarse: kinetic " << coarse[0] << " " << coarse[1] << " " << coarse[2] << ", chi2 " << c.chi2_before << " -> "
                            << c.chi2_after);
    // Seen failing: with the step's sign flipped (no step lowers the chi-square) and with the static
    // excesses moved too (0.0059 off). The search's own difference step does as well here (the docs).
    CHECK(coarse_off < 0.005);
    CHECK(c.chi2_after < 0.02 * c.chi2_before);
    for (int j = 3; j < 6; ++j) CHECK(coarse[j] - coarse[j - 3] == Approx(guess[j]).margin(1e-12));   // excesses held
}

// After a first start that did not fit as well as the noise allows, the second starts from its kinetic
// coefficients and offsets with the scene's static excesses; without static coefficients, from its draw.
// Seen failing with the roles exchanged (the fit's statics kept, the draw's kinetics taken).
TEST_CASE("a later start keeps the fit's kinetic coefficients and offsets and takes the draw's static ones",
          "[identify][coarse]") {
    const Scene fig4 = scene("fig4");
    const Layout both(fig4, {"mu_k1", "mu_s1", "mu_k2", "com_x"});
    const std::vector<double> fit = {0.25, 0.05, 0.31, 1.5}, statics = {0.3, 0.06, 0.3, 0.0}, draw = {0.6, 0.2, 0.7, -3.0};
    CHECK(identify_detail::restart(both, fit, statics, draw) == std::vector<double>{0.25, 0.06, 0.31, 1.5});
    const Layout kinetic(fig4, {"mu_k1", "mu_k2"});
    CHECK(identify_detail::restart(kinetic, {0.25, 0.31}, {0.3, 0.3}, {0.6, 0.7}) == std::vector<double>{0.6, 0.7});
}
