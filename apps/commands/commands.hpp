// The commands of `plate`, one file each: apps/commands/NAME.cpp holds the command's arguments (an
// Args struct over Options: its options, its line in `plate --help` and the text of
// `plate NAME --help`) and its cmd_ function. Each is exposed here by one function that adds it to
// the command line; apps/cli.cpp's run() calls them from one table, in the order of `plate --help`.
#pragma once

#include "options.hpp"

#include <functional>
#include <memory>
#include <utility>

namespace plate::cli {

// A command added to the command line: its options (CLI11 parses into them) and its function, run
// on them once they are parsed.
struct Command {
    std::unique_ptr<Options> options;
    std::function<int(Io&)> run;
};

// The Command of Args (constructed on `app`, so adding the subcommand and its options) and `run`:
// what each add_ function below returns.
template <class Args>
Command make_command(CLI::App& app, int (*run)(const Args&, Io&)) {
    auto args = std::make_unique<Args>(app);
    const Args& a = *args;
    return {std::move(args), [&a, run](Io& cio) { return run(a, cio); }};
}

// The commands (apps/commands/NAME.cpp), each added to `app`.
Command add_twist(CLI::App& app);          // twist.cpp
Command add_field(CLI::App& app);          // field.cpp
Command add_fixed_points(CLI::App& app);   // fixed_points.cpp
Command add_simulate(CLI::App& app);       // simulate.cpp
Command add_random_scene(CLI::App& app);   // random_scene.cpp
Command add_proofs(CLI::App& app);         // proofs.cpp
Command add_report(CLI::App& app);         // report.cpp
Command add_bench(CLI::App& app);          // bench.cpp
Command add_design(CLI::App& app);         // design.cpp
Command add_sweep(CLI::App& app);          // sweep.cpp
Command add_robustness(CLI::App& app);     // robustness.cpp
Command add_identify(CLI::App& app);       // identify.cpp
Command add_control(CLI::App& app);        // control.cpp

}   // namespace plate::cli
