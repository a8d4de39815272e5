// bench_auto: `--dynamics auto` decided up front against simply running the full model, on the
// question "where is the part after 20 s from rest" (plate simulate's auto), in one run, times
// alternating (median of five) on this machine. Speed is never asserted by tests.
#include "plate/hierarchy.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

using namespace plate;

namespace {

double seconds(const std::chrono::steady_clock::time_point& t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}   // namespace

int main() {
    std::printf("machine: %s\n\n", machine_description().c_str());
    std::printf("the 20 s question from rest at (0.02, -0.01, 0.5), model tolerance 1e-2 (of rho and radians)\n");
    struct Case {
        const char* scene;
        bool translate_only;   // the plate's rotations removed: U-dynamics drop nothing
    };
    for (const Case& c : {Case{"fig4", false}, Case{"fig4", true}, Case{"fig1", true}, Case{"fig1", false}}) {
        Scene sc = load_scene(std::string(PLATE_SOURCE_DIR) + "/scenes/" + c.scene + ".json");
        if (c.translate_only) {
            std::vector<Harmonic> keep;
            for (const auto& h : sc.plate.harmonics)
                if (h.axis == Axis::x || h.axis == Axis::y || h.axis == Axis::z) keep.push_back(h);
            sc.plate.harmonics = keep;
        }
        const Vec3 q0(0.02, -0.01, 0.5);
        const double D = 20, tol = 1e-2;
        std::vector<double> t_auto, t_full;
        std::string picked;
        double predicted = 0;
        for (int k = 0; k < 5; ++k) {
            auto t0 = std::chrono::steady_clock::now();
            const ModelEstimate est = estimate_model_errors(sc, q0, D);
            PartModel p;
            Dynamics d;
            predicted = a_priori_pick(sc, est, tol, p, d);
            const Scene s = simplified(sc, p);
            if (d == Dynamics::ReducedU)
                field_curve(s, q0, D, D);
            else
                simulate(s, d, q0, Vec3::Zero(), D, D);
            t_auto.push_back(seconds(t0));
            Rung r;
            r.part = p;
            r.dynamics = d;
            picked = r.name();
            t0 = std::chrono::steady_clock::now();
            simulate(sc, Dynamics::Full, q0, Vec3::Zero(), D, D);
            t_full.push_back(seconds(t0));
        }
        std::sort(t_auto.begin(), t_auto.end());
        std::sort(t_full.begin(), t_full.end());
        std::printf("  %-5s%s: auto picked %-12s (predicted %.2g): %.4f s; full model %.4f s; auto / full = %.2f\n", c.scene,
                    c.translate_only ? " (translating plate)" : "                   ", picked.c_str(), predicted, t_auto[2],
                    t_full[2], t_auto[2] / t_full[2]);
    }
    return 0;
}
