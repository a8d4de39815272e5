// plate identify: the part's friction coefficients and centre-of-mass offset from camera tracks, by
// least squares over the simulation (identify.hpp), with covariance, 95 % intervals and what the
// tracks cannot separate, as JSON.
#include "commands.hpp"

#include "plate/identify.hpp"
#include "plate/output.hpp"

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct IdentifyArgs : Options {
    std::string scene, params, dynamics = "full", out = "-";
    std::vector<std::string> tracks;
    IdentifyOptions o;
    explicit IdentifyArgs(CLI::App& app)
        : Options(app, "identify", "friction coefficients and centre-of-mass offset from camera tracks, JSON",
                  "Fits the named parameters of SCENE's part (--params, comma-separated: mu_k, mu_k1..3 kinetic\n"
                  "friction shared or per contact, mu_s, mu_s1..3 static, com_x, com_y the centre of mass's offset\n"
                  "[m] in the part frame) to the tracks (--tracks, files of plate simulate --observe: each filmed\n"
                  "under SCENE, the camera's noise sds weighing the residuals). Each track's start (at rest at t = 0,\n"
                  "the configuration fitted) is fitted too; --settle N leaves out the frames of its first N periods\n"
                  "(default 0; for tracks filmed from an unknown start twist).\n"
                  "Levenberg-Marquardt (Ceres) over the full (or u) dynamics, from --starts starts (the scene's\n"
                  "values, then seeded draws), the best kept; each start at most --max-iterations, all within\n"
                  "--time-limit s. JSON: the estimates with their sd and 95 % intervals, the covariance, residual\n"
                  "RMS per track [mm, mrad], chi-square and its reduced value (near 1 when model and noise are\n"
                  "right), the solver's report, and the parameter combinations the tracks cannot place within the\n"
                  "physical ranges (friction 0.05-1.5): \"not identifiable from these tracks\", with no interval.\n"
                  "Exit 2 for a track of another scene, too few frames or a bad cell (file and line named), a name\n"
                  "that is no parameter or one the part has not (mu_k2, com_x for a point part).\n") {
        scene_file(scene);
        words("--tracks", tracks, 1, 1000, "T.csv ...", "the track files; required");
        text("--params", params, "NAMES", "the parameters, comma-separated; required");
        text("--dynamics", dynamics, "full|u", "the model fitted (default full)");
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--starts", o.starts, 1, 1000, "starts of the search");
        whole("--seed", o.seed, 0, 1'000'000'000'000L, "seed of the drawn starts");
        whole("--max-iterations", o.max_iterations, 1, 10000, "Levenberg-Marquardt iterations per start");
        number("--time-limit", o.time_limit, "seconds for the whole search");
        number("--settle", o.settle_periods, "plate periods of each track left out at its start");
        number("--rtol", o.rtol, "the simulation's tolerance");
        whole("--threads", o.threads, 1, 1024, "tracks simulated in parallel");
    }
};

std::vector<std::string> split_names(const std::string& s) {
    std::vector<std::string> v;
    std::stringstream in(s);
    for (std::string w; std::getline(in, w, ',');) v.push_back(w);
    return v;
}

int cmd_identify(const IdentifyArgs& a, Io& cio) {
    if (!a.has("--tracks")) throw UsageError("missing --tracks T.csv ...");
    if (!a.has("--params")) throw UsageError("missing --params NAMES");
    if (a.dynamics != "full" && a.dynamics != "u") throw UsageError("--dynamics: full or u");
    const Scene sc = scene_arg(a.scene, cio);
    IdentifyOptions o = a.o;
    o.params = split_names(a.params);
    o.level = a.dynamics == "u" ? Dynamics::U : Dynamics::Full;
    try {
        o.validate();
        check_parameter_names(sc, o.params);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--params/options: ") + e.what());
    }
    std::vector<Track> tracks;
    for (const std::string& f : a.tracks) tracks.push_back(read_track_csv(f));
    check_tracks(sc, tracks, o);
    const IdentifySummary s = identify(sc, tracks, o);
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << identify_json(s, o).dump(2) << "\n"; }, cio.out);
    return 0;
}

}   // namespace

Command add_identify(CLI::App& app) { return make_command<IdentifyArgs>(app, cmd_identify); }

}   // namespace plate::cli
