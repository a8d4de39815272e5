#include "report.hpp"
#include "report_html.hpp"
#include "report_sections.hpp"

#include "plate/output.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

namespace {

// The sections run apart from the report (their anchors stand before their markers in the page).
const std::pair<const char*, const char*> kStudies[] = {{"speed", "Speed and accuracy (plate bench)"},
                                                        {"peers", "Side by side with Bullet, ODE and MuJoCo"},
                                                        {"campaigns", "Campaigns (bench/scaling.py)"},
                                                        {"mutations", "Mutation score (scripts/mutants.py)"}};

// The contents list and the verdict table at the top of the page: each check the page states, linked.
std::string contents_and_verdicts(const Ctx& c) {
    std::ostringstream o;
    o << "<nav><h2 id=\"contents\">Contents</h2><ol>\n<li><a href=\"#verdicts\">Verdicts</a></li>\n";
    for (const auto& [id, title] : c.contents) o << "<li><a href=\"#" << id << "\">" << esc(title) << "</a></li>\n";
    for (const auto& [id, title] : kStudies) o << "<li><a href=\"#" << id << "\">" << esc(title) << "</a></li>\n";
    o << "<li><a href=\"#timings\">Time per part</a></li>\n</ol></nav>\n";
    int failed = 0, checks = 0, printed = 0, differ = 0;
    for (const auto& k : c.checks) {
        (k.paper ? printed : checks) += 1;
        (k.paper ? differ : failed) += !k.ok;
    }
    o << "<h2 id=\"verdicts\">Verdicts</h2>\n<p>" << checks << (checks == 1 ? " check" : " checks") << " stated in this run: "
      << (failed == 0 ? std::string("<span class=\"pass\">all pass</span>")
                      : "<span class=\"fail\">" + std::to_string(failed) + " failed</span>")
      << ". " << printed << " of the paper's printed equations compared with the derivation: " << differ
      << " differ, each row saying why (findings on the print, not failures). Each line links to where the page states "
         "it, with its evidence. The studies run apart (speed, peers, campaigns, mutation score) state their verdicts in "
         "their own sections.</p>\n"
      << "<table id=\"verdict-table\"><tr><th>section</th><th>check</th><th>verdict</th></tr>\n";
    for (const auto& k : c.checks)
        o << "<tr><td>" << esc(k.section) << "</td><td><a href=\"#" << k.id << "\">" << k.what << "</a></td><td class=\""
          << (k.ok ? "pass" : "fail") << "\">" << esc(k.shown) << "</td></tr>\n";
    o << "</table>\n";
    return o.str();
}

// The playground (issue 55): the built site copied beside the page and linked, or how to build it.
std::string playground_section(Ctx& c, const ReportOptions& opt) {
    std::ostringstream o;
    o << c.heading("Playground: the field in a browser", "playground");
    std::error_code ec;
    const fs::path site = opt.playground;
    if (!opt.playground.empty() && fs::exists(site / "index.html", ec)) {
        fs::remove_all(c.dir / "playground", ec);
        fs::copy(site, c.dir / "playground", fs::copy_options::recursive);
        o << "<p>The playground is beside this page: <a href=\"playground/index.html\">playground/index.html</a> -- the "
             "numeric core in WebAssembly, the field recomputed as each harmonic's and the part's sliders move, a dropped "
             "part's full-dynamics trajectory. A Web Worker does not start from a file: serve this folder over http, e.g. "
             "<code>python3 -m http.server -d "
          << esc(opt.out) << " 8000</code>, and open <code>http://localhost:8000/playground/</code> (its field equals "
          << "<code>plate field</code>'s to 1e-9: ctest -R web_).</p>\n";
    } else {
        fs::remove_all(c.dir / "playground", ec);   // (an older run's copy is not this build's)
        o << "<p>Not built. To add it: <code>cmake --build build --target web</code> (Debian's emscripten; "
             "scripts/install-deps.sh installs it), then <code>plate report</code> again copies build/web/site here as "
             "playground/ and links it (web/README.md).</p>\n";
    }
    return o.str();
}

}   // namespace

