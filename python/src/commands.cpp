// The command line's remaining commands from Python (issue 54: every command reachable): a seeded
// random scene (plate random-scene), a campaign (plate sweep), Theorem 1's checks (plate proofs), the
// verification report (plate report) and the speed-accuracy study (plate bench), each with the
// command's options and its JSON or its page.
#include "bindings.hpp"
#include "interrupt.hpp"

#include "plate/random_scene.hpp"
#include "plate/farm.hpp"
#include "plate/sweep.hpp"
#include "proofs_json.hpp"
#include "report.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>

namespace plate::python {

namespace {

// The project folder a report reads (scenes/, reports/generated/): `source`, else the one this module
// was built from if it is still there (a pip-installed module carries no scenes).
std::string project_folder(const std::optional<std::filesystem::path>& source) {
    const std::filesystem::path root = source ? *source : std::filesystem::path(PLATE_SOURCE_DIR);
    std::error_code ec;
    require(std::filesystem::exists(root / "scenes", ec),
            "source: " + root.string() +
                " has no scenes/ (give source=, the project's folder: a checkout of plate, where scenes/ and reports/ are)");
    return root.string();
}

void bind_report(py::module_& m) {
    m.def(
        "report",
        [](const std::filesystem::path& out, bool quick, std::vector<std::string> sections, std::uint64_t seed, int threads,
           const std::optional<std::filesystem::path>& source, const std::optional<std::filesystem::path>& playground) {
            require(threads >= 0, "threads: expected >= 0 (0: all cores)");
            try {
                report::check_sections(sections);
            } catch (const std::invalid_argument& e) {
                require(false, std::string("sections: ") + e.what());
            }
            report::ReportOptions o;
            o.out = out.string();
            o.source_dir = project_folder(source);
            o.seed = seed;
            o.quick = quick;
            o.threads = threads;
            o.sections = std::move(sections);
            o.playground = playground ? playground->string() : std::string(PLATE_BUILD_DIR) + "/web/site";
            interruptible(py::none(), [&](Watch&) {
                report::write_report(o);
                return 0;
            });
            return (out / "index.html").string();
        },
        py::arg("out"), py::kw_only(), py::arg("quick") = false, py::arg("sections") = std::vector<std::string>{},
        py::arg("seed") = 1, py::arg("threads") = 0, py::arg("source") = py::none(), py::arg("playground") = py::none(),
        "The verification report, as `plate report --out DIR`: out/index.html and its SVG figures (gnuplot).\n"
        "quick: small campaigns and grids; sections: only these (names as plate report --help lists them),\n"
        "the page naming those left out. source: the project folder (scenes/, reports/generated/), default\n"
        "the one this module was built from. playground: a built playground site to copy beside the page and\n"
        "link (default the build's web/site when there is one). Returns the page's path. Ctrl-C stops it\n"
        "(KeyboardInterrupt);\n"
        "an interrupted report leaves no index.html.");
    m.def(
        "bench",
        [](const std::filesystem::path& out, bool full, const std::optional<std::filesystem::path>& source) {
            report::SpeedOptions o;
            o.out = out.string();
            o.source_dir = project_folder(source);
            o.full = full;
            interruptible(py::none(), [&](Watch&) {
                report::write_speed_study(o);
                return 0;
            });
            return (out / "index.html").string();
        },
        py::arg("out"), py::kw_only(), py::arg("full") = false, py::arg("source") = py::none(),
        "The speed-accuracy study, as `plate bench --out DIR`: work-precision charts into out, its section\n"
        "into out/index.html (the report's page if there is one). Minutes; full: the long campaign. (The\n"
        "peer engines' study, `plate bench --peers`, is bench/peers/study.py.) Returns the page's path.\n"
        "Ctrl-C stops it (KeyboardInterrupt).");
}

}   // namespace

void bind_commands(py::module_& m) {
    m.def(
        "random_scene",
        [](std::uint64_t seed, bool thin, bool point) {
            require(!(thin && point), "thin and point exclude each other");
            RandomSceneOptions ro;
            ro.thin = thin;
            ro.point = point;
            return random_scene(seed, ro);
        },
        py::arg("seed"), py::kw_only(), py::arg("thin") = false, py::arg("point") = false,
        "A seeded random part (thick by default; thin: contacts in the plane of the centre of mass, as\n"
        "Theorem 1 asks; point: a point part) and a random plate motion (harmonics 1-2 on every axis, the\n"
        "vertical acceleration below 0.6 g within 3 cm of the centre), as `plate random-scene --seed`.");
    m.def(
        "sweep",
        [](const std::filesystem::path& campaign, const std::filesystem::path& out, int threads, const py::object& progress) {
            require(threads >= 0, "threads: expected >= 0 (0: all cores)");
            sweep::SweepOptions o;
            o.out = out.string();
            const sweep::SweepSummary s = interruptible(progress, [&](Watch& watch) {
                o.progress = [&watch](int done, int total) { watch.report(done, total); };
                const std::unique_ptr<sweep::Farm> farm = sweep::thread_farm(threads);
                return sweep::run_sweep(campaign.string(), o, *farm);
            });
            return json_to_python(sweep::sweep_summary_json(campaign.string(), out.string(), s));
        },
        py::arg("campaign"), py::arg("out"), py::kw_only(), py::arg("threads") = 0, py::arg("progress") = py::none(),
        "A campaign (campaigns/*.json: a base scene, the parameters to vary, what to compute per case) run\n"
        "on `threads` threads into the folder `out`, as `plate sweep CAMPAIGN --out DIR`: each finished\n"
        "case is journaled, a rerun resumes, and when all are done out/table.csv and out/table.jsonl are\n"
        "written. Returns the command's JSON summary as a dict. Paths may be str or os.PathLike. progress: a\n"
        "callable given a plate.Progress (cases done of those to compute) every 0.05 s while it changes.");
    m.def(
        "proofs",
        [](int thin, int thick, int surfaces, std::uint64_t seed, int threads, const std::string& wrong_model) {
            require(thin >= 0 && thick >= 0 && surfaces >= 0, "thin, thick, surfaces: expected counts >= 0");
            require(threads >= 0, "threads: expected >= 0 (0: all cores)");
            proofs::ProofsOptions o;
            o.thin = thin;
            o.thick = thick;
            o.surfaces = surfaces;
            o.seed = seed;
            o.threads = threads;
            try {
                o.wrong = proofs::wrong_model(wrong_model);
            } catch (const std::invalid_argument& e) {
                require(false, std::string("wrong_model: ") + e.what());
            }
            const nlohmann::json j = interruptible(py::none(), [&](Watch&) {
                nlohmann::json a = proofs::contraction_json(proofs::check_contraction(proofs::contraction_options(o, true)));
                nlohmann::json b = proofs::contraction_json(proofs::check_contraction(proofs::contraction_options(o, false)));
                return proofs::proofs_json(o, std::move(a), std::move(b));
            });
            return json_to_python(j);
        },
        py::kw_only(), py::arg("thin") = 10000, py::arg("thick") = 1000, py::arg("surfaces") = 200, py::arg("seed") = 1,
        py::arg("threads") = 0, py::arg("wrong_model") = "none",
        "Theorem 1's numerical checks on seeded random parts and plate motions, as `plate proofs`: the\n"
        "contraction of the relative twist on `thin` parts (a verdict) and on `thick` ones beyond the theorem\n"
        "(observations), limit surfaces of `surfaces` thin parts (a verdict), A's conditioning toward\n"
        "collinear contacts. Returns the command's JSON as a dict: 'passed', and 'failed' naming what did\n"
        "not. wrong_model='pushing-friction' or 'mu3' runs them on a deliberately wrong model, to see them\n"
        "fail.");
    bind_report(m);
}

}   // namespace plate::python
