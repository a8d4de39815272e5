// Benchmark: a point part's 25 x 25 field on one thread (issue 55's target: recomputed in <= 100 ms),
// the field `plate field SCENE --grid 25 --ntheta 1 --threads 1` computes, repeated. Prints each run's
// wall time, the median and the least, right-hand-side evaluations, ns per evaluation, the machine
// and the load average, and a checksum of the field's bits (twists, periods, evaluations): two builds
// that print the same checksum computed the same field to the bit.
// Usage: bench_point_field [SCENE [RUNS [GRID]]] (default scenes/fig1_point.json, 15 runs, 25).
// Not a test: nothing here passes or fails.
#include "machine.hpp"
#include "plate/field.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

using namespace plate;

namespace {

// FNV-1a over the bytes of what a field reports per point.
std::uint64_t checksum(const Field& f) {
    std::uint64_t h = 1469598103934665603ull;
    auto add = [&h](const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    for (const FieldPoint& p : f.points) {
        add(p.twist.data(), 3 * sizeof(double));
        add(&p.periods, sizeof p.periods);
        add(&p.residual, sizeof p.residual);
        add(&p.min_normal_force, sizeof p.min_normal_force);
        add(&p.rhs_evals, sizeof p.rhs_evals);
        add(p.stick_fraction.data(), 3 * sizeof(double));
    }
    return h;
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return a + " " + b + " " + c;
}

}   // namespace

int main(int argc, char** argv) {
    const std::string path = argc > 1 ? argv[1] : PLATE_SOURCE_DIR "/scenes/fig1_point.json";
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 15;
    const int n = argc > 3 ? std::max(2, std::atoi(argv[3])) : 25;
    const Scene sc = load_scene(path);
    std::printf("machine: %s; load average before: %s\n", bench::machine().c_str(), load_average().c_str());
    GridSpec g;   // (plate field's default bounds, --grid n --ntheta 1)
    g.nx = g.ny = n;
    g.nth = 1;
    FieldOptions opt;
    opt.threads = 1;
    std::vector<double> ms;
    Field f;
    for (int r = 0; r < runs; ++r) {
        f = compute_field(sc, g, opt);
        ms.push_back(1e3 * f.seconds);
    }
    std::printf("scene %s, %d x %d, 1 thread, %d runs [ms]:", sc.name.c_str(), n, n, runs);
    for (double m : ms) std::printf(" %.1f", m);
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2];
    std::printf("\nmedian %.1f ms, least %.1f ms; %ld rhs evaluations, %.1f ns per evaluation at the median\n", median,
                sorted.front(), f.rhs_evals, 1e6 * median / f.rhs_evals);
    std::printf("field checksum %016llx; load average after: %s\n", static_cast<unsigned long long>(checksum(f)),
                load_average().c_str());
    return 0;
}
