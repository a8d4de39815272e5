// plate field: the asymptotic twist field on a grid over (s_x, s_y, theta), JSON or CSV.
#include "commands.hpp"

#include "plate/output.hpp"

#include <string>

namespace plate::cli {
namespace {

struct FieldArgs : Options {
    std::string scene, format = "json", out = "-";
    GridArgs grid;
    CycleArgs cycle;
    MeasuredArgs measured;
    long max_work = kDefaultFieldWork;
    explicit FieldArgs(CLI::App& app)
        : Options(app, "field", "asymptotic twist field on a grid over (s_x, s_y, theta), JSON or CSV",
                  "Asymptotic twist field on a regular grid (default 7x7x7 over [-0.05,0.05]^2 m x [0, 2pi)),\n"
                  "theta covering a full turn. Point parts: asymptotic velocity field on (s_x, s_y).\n"
                  "Configurations run in parallel on all cores (--threads). Output to stdout or --out FILE.\n"
                  "--max-work N: the budget in right-hand sides (default 2e9); the work is estimated up front\n"
                  "from one cycle and a larger field is refused with the estimate (exit 2); a field that spends\n"
                  "it anyway stops there (exit 1, no output).\n") {
        scene_file(scene);
        add_grid_options(*this, grid);
        text("--format", format, "json|csv", "the output's format (default json)");
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--max-work", max_work, 1000, kMaxWorkLimit, "work budget of the field, right-hand sides");
        add_cycle_options(*this, cycle);
        add_measured_options(*this, measured);
    }
};

int cmd_field(const FieldArgs& a, Io& cio) {
    launched_farm(cio, a.grid.threads);
    const Scene sc = measured_arg(a, a.measured, scene_arg(a.scene, cio), cio);
    const GridSpec g = grid_opts(a, a.grid);
    const std::string format = a.format;
    if (format != "json" && format != "csv") throw UsageError("--format: expected json or csv");
    const Field f = bounded_field(sc, g, cycle_opts(a, a.cycle), a.grid.threads, a.max_work, cio);
    if (cio.farm && !cio.farm->root()) return 0;   // (rank 0 writes)
    write_file_atomic(
        a.out,
        [&](std::ostream& out) {
            if (format == "csv") {
                write_field_csv(out, f);
            } else {
                nlohmann::json j = to_json(sc, f);
                if (cio.farm) j["mpi"] = cio.farm->describe();
                out << j.dump(1) << "\n";
            }
        },
        cio.out);
    return 0;
}

}   // namespace

Command add_field(CLI::App& app) { return make_command<FieldArgs>(app, cmd_field); }

}   // namespace plate::cli
