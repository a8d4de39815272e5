// plate report: the verification report, DIR/index.html with SVG figures (gnuplot).
#include "commands.hpp"

#include "report.hpp"

#include <filesystem>

#include <cstdint>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct ReportArgs : Options {
    std::string out, source;
    std::uint64_t seed = 1;
    int threads = 0;
    bool quick = false;
    std::vector<std::string> sections;
    explicit ReportArgs(CLI::App& app)
        : Options(app, "report", "the verification report: DIR/index.html with SVG figures (gnuplot)",
                  "Writes DIR/index.html and its figures: the derivation and its findings, kernel equivalence,\n"
                  "Theorem 1 checks (10^4 thin, 10^3 thick parts; --quick: a few), limit surfaces, Fig. 3, and the\n"
                  "paper's fields with full-dynamics trajectories and fixed-point tables, the inverse designs, and\n"
                  "the robustness of each design in scenes/designs/ under scenes/uncertainty/ppod.json (200 draws;\n"
                  "--quick: 40), and an identification (fig1_point's part filmed at other friction, fitted, with profile\n"
                  "likelihoods), and closed-loop control against the open-loop design on the same plates and starts.\n"
                  "ROOT: the project folder (scenes/, reports/generated/), default the one this\n"
                  "program was built from. --sections computes only the named ones (derivation kernels proofs fig3\n"
                  "fields design orient fixed-point robustness identify control; the page names those left out).\n") {
        text("--out", out, "DIR", "the report's folder; required");
        flag("--quick", quick, "small campaigns and grids");
        words("--sections", sections, 1, 11, "NAME ...", "only these sections (default all)");
        whole("--seed", seed, 0, 1L << 40, "the seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        text("--source", source, "ROOT", "the project folder");
    }
};

int cmd_report(const ReportArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    report::ReportOptions o;
    o.out = a.out;
    o.source_dir = a.has("--source") ? a.source : data_root();
    o.seed = a.seed;
    o.quick = a.quick;
    o.threads = a.threads;
    try {
        report::check_sections(a.sections);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--sections: ") + e.what());
    }
    o.sections = a.sections;
    {   // the playground, when the web target was built beside this program (build/web/site)
        std::error_code ec;
        const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        if (!ec) o.playground = (exe.parent_path() / "web" / "site").string();
    }
    report::write_report(o);
    cio.err << "report: " << o.out << "/index.html" << std::endl;
    return 0;
}

}   // namespace

Command add_report(CLI::App& app) { return make_command<ReportArgs>(app, cmd_report); }

}   // namespace plate::cli
