// Benchmark: nanoseconds per right-hand-side evaluation (q'', n from A z = b) of the generated
// kernels against the hand-written generic Eigen solve, measured in one run on one core.
// One evaluation = slip directions from the twist, b of (32), the solve, q''. The plate's
// u(t) is evaluated once outside the loop (it is the same for every method).
#include "plate/dynamics.hpp"
#include "plate/output.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

using namespace plate;

namespace {


template <class F>
double ns_once(const Scene& sc, Dynamics level, F&& f, double& checksum) {
    Workspace ws;
    const PlateState ps = plate_state(sc.plate, 0.013, level);
    const Vec3 q(0.01, 0.02, 0.3);
    Vec3 qd(0.1, -0.05, 2);
    const int n = 1'000'000;
    f(sc, level, q, qd, ps, ws);   // warm up, prepare
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) {
        qd[0] = 0.1 + 1e-7 * (i & 1023);   // slip directions change every call
        f(sc, level, q, qd, ps, ws);
        checksum += ws.qdd[0];
    }
    return 1e9 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n;
}

// The smallest of five timings of 10^6 evaluations: the machine is shared, and the minimum is
// the least disturbed measurement.
template <class F>
double ns_per_eval(const Scene& sc, Dynamics level, F&& f, double& checksum) {
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) best = std::min(best, ns_once(sc, level, f, checksum));
    return best;
}

}  // namespace

int main() {
    std::printf("machine: %s (timed on one core)\n", machine_description().c_str());
    const Scene thick = load_scene(PLATE_SOURCE_DIR "/scenes/fig4.json");
    Scene thin = random_scene(8, RandomSceneOptions{true});
    const Scene point = load_scene(PLATE_SOURCE_DIR "/scenes/fig1_point.json");
    double cs = 0;
    const double ref_thick = ns_per_eval(thick, Dynamics::ReducedU, accelerations_reference, cs);
    const double gen_thick = ns_per_eval(thick, Dynamics::ReducedU, accelerations, cs);
    const double ref_thin = ns_per_eval(thin, Dynamics::ReducedU, accelerations_reference, cs);
    const double gen_thin = ns_per_eval(thin, Dynamics::ReducedU, accelerations, cs);
    const double ref_point = ns_per_eval(point, Dynamics::ReducedU, accelerations_reference, cs);
    const double gen_point = ns_per_eval(point, Dynamics::ReducedU, accelerations, cs);
    const double ref_full = ns_per_eval(thick, Dynamics::Full, accelerations_reference, cs);
    const double gen_full = ns_per_eval(thick, Dynamics::Full, accelerations, cs);
    std::printf("%-34s %10s %10s %8s\n", "right-hand side (reduced U unless said)", "generated", "generic", "ratio");
    std::printf("%-34s %8.1f ns %8.1f ns %7.2fx\n", "thick part (fig4, 3x3 reduced LU)", gen_thick, ref_thick, ref_thick / gen_thick);
    std::printf("%-34s %8.1f ns %8.1f ns %7.2fx\n", "thin part ((38) inverse)", gen_thin, ref_thin, ref_thin / gen_thin);
    std::printf("%-34s %8.1f ns %8.1f ns %7.2fx\n", "point part (explicit)", gen_point, ref_point, ref_point / gen_point);
    std::printf("%-34s %8.1f ns %8.1f ns %7.2fx\n", "thick part, full dynamics (31)", gen_full, ref_full, ref_full / gen_full);
    std::printf("(checksum %.6g)\n", cs);
    return 0;
}
