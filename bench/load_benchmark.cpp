// Load (issue 18, point 7; a benchmark, not a test): 10^4 consecutive twist calls through the library
// and a 10^5-configuration field, twice, with the resident memory (VmRSS) and its peak (VmHWM) read
// from /proc after each block. Flat memory: the peak after the last block equals the peak after the
// first; no slowdown: the last block's time against the first's, measured in this run.
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

using namespace plate;

namespace {

long status_kb(const char* key) {
    std::ifstream in("/proc/self/status");
    for (std::string line; std::getline(in, line);)
        if (line.rfind(key, 0) == 0) return std::stol(line.substr(std::string(key).size()));
    return -1;
}

double since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}   // namespace

int main() {
    std::printf("machine: %s\n", machine_description().c_str());
    const Scene sc = load_scene(PLATE_SOURCE_DIR "/scenes/fig4.json");
    std::printf("start: VmRSS %ld kB, VmHWM %ld kB\n", status_kb("VmRSS:"), status_kb("VmHWM:"));

    std::printf("\n10^4 twist calls (limit_cycle from rest at seeded random configurations of fig4), blocks of 1000:\n");
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-0.05, 0.05), th(0, 2 * kPi);
    double first = 0, last = 0;
    long hwm_first = 0;
    for (int block = 0; block < 10; ++block) {
        const auto t0 = std::chrono::steady_clock::now();
        int converged = 0;
        for (int i = 0; i < 1000; ++i) converged += limit_cycle(sc, Vec3{u(rng), u(rng), th(rng)}).converged;
        const double s = since(t0);
        (block == 0 ? first : last) = s;
        if (block == 0) hwm_first = status_kb("VmHWM:");
        std::printf("  block %d: %.3f s (%d/1000 converged), VmRSS %ld kB, VmHWM %ld kB\n", block, s, converged,
                    status_kb("VmRSS:"), status_kb("VmHWM:"));
    }
    std::printf("  last block / first: %.3f; VmHWM growth after the first block: %ld kB\n", last / first,
                status_kb("VmHWM:") - hwm_first);

    std::printf("\nfield of 47x47x46 = 101614 configurations (fig4), twice:\n");
    GridSpec g;
    g.nx = g.ny = 47;
    g.nth = 46;
    double t_first = 0;
    long hwm_after_first = 0;
    for (int run = 0; run < 2; ++run) {
        const Field f = compute_field(sc, g);
        int defined = 0;
        for (const auto& p : f.points) defined += p.converged;
        std::printf("  run %d: %.2f s wall on %d threads, %d/%zu defined, VmRSS %ld kB, VmHWM %ld kB\n", run, f.seconds,
                    f.threads, defined, f.points.size(), status_kb("VmRSS:"), status_kb("VmHWM:"));
        if (run == 0) {
            t_first = f.seconds;
            hwm_after_first = status_kb("VmHWM:");
        } else
            std::printf("  second / first: %.3f; VmHWM growth in the second run: %ld kB\n", f.seconds / t_first,
                        status_kb("VmHWM:") - hwm_after_first);
    }
    return 0;
}
