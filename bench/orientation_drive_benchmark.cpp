// Benchmark (a measurement, not a test): how strongly can a plate motion inside the design limits give a
// rigid part ONE preferred orientation? Issue 16 asks for fig4's part at a unique stable fixed point, and
// a fixed point's orientation is decided by theta' at its position, a function of theta alone there:
//     theta'(theta) = M + sum_k B_k sin(k theta + phi_k)     (the twist's third component, eq. 36).
// If B_1 > |M| + B_2 + B_3 + ..., theta' is positive on one arc and negative on the other, so every
// stable zero lies in one narrow arc (one zero, where theta' is monotonic there), pulled at order B_1.
// If the pi-periodic part (M, B_2, B_4, ...) dominates, the stable zeros come in pairs about a half turn
// apart and so do the unstable ones between them: each stable zero's basin (the arc between its two
// unstable neighbours) is then close to half the turn, and one zero can be made unique only by tuning M
// onto a saddle-node of that part, which leaves a bottleneck of |theta'| ~ B_1 where its twin was.
//
// So this measures, for fig4's part and for scenes/foot.json (the same triangle with unequal friction,
// which a translating plate turns like a weathervane: the control, where the measure must find a strong
// first harmonic), the largest B_1 / (|M| + B_2 + ... + B_6 + 1e-3 rad/s) that COBYLA finds over the rigid
// design's space: cosine and sine coefficients of harmonics n = 1, 2 on x, y, z, rx, ry, rz (24), each
// harmonic within 20 m/s^2 / 150 rad/s^2, no flight over the region widened by the part's reach
// (vertical_margin >= 0.2), |coning| <= 1e-4 rad/s -- the constraints `plate design` keeps. theta' from a
// ring of 12 orientations at the centre (harmonics up to 6; the field's own noise ~1e-6 rad/s).
// Prints per start the harmonics found, per part the best, and the wall time with the machine named.
#include "plate/design.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace plate;

namespace {

constexpr int kRing = 12;
constexpr int kParams = 24;
const Axis kAxes[6] = {Axis::x, Axis::y, Axis::z, Axis::rx, Axis::ry, Axis::rz};

// Parameter 4 a + 2 (n - 1) + {0, 1}: the cosine and sine coefficients of axis a's harmonic n.
PlateMotion motion(const std::vector<double>& p, double T) {
    PlateMotion u;
    u.T = T;
    for (int a = 0; a < 6; ++a)
        for (int n = 1; n <= 2; ++n) {
            const double c = p[4 * a + 2 * (n - 1)], s = p[4 * a + 2 * (n - 1) + 1];
            u.harmonics.push_back({kAxes[a], n, std::hypot(c, s), std::atan2(c, s)});   // c cos + s sin
        }
    return u;
}

// The measure: B_1 / (|M| + B_2 + ... + B_6 + 1e-3 rad/s) (the floor keeps a motion that turns
// nothing from scoring).
double ratio(const OrientationHarmonics& h) { return h.defined ? h.first() / (h.rest() + 1e-3) : -1.0; }

struct Search {
    Scene part;
    DesignOptions limits;   // the defaults: 20 / 150, region 0.05 m, flight margin 0.2
    LimitCycleOptions cyc = DesignOptions::cycle_defaults();
    double half_width = 0;
    long evaluations = 0;
    std::string lines;
};

double objective(const std::vector<double>& p, std::vector<double>&, void* data) {
    Search& s = *static_cast<Search*>(data);
    ++s.evaluations;
    Scene sc = s.part;
    sc.plate = motion(p, s.part.plate.T);
    return ratio(orientation_harmonics(sc, Vec2::Zero(), s.cyc, kRing));
}

struct Bound {
    Search* s;
    int k;   // 0..11: harmonic k's amplitude; 12: flight; 13, 14: coning either way
};
double constraint(const std::vector<double>& p, std::vector<double>&, void* data) {
    const Bound& b = *static_cast<Bound*>(data);
    if (b.k < 12) return std::hypot(p[2 * b.k], p[2 * b.k + 1]) / (b.k < 6 ? b.s->limits.lin_limit : b.s->limits.ang_limit) - 1;
    const PlateMotion u = motion(p, b.s->part.plate.T);
    if (b.k == 12) return b.s->limits.flight_margin - vertical_margin(u, b.s->part.g, b.s->half_width);
    return (b.k == 13 ? 1 : -1) * coning_rate(u) / 1e-4 - 1;
}

// Starts: seeded normal coefficients (a tenth of each limit), shrunk until feasible.
OrientationHarmonics search(Search& s, int starts, int evaluations, std::uint64_t seed) {
    s.half_width = flight_region(s.part, s.limits);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0, 1);
    OrientationHarmonics best;
    char buf[256];
    for (int start = 0; start < starts; ++start) {
        std::vector<double> p(kParams);
        std::vector<double> unused;
        std::vector<Bound> bounds;
        for (int k = 0; k < 15; ++k) bounds.push_back({&s, k});
        for (double scale = 0.1;; scale *= 0.8) {
            for (int i = 0; i < kParams; ++i) p[i] = scale * (i < 12 ? s.limits.lin_limit : s.limits.ang_limit) * normal(rng);
            bool feasible = true;
            for (Bound& b : bounds) feasible = feasible && constraint(p, unused, &b) <= 0;
            if (feasible) break;
        }
        nlopt::opt o(nlopt::LN_COBYLA, kParams);
        o.set_max_objective(objective, &s);
        for (Bound& b : bounds) o.add_inequality_constraint(constraint, &b, 1e-9);
        o.set_maxeval(evaluations);
        double f = 0;
        try {
            o.optimize(p, f);
        } catch (const std::exception&) {   // (NLopt's roundoff-limited stop keeps p)
        }
        Scene sc = s.part;
        sc.plate = motion(p, s.part.plate.T);
        const OrientationHarmonics h = orientation_harmonics(sc, Vec2::Zero(), s.cyc, kRing);
        if (!h.defined) {
            s.lines += s.part.name + " start " + std::to_string(start) + ": a cycle on the ring did not converge\n";
            continue;
        }
        std::snprintf(buf, sizeof buf, "%-10s %5d %+9.5f %9.5f %9.5f %9.5f %9.5f %9.2f %9.3f %+10.1e\n", s.part.name.c_str(),
                      start, h.mean, h.amplitude[1], h.amplitude[2], h.amplitude[3], h.amplitude[4], ratio(h),
                      vertical_margin(sc.plate, sc.g, s.half_width), coning_rate(sc.plate));
        s.lines += buf;
        if (!best.defined || ratio(h) > ratio(best)) best = h;
    }
    return best;
}

}  // namespace

