// plate robustness: where the part goes on the plates a real rig may be -- outcome probabilities,
// the fixed point's spread, first-order sensitivities and arrival times under an uncertainty spec.
#include "commands.hpp"

#include "plate/farm.hpp"
#include "plate/output.hpp"
#include "plate/robustness.hpp"

#include <cstdio>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct RobustnessArgs : Options {
    std::string scene, spec, out = "-", draws_dir;
    std::vector<double> target;
    GridArgs grid;
    CycleArgs cycle;
    RobustnessOptions o;
    MeasuredArgs measured;
    explicit RobustnessArgs(CLI::App& app)
        : Options(app, "robustness",
                  "outcome probabilities, fixed-point spread and sensitivities of a plate motion under an uncertainty spec",
                  "Draws --draws perturbed plates and parts from the uncertainty spec (JSON: friction, mass, inertia,\n"
                  "contacts, centre of mass, per-harmonic amplitude and phase, unmodelled harmonics, period; see\n"
                  "scenes/uncertainty/ and numeric/include/plate/uncertainty.hpp) and for each finds the field's fixed\n"
                  "points on the grid. Outcomes: unique (one stable fixed point, at the target), competing (another\n"
                  "attractor too), none (no stable point at the target), contact lost, failed; each with its share and\n"
                  "a 95 % interval. The target (--target; default the nominal field's one stable fixed point) is\n"
                  "matched within 10 mm and 0.5 rad. Spread: the fixed point's mean offset and 95 % radius [mm] and\n"
                  "angle [rad] over the draws, against the first-order prediction of the implicit function theorem\n"
                  "(sensitivities d q* / d p per parameter, with its share of the variance) and each draw's linear\n"
                  "prediction. Arrival: from --starts seeded starts, the time the field's integral curve takes to come\n"
                  "within 5 mm and 0.05 rad of the target (at most --horizon s), and the full dynamics' for the first\n"
                  "--full-draws draws. --measured FILE --harmonics N replaces the scene's plate motion by a measured\n"
                  "cycle (CSV: t,x,y,z,rx,ry,rz; numeric/include/plate/measured_cycle.hpp). Draws run in parallel\n"
                  "(--threads; under mpirun over the ranks); the same seed gives the same result. JSON to stdout or --out;\n"
                  "--write-draws DIR also writes each drawn scene (DIR/draw_INDEX.json), to run through any command.\n") {
        scene_file(scene);
        text("--uncertainty", spec, "SPEC.json", "the uncertainty spec; required");
        whole("--draws", o.draws, 1, 1'000'000, "draws");
        numbers("--target", target, 2, 3, "X Y THETA", "the fixed point followed [m, m, rad] (default: the nominal's one)");
        whole("--starts", o.starts, 0, 10'000, "seeded starts of the arrival runs");
        number("--horizon", o.horizon, "the longest arrival followed [s]");
        number("--curve-step", o.curve_step, "RK4 step of the field's integral curves [s]");
        whole("--full-draws", o.full_draws, 0, 1'000'000, "draws also run in full dynamics from the starts");
        add_measured_options(*this, measured);
        text("--out", out, "FILE", "the output file (default: standard output)");
        text("--write-draws", draws_dir, "DIR", "also write each drawn scene as DIR/draw_INDEX.json (a new folder)");
        add_grid_options(*this, grid);
        add_cycle_options(*this, cycle);
    }
};

int cmd_robustness(const RobustnessArgs& a, Io& cio) {
    launched_farm(cio, a.grid.threads);
    if (!a.has("--uncertainty")) throw UsageError("missing --uncertainty SPEC.json");
    const Scene sc = measured_arg(a, a.measured, scene_arg(a.scene, cio), cio);
    const UncertaintySpec spec = parse_uncertainty(input_text(a.spec, "uncertainty spec", cio), a.spec);
    RobustnessOptions o = a.o;
    if (!(o.horizon > 0)) throw UsageError("--horizon: expected a positive number of seconds");
    if (a.has("--write-draws")) {   // (before the run, as rank 0 sees it: another run's draws are not overwritten)
        std::string seen = "new";
        std::error_code ec;
        if ((!cio.farm || cio.farm->root()) && std::filesystem::exists(a.draws_dir, ec)) seen = "exists";
        if (cio.farm && cio.farm->ranks() > 1) cio.farm->broadcast(seen);
        if (seen != "new") throw UsageError("--write-draws: " + a.draws_dir + " exists (give a new folder)");
    }
    if (!(o.curve_step > 0 && o.curve_step <= o.horizon))
        throw UsageError("--curve-step: expected a positive number of seconds, at most --horizon");
    o.fixed.cycle = cycle_opts(a, a.cycle);
    o.grid = grid_opts(a, a.grid);
    o.threads = a.grid.threads;
    if (a.has("--target")) o.target = config_arg(a, "--target", a.target, sc, true);
    if (cio.farm) o.tasks = sweep::farm_tasks(*cio.farm);
    ProgressPrinter prog{"robustness draws"};
    prog.to = &cio.err == &std::cerr && progress_wanted() && (!cio.farm || cio.farm->root()) ? &cio.err : nullptr;
    o.progress = std::ref(prog);
    RobustnessSummary s;
    try {
        s = robustness(sc, spec, o);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string(a.scene) + ": " + e.what());
    }
    if (cio.farm && !cio.farm->root()) return 0;
    if (a.has("--write-draws")) {   // (each file written whole or not at all; a draw is a function of (seed, index))
        std::error_code ec;
        std::filesystem::create_directories(a.draws_dir, ec);
        if (ec) throw std::runtime_error(a.draws_dir + ": cannot create the folder: " + ec.message());
        for (int i = 0; i < o.draws; ++i)
            write_file_atomic(a.draws_dir + "/draw_" + std::to_string(i) + ".json", [&](std::ostream& out) {
                out << scene_to_json(draw(sc, spec, static_cast<std::uint64_t>(i))).dump(2) << "\n";
            });
    }
    nlohmann::json j = robustness_json(s, o, spec);
    if (cio.farm) j["mpi"] = cio.farm->describe();
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    const int n = static_cast<int>(s.draws.size());
    char line[200];
    std::snprintf(line, sizeof line, "plate robustness: %s: unique in %d of %d draws; 95 %% radius %.3g mm", a.scene.c_str(),
                  s.counts[0], n, 1e3 * s.radius95);
    cio.err << line;
    if (!s.sensitivities.empty()) {
        std::snprintf(line, sizeof line, " (first order %.3g mm)", 1e3 * s.predicted_radius95);
        cio.err << line;
    }
    std::snprintf(line, sizeof line, "; %.1f s\n", s.seconds);
    cio.err << line;
    return 0;
}

}   // namespace

Command add_robustness(CLI::App& app) { return make_command<RobustnessArgs>(app, cmd_robustness); }

}   // namespace plate::cli
