// plate: the command-line program (apps/main.cpp runs it). See `plate --help`.
// Exit codes: 0 success; 2 bad input (usage, scene file); 3 a simulation left the model's
// assumptions (contact lost, sticking, step collapse) -- its output up to that time is kept;
// 4 a design that failed verification (nothing written); 5 a verdict of plate proofs failed (its
// JSON written); 1 any other failure.
// The commands are in apps/commands/ (one file each), their shared options in apps/options.hpp.
#include "cli.hpp"

#include "commands/commands.hpp"
#include "options.hpp"

#include "plate/farm.hpp"
#include "plate/scene_io.hpp"

#include <CLI/CLI.hpp>

#include <exception>
#include <sstream>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

const char* kAbout = "plate: sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch)\n";
const char* kFooter =
    "plate COMMAND --help for its options; plate --version\n"
    "\n"
    "SCENE is a JSON scene file (see scenes/). Units are SI. Exit codes: 0 ok, 2 bad input,\n"
    "3 a simulation left the model (a normal force reached zero: the part would fly), 4 a design that\n"
    "failed its verification, 5 a check of plate proofs that failed, 1 other failure.\n";

// The commands, in the order `plate --help` lists them: run() adds each to the command line and runs
// the one given. Adding a command: its file apps/commands/NAME.cpp (an Args struct over Options,
// holding its options and help, and its cmd_ function, exposed by add_NAME), add_NAME's declaration
// in apps/commands/commands.hpp, the file in CMakeLists.txt's plate_cli, and one line here.
using AddCommand = Command (*)(CLI::App& app);
constexpr AddCommand kCommands[] = {
    add_twist,          // plate twist
    add_field,          // plate field
    add_fixed_points,   // plate fixed-points
    add_simulate,       // plate simulate
    add_random_scene,   // plate random-scene
    add_proofs,         // plate proofs
    add_report,         // plate report
    add_bench,          // plate bench
    add_design,         // plate design
    add_sweep,          // plate sweep
    add_robustness,     // plate robustness
    add_identify,       // plate identify
    add_control,        // plate control
};

}   // namespace

int run(int argc, char** argv, std::ostream& out, std::ostream& err) {
    Io cio{out, err, nullptr};
    CLI::App app{kAbout, "plate"};
    app.get_formatter()->label("Usage", "usage");   // (as before: the help says "usage: plate ...")
    app.get_formatter()->label("SUBCOMMAND", "COMMAND");
    app.footer(kFooter);
    app.set_version_flag("--version", [] { return "plate " PLATE_VERSION " (scenes and report inputs: " + data_root() + ")"; });
    app.require_subcommand(1);
    app.allow_extras();   // (and so every command) what is left over is judged by Options::reject
    std::vector<Command> commands;
    for (AddCommand add : kCommands) commands.push_back(add(app));

    if (argc < 2) {
        cio.out << app.help();
        return 2;
    }
    const std::string cmd = argv[1];
    const bool known = !app.get_subcommands([&](const CLI::App* c) { return c->get_name() == cmd; }).empty();
    if (!known && cmd != "--help" && cmd != "-h" && cmd != "--version") {
        cio.err << "plate: unknown command '" << cmd << "'\n" << app.help();
        return 2;
    }
    // An error's exit code (2: bad input or usage, 1: anything else), reported on stderr if `print`.
    auto fail = [&](const std::exception_ptr& ep, bool print) -> int {
        std::ostringstream msg;
        int code = 1;
        try {
            std::rethrow_exception(ep);
        } catch (const CLI::ParseError& e) {
            if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success))   // --help, --version
                return app.exit(e, cio.out, cio.err);
            msg << e.what() << " (see plate " << cmd << " --help)";
            code = 2;
        } catch (const InputError& e) {
            msg << e.what();
            code = 2;
        } catch (const UsageError& e) {
            msg << e.what() << " (see plate " << cmd << " --help)";
            code = 2;
        } catch (const std::exception& e) {
            msg << "error: " << e.what();
        }
        if (print) cio.err << "plate " << cmd << ": " << msg.str() << std::endl;
        return code;
    };
    try {
        app.parse(argc, argv);
        for (const Command& c : commands) {
            if (!c.options->given()) continue;
            c.options->reject(app.remaining(true));
            for (const std::string& n : c.options->notices()) cio.err << "plate " << cmd << ": " << n << "\n";
            return c.run(cio);
        }
        return 0;   // (not reached: a command is required)
    } catch (...) {
        const std::exception_ptr ep = std::current_exception();
        // (an error before the command joined its ranks, e.g. in its scene, meets every rank alike:
        // they join now to report it once)
        if (!cio.farm && sweep::mpi_launched() && sweep::mpi_built() && fail(ep, false) == 2) cio.farm = sweep::mpi_farm(1);
        if (!cio.farm || cio.farm->ranks() == 1) return fail(ep, true);
        // Under mpirun every rank meets the same bad input: rank 0 reports it, and every rank waits
        // for that before returning 2 (the launcher ends the job at the first rank that fails). Any
        // other error is one rank's: it says which, and ends every rank.
        if (fail(ep, false) == 2) {
            if (cio.farm->root()) fail(ep, true);
            cio.farm->barrier();
            return 2;
        }
        try {
            std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            cio.err << "plate " << cmd << ": error on rank " << cio.farm->rank() << ": " << e.what() << std::endl;
        } catch (...) {
            cio.err << "plate " << cmd << ": error on rank " << cio.farm->rank() << std::endl;
        }
        cio.farm->abort(1);
        return 1;
    }
}

}   // namespace plate::cli