int main(int argc, char** argv) {
    const int starts = argc > 1 ? std::atoi(argv[1]) : 4;
    const int evaluations = argc > 2 ? std::atoi(argv[2]) : 400;
    std::printf("machine: %s\n", machine_description().c_str());
    std::printf("theta' on 12 orientations at the centre; COBYLA over x..rz, n = 1, 2 (24 coefficients), %d starts x %d "
                "evaluations per part, seed 1; limits 20 m/s^2, 150 rad/s^2, flight 0.2 g, |coning| <= 1e-4 rad/s\n",
                starts, evaluations);
    Search parts[2];
    parts[0].part = load_scene(PLATE_SOURCE_DIR "/scenes/fig4.json");
    parts[1].part = load_scene(PLATE_SOURCE_DIR "/scenes/foot.json");
    OrientationHarmonics best[2];
    const auto t0 = std::chrono::steady_clock::now();
    std::thread other([&] { best[1] = search(parts[1], starts, evaluations, 1); });
    best[0] = search(parts[0], starts, evaluations, 1);
    other.join();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%-10s %5s %9s %9s %9s %9s %9s %9s %9s %10s\n", "part", "start", "M", "B1", "B2", "B3", "B4", "ratio",
                "margin", "coning");
    std::printf("%s%s", parts[0].lines.c_str(), parts[1].lines.c_str());
    std::printf("[rad/s; ratio = B1 / (|M| + B2 + ... + B6 + 1e-3); above 1 (the 1e-3 left out): every stable zero in one arc]\n");
    for (int i = 0; i < 2; ++i)
        std::printf("best %-10s ratio %.2f: B1 %.5f rad/s against |M| + B2 + ... + B6 = %.5f (%ld evaluations)\n",
                    parts[i].part.name.c_str(), ratio(best[i]), best[i].first(), best[i].rest(),
                    parts[i].evaluations);
    std::printf("foot / fig4: best B1 %.0fx, best ratio %.0fx; wall %.1f s on 2 threads (one part each)\n",
                best[1].first() / best[0].first(), ratio(best[1]) / ratio(best[0]), wall);
    return 0;
}
