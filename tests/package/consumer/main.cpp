// Uses an installed plate through its three libraries: loads a scene and prints the asymptotic twist
// at one configuration (plate::plate), a design target read back from its words (plate::design), and
// a campaign's number of cases and its last case's values (plate::sweep).
#include "plate/design_target.hpp"
#include "plate/limit_cycle.hpp"
#include "plate/scene_io.hpp"
#include "plate/sweep.hpp"

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 3) return 2;
    const plate::Scene sc = plate::load_scene(argv[1]);
    const plate::LimitCycleSummary lc = plate::limit_cycle(sc, plate::Vec3(0.02, 0.01, 0.5));
    const plate::DesignTarget t = plate::parse_design_target("sink", {0.01, -0.02}, true);
    const plate::sweep::Campaign c = plate::sweep::load_campaign(argv[2]);
    const std::vector<double> last = plate::sweep::case_values(c, c.cases() - 1);
    std::printf("%d %.17g %.17g %.17g\n", lc.converged ? 1 : 0, lc.twist[0], lc.twist[1], lc.twist[2]);
    std::printf("%s %.17g %.17g\n", plate::design_target_kind(t).c_str(), t.at[0], t.at[1]);
    std::printf("%d", c.cases());
    for (double v : last) std::printf(" %.17g", v);
    std::printf("\n");
    return lc.converged ? 0 : 1;
}