void write_report(const ReportOptions& opt) {
    if (opt.out.empty()) throw std::runtime_error("report: no output folder");
    check_sections(opt.sections);
    Ctx c;
    c.dir = opt.out;
    fs::create_directories(c.dir / "data");
    // The page appears complete or not at all: an older page goes first (a killed run must not leave it
    // beside new figures), the new one is written to a temporary and renamed at the end.
    fs::remove(c.dir / "index.html");
    const fs::path src = opt.source_dir;
    const auto t0 = std::chrono::steady_clock::now();
    auto wanted = [&](const char* n) {
        return opt.sections.empty() || std::find(opt.sections.begin(), opt.sections.end(), n) != opt.sections.end();
    };
    std::string left_out;
    for (const auto& n : report_section_names())
        if (!wanted(n.c_str())) left_out += (left_out.empty() ? "" : ", ") + n;
    if (wanted("derivation")) c.timed("derivation", [&] { section_derivation(c); });
    if (wanted("kernels")) c.timed("kernel equivalence", [&] { section_kernels(c, opt.seed); });
    if (wanted("proofs")) section_proofs(c, opt);
    if (wanted("fig3")) c.timed("Fig. 3", [&] { section_fig3(c, src); });
    if (wanted("fields")) section_fields(c, src, opt);
    if (wanted("design")) c.timed("inverse design", [&] { section_design(c, src, opt); });
    if (wanted("orient")) c.timed("orienter", [&] { section_orient(c, src, opt); });
    if (wanted("fixed-point")) c.timed("rigid fixed point", [&] { section_fixed_point(c, src, opt); });
    if (wanted("robustness")) section_robustness(c, src, opt);
    if (wanted("identify")) c.timed("identification", [&] { section_identify(c, src, opt); });
    if (wanted("control")) c.timed("closed loop", [&] { section_control(c, src, opt); });
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // KaTeX from Debian's libjs-katex, copied beside the report when present.
    std::string katex;
    const fs::path kdir = "/usr/share/javascript/katex";
    if (fs::exists(kdir / "katex.min.js")) {
        fs::copy(kdir, c.dir / "katex", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
        katex =
            "<link rel=\"stylesheet\" href=\"katex/katex.min.css\"><script src=\"katex/katex.min.js\"></script>"
            "<script src=\"katex/contrib/auto-render.js\"></script><script>document.addEventListener('DOMContentLoaded',"
            "function(){renderMathInElement(document.body,{delimiters:[{left:'$$',right:'$$',display:true}],throwOnError:false});"
            "});</script>\n";
    }
    std::ostringstream html;
    html << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>plate: verification report</title>\n"
         << kErrorTrap << kStyle << katex
         << "</head><body>\n<h1>Sliding manipulation on a 6-DoF plate: verification report</h1>\n";
    html << "<p>Every number below was computed by this run. Seed " << opt.seed << (opt.quick ? " (quick mode)" : "")
         << "; machine: " << esc(machine_description()) << "; total " << fmt(total, 4) << " s."
         << (left_out.empty() ? "" : " Sections left out of this run (--sections): " + esc(left_out) + ".") << "</p>\n";
    const std::string playground = playground_section(c, opt);   // (before the contents list, which lists it)
    html << contents_and_verdicts(c);
    html << "<h2 id=\"timings\">Time per part</h2>\n<table><tr><th>part</th><th>seconds</th></tr>\n";
    for (const auto& [w, s] : c.timings) html << "<tr><td>" << esc(w) << "</td><td>" << fmt(s, 4) << "</td></tr>\n";
    html << "</table>\n" << c.html.str();
    // The studies run apart from the report keep their sections between their markers: DIR/data/NAME_section.html
    // where the study has run, else a stub that says which command writes it.
    const std::string out = esc(opt.out);
    auto study = [&](const char* begin, const char* end, const char* name, const std::string& stub) {
        const fs::path file = c.dir / "data" / (std::string(name) + "_section.html");
        html << "<a id=\"" << name << "\"></a>" << begin;
        if (fs::exists(file))
            html << std::ifstream(file).rdbuf();
        else
            html << stub;
        html << end << "\n";
    };
    html << playground;
    study(kSpeedBegin, kSpeedEnd, "speed",   // plate bench
          "<h2>Speed and accuracy</h2><p>Not run yet. To fill it: <code>plate bench --out " + out +
              "</code> writes this section into this page (work-precision charts, failure maps, limit-cycle solvers, model "
              "hierarchy).</p>\n");
    study(kPeersBegin, kPeersEnd, "peers",   // bench/peers/study.py
          "<h2>Side by side with Bullet, ODE and MuJoCo</h2><p>Not run yet. To fill it: <code>bench/peers/study.py --out " + out +
              "</code> writes this section into this page (the same questions to the engines found at build time and to plate, "
              "error against CPU time).</p>\n");
    study(kCampaignsBegin, kCampaignsEnd, "campaigns",   // bench/scaling.py
          "<h2>Campaigns</h2><p>Not run yet. To fill it: <code>bench/scaling.py --out " + out +
              "</code> writes this section into this page (strong and weak scaling of <code>plate sweep</code> over threads and "
              "MPI ranks, "
              "load balance, the cost of a 1 000-core campaign).</p>\n");
    study(kMutationsBegin, kMutationsEnd, "mutations",   // scripts/mutants.py --report
          "<h2>Mutation score</h2><p>Not run yet. To fill it: <code>scripts/mutants.py --report " + out +
              "</code> writes this section into this page (one-line physics bugs from tests/mutations/catalogue.json, each "
              "applied to a "
              "scratch copy, and the tests that caught it).</p>\n");
    html << kPageCheck << "</body></html>\n";
    write_file_atomic((c.dir / "index.html").string(), [&](std::ostream& o) { o << html.str(); });
}

const std::vector<std::string>& report_section_names() {
    static const std::vector<std::string> names = {"derivation", "kernels",     "proofs",     "fig3",     "fields", "design",
                                                   "orient",     "fixed-point", "robustness", "identify", "control"};
    return names;
}

void check_sections(const std::vector<std::string>& sections) {
    const auto& names = report_section_names();
    for (const auto& n : sections) {
        if (std::find(names.begin(), names.end(), n) != names.end()) continue;
        std::string all;
        for (const auto& m : names) all += (all.empty() ? "" : ", ") + m;
        throw std::invalid_argument("'" + n + "' is not a section (" + all + ")");
    }
}

std::string collinear_sentence(const std::vector<double>& conds, const std::vector<double>& gaps, double singular) {
    if (conds.size() < 2) return "Too few contact spreads to say how A's conditioning grows.";
    double grow = 1e300, shrink = 1e300;   // the smallest factor per tenth of e/L
    for (std::size_t i = 1; i < conds.size(); ++i) {
        grow = std::min(grow, conds[i] / conds[i - 1]);
        if (gaps[i] > 0) shrink = std::min(shrink, gaps[i - 1] / gaps[i]);
    }
    std::ostringstream o;
    o.precision(2);
    if (grow >= 5)
        o << "A's condition number grows at least " << grow << "x per tenth of e/L (like L/e)";
    else
        o << "A's condition number does not grow like L/e here: at least " << grow << "x per tenth of e/L";
    o << (singular < 1e-12 ? " and A is singular at e = 0" : ", and A is not singular at e = 0 (check)");
    if (shrink >= 5)
        o << "; the two twists' wrenches approach each other at least " << shrink
          << "x per tenth: the limit surface develops a vertex.";
    else
        o << "; the two twists' wrenches do not approach each other like e (at least " << shrink << "x per tenth).";
    return o.str();
}

std::string scene_heading(const std::string& title, const std::string& scene_name, const std::string& file) {
    return "<h3>" + esc(title) + " (<code>" + esc(scene_name) + "</code>, <code>scenes/" + esc(file) + "</code>)</h3>";
}

std::string contraction_caption(int shown, double worst_factor) {
    std::ostringstream o;
    o.precision(3);
    if (shown <= 0) return "No thin case stayed in the model: none shown.";
    if (worst_factor < 1)
        o << "The " << shown << " thin parts shown contract geometrically: |ξ_rel| falls each period to at most " << worst_factor
          << " of its value.";
    else
        o << "The " << shown << " thin parts shown do not all contract geometrically: in one period |ξ_rel| grew to "
          << worst_factor << " of its value.";
    return o.str();
}

std::string fig3_caption(int periods, double gap_start, double gap_end) {
    std::ostringstream o;
    o.precision(2);
    o << "Two initial twists " << gap_start << " v_ref apart; after " << periods << " periods their twists at the period "
      << "boundary are " << gap_end << " v_ref apart: ";
    if (gap_end <= 1e-2 * gap_start)
        o << "converging to one limit cycle (twist space).";
    else
        o << "not shown converging to one limit cycle in these periods (the gap shrank less than 100x).";
    return o.str();
}

std::string design_runs_caption(int reached, int runs, double distance, bool verified, const std::string& failure) {
    std::ostringstream o;
    o.precision(3);
    o << "The designed velocity field (arrows, scaled) and the verification's full-dynamics runs from random starts: " << reached
      << " of " << runs << " end within " << distance * 1e3 << " mm of the target";
    if (verified && reached == runs && runs > 0)
        o << ", converging on the target.";
    else
        o << ": not all converge on the target" << (verified ? "." : "; the design failed verification: " + esc(failure) + ".");
    return o.str();
}

std::string observation1_sentence(int valid, int converged, int unique, int attracting) {
    if (valid <= 0) return "No thick case stayed in the model, so this campaign says nothing on Observation 1.";
    if (converged == valid && unique == valid && attracting == valid)
        return "In this campaign every cycle found was unique and attracting (Observation 1), in all " + std::to_string(valid) +
               " cases.";
    std::string s = "Observation 1 does not hold in this campaign for every case: of " + std::to_string(valid) + " cases, ";
    std::string parts;
    auto add = [&](int bad, const char* what) {
        if (bad <= 0) return;
        if (!parts.empty()) parts += ", ";
        parts += std::to_string(bad) + " " + what;
    };
    add(valid - converged, "reached no cycle");
    add(converged - unique, "reached another cycle from other initial twists");
    add(converged - attracting, "had a Floquet multiplier of modulus 1 or more");
    return s + parts + ".";
}

}   // namespace plate::report
