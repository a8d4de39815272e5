// plate bench: the speed-accuracy study, written into the report in DIR (--peers: Bullet, ODE and
// MuJoCo beside plate).
#include "commands.hpp"

#include "report.hpp"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

namespace plate::cli {
namespace {

struct BenchArgs : Options {
    std::string out, source;
    bool full = false, peers = false;
    explicit BenchArgs(CLI::App& app)
        : Options(app, "bench", "the speed-accuracy study, written into the report in DIR (--full: the long campaign)",
                  "The speed-accuracy study: work-precision charts (every method and friction treatment on (a) an\n"
                  "asymptotic twist of fig4, (b) fig4's 20 s full-dynamics trajectory, (c) a near-sticking twist of\n"
                  "fig6) against reference solutions; the limit-cycle solvers on fig4's field against period-by-\n"
                  "period RK4; failure maps; the model hierarchy. Writes the charts into DIR and the section into\n"
                  "DIR/index.html (the report's page if `plate report --out DIR` wrote one). Quick by default\n"
                  "(minutes); --full sweeps more settings. --peers: instead, Bullet, ODE and MuJoCo beside plate on\n"
                  "the same questions (the engines found at build time; quick unless --full).\n") {
        text("--out", out, "DIR", "the report's folder; required");
        flag("--full", full, "the long campaign");
        flag("--peers", peers,
             "instead: Bullet, ODE and MuJoCo beside plate (bench/peers/study.py, the engines this build found)");
        text("--source", source, "ROOT", "the project folder (default: the one this program was built from)");
    }
};

int cmd_bench(const BenchArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    if (a.peers) {
        // The peers study runs the engines' program built beside this one (bench/peers), charted by
        // its script: both live in the build tree, so an installed plate has no peers.
        std::error_code ec;
        const std::filesystem::path dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
        const std::string source = a.has("--source") ? a.source : std::string(PLATE_SOURCE_DIR);
        if (ec || !std::filesystem::exists(dir / "bench_peers"))
            throw UsageError(
                "--peers: no bench_peers beside this plate (no peer engine was found when it was built: "
                "install libbullet-dev, libode-dev or libmujoco-dev and rebuild)");
        auto quote = [](const std::string& x) {   // for the shell, quotes and all
            std::string q = "'";
            for (char ch : x) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
            return q + "'";
        };
        const std::string cmd = "/usr/bin/python3 " + quote(source + "/bench/peers/study.py") + " --out " + quote(a.out) +
                                " --build " + quote(dir.string()) + (a.full ? "" : " --quick");
        const int rc = std::system(cmd.c_str());
        if (rc != 0) throw std::runtime_error("the peers study failed (" + cmd + ")");
        // (the study writes the section to DIR/data and splices it into the report's page if there is one)
        const bool page = std::filesystem::exists(std::filesystem::path(a.out) / "index.html");
        cio.err << "bench: " << a.out << "/data/peers_section.html (peers"
                << (page ? "; spliced into " + a.out + "/index.html)" : "; no report page in " + a.out + " to splice it into)")
                << std::endl;
        return 0;
    }
    report::SpeedOptions o;
    o.out = a.out;
    o.source_dir = a.has("--source") ? a.source : data_root();
    o.full = a.full;
    report::write_speed_study(o);
    cio.err << "bench: " << o.out << "/index.html" << std::endl;
    return 0;
}

}   // namespace

Command add_bench(CLI::App& app) { return make_command<BenchArgs>(app, cmd_bench); }

}   // namespace plate::cli
