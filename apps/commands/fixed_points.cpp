// plate fixed-points: the zeros of the field, refined and classified (stable, unstable, saddle, centre;
// lines), the regions where the part sticks and the rotating attractors.
#include "commands.hpp"

#include "plate/output.hpp"

#include <algorithm>
#include <string>

namespace plate::cli {
namespace {

struct FixedPointsArgs : Options {
    std::string scene, out = "-";
    GridArgs grid;
    CycleArgs cycle;
    MeasuredArgs measured;
    long max_work = kDefaultFieldWork;
    explicit FixedPointsArgs(CLI::App& app)
        : Options(app, "fixed-points",
                  "zeros of the field, refined and classified (stable, unstable, saddle, centre; lines); stuck regions; rotating "
                  "attractors",
                  "Computes the field, finds cells where every component changes sign, refines the zeros\n"
                  "by Gauss-Newton, classifies them by the Jacobian's eigenvalues (stable, unstable, saddle)\n"
                  "and reports curves of zeros as lines. A centre: eigenvalues whose real parts are zero within\n"
                  "the difference Jacobian's own error (eigen_error, from two steps). Configurations where the part\n"
                  "does not move are reported as stuck regions with their extent, not refined; orbits where the\n"
                  "position returns while theta turns once (rigid parts) as rotating attractors with their rate\n"
                  "[rad/s]; on a plate motion that only heaves and yaws, the part turning about its point `pivot`\n"
                  "held on the plate's axis, its position circling at `radius` (fig6: about its tip contact).\n"
                  "The summary warns when the grid may be too coarse, and names a finer one.\n"
                  "JSON to stdout or --out FILE. --max-work as for field;\n"
                  "the refinement's own budget is the smaller of it and 2e7 right-hand sides.\n") {
        scene_file(scene);
        add_grid_options(*this, grid);
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--max-work", max_work, 1000, kMaxWorkLimit, "work budget of the field, right-hand sides");
        add_cycle_options(*this, cycle);
        add_measured_options(*this, measured);
    }
};

int cmd_fixed_points(const FixedPointsArgs& a, Io& cio) {
    launched_farm(cio, a.grid.threads);
    const Scene sc = measured_arg(a, a.measured, scene_arg(a.scene, cio), cio);
    const LimitCycleOptions cycle = cycle_opts(a, a.cycle);
    const GridSpec g = grid_opts(a, a.grid);
    const Field f = bounded_field(sc, g, cycle, a.grid.threads, a.max_work, cio);
    if (cio.farm && !cio.farm->root()) return 0;   // (rank 0 refines the zeros and writes)
    FixedPointOptions fpo;                         // (the refinement has its own budget)
    fpo.cycle = cycle;
    if (a.has("--max-work")) fpo.max_rhs_evaluations = std::min(fpo.max_rhs_evaluations, a.max_work);
    const FixedPoints fp = find_fixed_points(sc, f, fpo);
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << to_json(sc, fp).dump(2) << "\n"; }, cio.out);
    return 0;
}

}   // namespace

Command add_fixed_points(CLI::App& app) { return make_command<FixedPointsArgs>(app, cmd_fixed_points); }

}   // namespace plate::cli
