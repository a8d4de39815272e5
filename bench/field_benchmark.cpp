// Benchmark: fig4's asymptotic twist field (343 configurations) at 1e-6 relative accuracy.
// Prints wall time, right-hand-side evaluations, ns per evaluation, periods per configuration,
// the accuracy reached (against a tight-tolerance reference field) and the machine.
// Not a test: nothing here passes or fails.
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"
#include "plate/study.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

using namespace plate;


int main(int argc, char** argv) {
    const std::string path = argc > 1 ? argv[1] : PLATE_SOURCE_DIR "/scenes/fig4.json";
    const Scene sc = load_scene(path);
    std::printf("machine: %s\n", machine_description().c_str());
    std::printf("scene: %s, v_ref = %.4g m/s (errors below are relative to v_ref, angular rates times rho)\n", sc.name.c_str(),
                sc.v_ref());

    // One right-hand side: the generic 6x6 solve of (32).
    {
        Workspace ws;
        const PlateState ps = plate_state(sc.plate, 0.013, Dynamics::U);
        const int n = 2'000'000;
        Vec3 qd(0.1, -0.05, 2);
        const auto t0 = std::chrono::steady_clock::now();
        for (int i = 0; i < n; ++i) {
            qd[0] += 1e-9;
            accelerations(sc, Dynamics::ReducedU, Vec3(0.01, 0.02, 0.3), qd, ps, ws);
        }
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("rhs (generic Eigen 6x6 LU): %.1f ns per evaluation (%d evaluations, checksum %.3g)\n", 1e9 * s / n, n,
                    ws.qdd.sum());
    }

    FieldOptions ref_opt;
    ref_opt.cycle.integration.rtol = 1e-12;
    ref_opt.cycle.tol = 1e-11;
    const Field ref = compute_field(sc, GridSpec{}, ref_opt);

    for (int threads : {1, 0}) {
        FieldOptions opt;   // defaults: rtol 1e-8, cycle tol 1e-7
        opt.threads = threads;
        const Field f = compute_field(sc, GridSpec{}, opt);
        double periods = 0;
        int converged = 0;
        for (const auto& p : f.points) {
            periods += p.periods;
            converged += p.converged;
        }
        std::printf(
            "field %dx%dx%d, %d thread(s): %.3f s wall, %ld rhs evaluations, %.1f ns per evaluation "
            "(wall x threads / evaluations), %.1f periods per configuration, %d/%zu converged, "
            "max error %.2g\n",
            f.grid.nx, f.grid.ny, f.grid.nth, f.threads, f.seconds, f.rhs_evals, 1e9 * f.seconds * f.threads / f.rhs_evals,
            periods / f.points.size(), converged, f.points.size(), field_max_error(sc, f, ref));
    }
    std::printf("reference field (rtol 1e-12, tol 1e-11): %.3f s, %ld rhs evaluations\n", ref.seconds, ref.rhs_evals);
    return 0;
}
