// Benchmark: what gradients buy the design's local search. The point-part sink of issue 16 (fig1_point,
// (0.02, -0.01), limits 15 m/s^2 and 100 rad/s^2) designed with COBYLA (derivative-free) and with
// SLSQP on forward-difference gradients, from the same seeded starts and the same evaluation budget
// (each gradient costs n + 1 objective evaluations, each a few limit cycles). Prints, per seed and
// method, the convergence rate reached, the evaluations and the limit cycles, wall time, and whether
// the design verified; then the ratio of evaluations. Not a test: nothing here passes or fails.
#include "plate/design.hpp"
#include "plate/scene_io.hpp"
#include "plate/output.hpp"

#include <chrono>
#include <cstdio>

using namespace plate;

int main() {
    const Scene part = load_scene(PLATE_SOURCE_DIR "/scenes/fig1_point.json");
    std::printf("machine: %s\n", machine_description().c_str());
    std::printf("point-part sink at (0.02, -0.01), limits 15 / 100; 4 starts x 400 evaluations, 2 threads\n");
    std::printf("%-6s %-22s %10s %12s %12s %10s %9s\n", "seed", "local search", "rate[1/s]", "evaluations", "cycles", "wall[s]",
                "verified");
    double ev[2] = {0, 0}, rate[2] = {0, 0};
    for (std::uint64_t seed : {1, 2, 3}) {
        for (int m = 0; m < 2; ++m) {
            DesignOptions o;
            o.lin_limit = 15;
            o.ang_limit = 100;
            o.starts = 4;
            o.local_evaluations = 400;
            o.threads = 2;
            o.seed = seed;
            o.local = m == 0 ? DesignOptions::Local::Cobyla : DesignOptions::Local::SlsqpFiniteDifferences;
            DesignTarget t;
            t.at = Vec2(0.02, -0.01);
            const auto t0 = std::chrono::steady_clock::now();
            const DesignSummary d = design(part, t, o);
            const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::printf("%-6llu %-22s %10.4f %12ld %12ld %10.2f %9s\n", static_cast<unsigned long long>(seed),
                        m == 0 ? "COBYLA" : "SLSQP, FD gradients", d.rate, d.evaluations, d.cycles, wall,
                        d.verified ? "yes" : "no");
            ev[m] += static_cast<double>(d.evaluations);
            rate[m] += d.rate / 3;
        }
    }
    std::printf("mean rate: COBYLA %.4f, SLSQP %.4f 1/s; evaluations SLSQP / COBYLA = %.2f\n", rate[0], rate[1], ev[1] / ev[0]);
    return 0;
}
