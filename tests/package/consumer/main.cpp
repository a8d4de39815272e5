// Loads a scene and prints the asymptotic twist at one configuration, through the installed library.
#include "plate/limit_cycle.hpp"
#include "plate/scene_io.hpp"

#include <cstdio>

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    const plate::Scene sc = plate::load_scene(argv[1]);
    const plate::LimitCycleSummary lc = plate::limit_cycle(sc, plate::Vec3(0.02, 0.01, 0.5));
    std::printf("%d %.17g %.17g %.17g\n", lc.converged ? 1 : 0, lc.twist[0], lc.twist[1], lc.twist[2]);
    return lc.converged ? 0 : 1;
}
