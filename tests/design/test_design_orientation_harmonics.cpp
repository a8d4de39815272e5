// Orientation harmonics (design/src/orientation_harmonics.cpp): what a plate can give a rigid part's
// orientation, from the exact symmetries.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace plate;
using namespace design_tests;

TEST_CASE("orientation harmonics: what a plate can give a rigid part's orientation, from the exact symmetries",
          "[design][orient]") {
    // theta' at a position, as M + sum_k B_k sin(k theta + phi_k) from 12 orientations. Each check below
    // follows from a symmetry (design.hpp), and each has a case where the symmetry is broken and the
    // harmonic it forbids is there. The cycles at tight() are within ~60 rtol v_ref of the limit: the
    // harmonics' noise is about that times v_ref / rho (~5e-9 rad/s for fig4's part); 1e-6 rad/s is
    // the bound, far below the harmonics that are allowed (1e-3 and up).
    const Scene fig4 = scene("fig4"), foot = scene("foot");
    const LimitCycleOptions o = tight();
    const double noise = 1e-6;
    auto harmonics = [&](const Scene& sc, const Vec2& s) {
        const OrientationHarmonics h = orientation_harmonics(sc, s, o);
        REQUIRE(h.defined);
        REQUIRE(h.amplitude.size() == 7);
        return h;
    };
    // (0) The transform itself, on known series: M + B_1 sin(theta + 0.3) + B_2 sin(2 theta - 1) +
    // B_6 cos(6 theta) on 12 points (k = 6 = n/2: only a cosine part is seen there).
    {
        std::vector<double> w(12);
        for (int k = 0; k < 12; ++k) {
            const double th = 2 * kPi * k / 12;
            w[k] = -0.02 + 0.3 * std::sin(th + 0.3) + 0.1 * std::sin(2 * th - 1) + 0.05 * std::cos(6 * th);
        }
        const OrientationHarmonics h = harmonics_of(w);
        CHECK(h.mean == Approx(-0.02).margin(1e-15));
        const double expected[7] = {0.02, 0.3, 0.1, 0, 0, 0, 0.05};
        for (int k = 0; k <= 6; ++k) CHECK(h.amplitude[k] == Approx(expected[k]).margin(1e-14));
        CHECK(h.rest() == Approx(0.17));
        CHECK(h.slope_bound() == Approx(2 * 0.1 + 6 * 0.05));
        CHECK_FALSE(h.one_stable());   // 0.09 < 0.17^2 + 0.5^2
        // Either side of the threshold B_1^2 = rest^2 + slope^2: 0.02 + B_1 sin(theta) + 0.05 sin(2 theta)
        // has rest 0.07 and slope bound 0.1, so B_1^2 against 0.0149: one stable orientation at B_1 =
        // 0.13 (0.0169) -- theta' = 0.02 + 0.13 sin + 0.05 sin 2 has exactly one zero with negative slope,
        // counted here on a fine ring -- and not claimed at B_1 = 0.12 (0.0144).
        for (const double b1 : {0.13, 0.12}) {
            INFO("B_1 = " << b1);
            const auto series = [&](double th) { return 0.02 + b1 * std::sin(th) + 0.05 * std::sin(2 * th); };
            for (int k = 0; k < 12; ++k) w[k] = series(2 * kPi * k / 12);
            const OrientationHarmonics hb = harmonics_of(w);
            CHECK(hb.rest() == Approx(0.07));
            CHECK(hb.slope_bound() == Approx(0.1));
            CHECK(hb.one_stable() == (b1 > 0.1221));
            int stable = 0;
            for (int k = 0; k < 100000; ++k)
                stable += series(2 * kPi * k / 100000) > 0 && series(2 * kPi * (k + 1) / 100000) <= 0;
            if (hb.one_stable()) CHECK(stable == 1);
        }
    }
    // (1) One friction coefficient on a plate that only translates: theta' = 0 is invariant, nothing
    // turns the part. With the rubber foot (foot.json's own plate, the same motion) friction's torque
    // -(sum_i (mu_i - mu) N_i r_i) x u turns it, and the same way everywhere (no position in the
    // dynamics): a weathervane, its first harmonic above the rest (B_1 0.37 against 0.16 rad/s) -- but not
    // enough for one stable orientation by one_stable(), and indeed there are three at a finer scale
    // (design.hpp).
    Scene plain = fig4;
    plain.plate = foot.plate;
    const OrientationHarmonics none = harmonics(plain, Vec2::Zero());
    CHECK(none.first() + none.rest() < noise);
    const OrientationHarmonics vane = harmonics(foot, Vec2::Zero()), there = harmonics(foot, Vec2(0.03, -0.02));
    CHECK(vane.first() > 0.1);
    CHECK(vane.first() > vane.rest());
    CHECK_FALSE(vane.one_stable());
    for (int k = 0; k <= 6; ++k) CHECK(std::abs(there.amplitude[k] - vane.amplitude[k]) < noise);
    // (2) Odd harmonics without z or rz (fig4's own plate): turning the motion by pi is shifting it by
    // half a period, so at the centre theta'(theta + pi) = theta'(theta): no odd harmonic. (The foot's
    // plate has a heave: B_1 above.)
    const OrientationHarmonics odd = harmonics(fig4, Vec2::Zero());
    CHECK(odd.amplitude[1] < noise);
    CHECK(odd.amplitude[3] < noise);
    CHECK(odd.amplitude[5] < noise);
    CHECK(odd.amplitude[2] > 0.05);   // the half-turn pairing's own term
    // Away from the centre the pairing maps s to -s: nothing forbids B_1 there (the plate's tilt and
    // alpha x s make the position matter).
    CHECK(harmonics(fig4, Vec2(0.03, -0.02)).amplitude[1] > 1e-4);
    // (3) A quarter-turn-symmetric motion: x, y, rx, ry turning in circles one way at n = 1 and the
    // other way at n = 3. Turning it by pi/2 is shifting it by T/4 (e^{i pi/2} at n = 1, e^{i 3 pi/2}
    // = e^{-i pi/2} at n = 3), so theta' at the centre has period pi/2: only B_4 (and M) remain. With
    // the third harmonic's angular-acceleration amplitude sqrt(27) times the first's (its tilt angle
    // 1/sqrt(3) times) the two harmonics' coning cancels exactly (coning_rate: Im(A_rx conj A_ry) /
    // (2 (n w)^3) per harmonic). With n = 3 reversed, turning the same way as n = 1, the symmetry is
    // broken (the motion is still odd): B_2 returns.
    auto quarter_turn = [&](int sense3) {
        const double a1 = 20, c = 9.5, a3 = 7.3, d = std::sqrt(27.0) * c, q = kPi / 2, flip = sense3 < 0 ? kPi : 0;
        PlateMotion u;
        u.T = fig4.plate.T;
        u.harmonics = {{Axis::x, 1, a1, q},        {Axis::y, 1, a1, 0},          {Axis::rx, 1, c, q + 6.30},
                       {Axis::ry, 1, c, 6.30},     {Axis::x, 3, a3, q + 3.06},   {Axis::y, 3, a3, 3.06 + flip},
                       {Axis::rx, 3, d, q + 6.33}, {Axis::ry, 3, d, 6.33 + flip}};
        return u;
    };
    Scene sym = fig4;
    sym.plate = quarter_turn(-1);
    CHECK(std::abs(coning_rate(sym.plate)) < 1e-12);
    const OrientationHarmonics quarter = harmonics(sym, Vec2::Zero());
    for (int k : {1, 2, 3, 5}) CHECK(quarter.amplitude[k] < noise);
    CHECK(quarter.amplitude[4] > 1e-3);
    sym.plate = quarter_turn(+1);
    CHECK(std::abs(coning_rate(sym.plate)) > 1e-5);
    const OrientationHarmonics broken = harmonics(sym, Vec2::Zero());
    CHECK(broken.amplitude[2] > 1e-3);
    CHECK(broken.amplitude[1] < noise);   // (still odd)
}
