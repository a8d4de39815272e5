// plate twist: the asymptotic twist (36) at one configuration, as JSON.
#include "commands.hpp"

#include "plate/output.hpp"

#include <iostream>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct TwistArgs : Options {
    std::string scene;
    std::vector<double> at, twist;
    CycleArgs cycle;
    MeasuredArgs measured;
    explicit TwistArgs(CLI::App& app)
        : Options(app, "twist", "asymptotic twist (36) at one configuration, as JSON",
                  "Asymptotic twist (36) of the reduced U-dynamics limit cycle at (SX, SY, THETA), starting\n"
                  "from the part twist --twist (default: at rest relative to the plate). Point parts: --at SX SY.\n"
                  "--tol: accepted distance to the cycle relative to the slip-speed scale (default 1e-7);\n"
                  "--rtol: integrator tolerance (default 1e-8); --max-periods (default 400); --max-rhs: the work\n"
                  "budget of the cycle in right-hand sides (default 2e6, about 0.3 s; then stop: step_limit).\n") {
        scene_file(scene);
        numbers("--at", at, 2, 3, "SX SY THETA", "the configuration (point parts: SX SY); required");
        numbers("--twist", twist, 2, 3, "VX VY OMEGA", "the part's twist relative to the plate at the start");
        deprecated("--from", "--twist");
        add_cycle_options(*this, cycle);
        add_measured_options(*this, measured);
    }
};

int cmd_twist(const TwistArgs& a, Io& cio) {
    const Scene sc = measured_arg(a, a.measured, scene_arg(a.scene, cio), cio);
    const Vec3 q = config_arg(a, "--at", a.at, sc, true);
    const Vec3 qd = config_arg(a, "--twist", a.twist, sc, false);
    const LimitCycleSummary lc = limit_cycle(sc, q, cycle_opts(a, a.cycle), qd);
    cio.out << to_json(sc, q, lc).dump(2) << std::endl;
    return 0;
}

}   // namespace

Command add_twist(CLI::App& app) { return make_command<TwistArgs>(app, cmd_twist); }

}   // namespace plate::cli
