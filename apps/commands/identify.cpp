// plate identify: the part's friction coefficients and centre-of-mass offset from camera tracks, by
// least squares over the simulation (identify.hpp), with covariance, 95 % intervals and what the
// tracks cannot separate, as JSON.
#include "commands.hpp"

#include "plate/identify.hpp"
#include "plate/output.hpp"
#include "plate/profile.hpp"
#include "plate/scene_io.hpp"
#include "plate/suggest.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct IdentifyArgs : Options {
    std::string scene, params, dynamics = "full", out = "-", camera, scene_out, profile;
    std::vector<std::string> tracks;
    std::vector<double> limits;
    bool suggest = false;
    bool no_envelope = false;
    IdentifyOptions o;
    SuggestOptions so;
    ProfileOptions po;
    explicit IdentifyArgs(CLI::App& app)
        : Options(app, "identify", "friction coefficients and centre-of-mass offset from camera tracks, JSON",
                  "Fits the named parameters of SCENE's part (--params, comma-separated: mu_k, mu_k1..3 kinetic\n"
                  "friction shared or per contact, mu_s, mu_s1..3 static, com_x, com_y the centre of mass's offset\n"
                  "[m] in the part frame) to the tracks (--tracks, files of plate simulate --observe: each filmed\n"
                  "under SCENE, the camera's noise sds weighing the residuals). Each track's start (at rest at t = 0,\n"
                  "the configuration fitted) is fitted too; --settle N leaves out the frames of its first N periods\n"
                  "(default 0; for tracks filmed from an unknown start twist).\n"
                  "Each start of the search first fits the tracks cut into pieces of --pieces S seconds (default 2;\n"
                  "0: none), each from its own start at rest, its first 4 periods left out: short pieces keep the\n"
                  "search out of the valleys a long track's chi-square has far from its minimum (not where the\n"
                  "plate turns about more than one axis: its orientation is then not periodic). Before them, up to\n"
                  "--coarse N steps (default 2; 0: none) move the kinetic coefficients and offsets on the whole\n"
                  "tracks, their starts held at the first frames and the static coefficients' excesses over the\n"
                  "kinetic ones held: from a guess, they reach the chi-square's bowl around the truth. After the\n"
                  "search, up to --wide N steps (default 4; 0: none) move every fitted coefficient and start at once, the\n"
                  "Jacobian by differences 10 times the search's, then up to N Gauss-Newton steps on differences of\n"
                  "each of 300, 100 and 30 times the search's, each step as long as the chi-square along it says:\n"
                  "where the search stopped in one of the cells below, above the truth's chi-square, or before an\n"
                  "arrest's band, they take it on (then the search again).\n"
                  "Under static friction the chi-square is piecewise smooth on cells smaller than the sds (an arrest\n"
                  "held or slipped through moves every later frame): each sd also takes the spread over the cells'\n"
                  "minima near the fit, from --cells N points drawn about it (default 32; 0: none; \"sd_cells\"); the\n"
                  "within-cell sd is replaced by the Jacobian's by differences 3, 10 or 30 times the search's where\n"
                  "that is wider (a secant over several cells, their envelope; --no-envelope: not; \"sd_envelope\").\n"
                  "Levenberg-Marquardt (Ceres) over the full (or u) dynamics, from --starts starts (the scene's\n"
                  "values; then the best fit's kinetic coefficients and offsets with the static excesses of the\n"
                  "scene's values, then of seeded draws; a start runs only while none fits as well as the noise\n"
                  "allows), the best kept; each start at most --max-iterations, all within\n"
                  "--time-limit s. JSON: the estimates with their sd and 95 % intervals, the covariance, residual\n"
                  "RMS per track [mm, mrad], chi-square and its reduced value (near 1 when model and noise are\n"
                  "right), the solver's report, and the parameter combinations the tracks cannot place within the\n"
                  "physical ranges (friction 0.05-1.5): \"not identifiable from these tracks\", with no interval.\n"
                  "Each interval within the fit's cell (estimate -+ 1.96 sqrt(sd^2 - sd_cells^2 - sd_envelope^2)) is\n"
                  "checked at its ends (\"interval95_check\"): the chi-square's rise there along the linearised\n"
                  "profile's path, 3.84 where the chi-square is quadratic; \"too narrow\" (a rise below 2.67, or a\n"
                  "better fit there) or \"unconfirmed\" (above 6.0): run --profile before trusting it.\n"
                  "--profile NAMES|all: after the fit, each named fitted parameter's profile likelihood (chi-square\n"
                  "minimised over the other parameters and the starts, stepped outward until it rises by 3.84 or\n"
                  "reaches the physical bound; at most --profile-steps re-minimisations a side, all within\n"
                  "--profile-time-limit s): its points and 95 % interval (ends \"crossed\", \"at bound\", \"cut short\")\n"
                  "under \"profiles\"; a parameter's \"interval95\" is the profile's where it runs to a bound or its\n"
                  "ends differ from the linearised ones by more than a fifth of the half-width, \"not identifiable\"\n"
                  "where it runs to both bounds.\n"
                  "Exit 2 for a track of another scene, too few frames or a bad cell (file and line named), a name\n"
                  "that is no parameter or one the part has not (mu_k2, com_x for a point part).\n"
                  "--suggest: no fit; which plate motion to film so that the --params are identifiable. Candidate\n"
                  "horizontal drives (x and its second harmonic; with a y second harmonic; each with yaw for rigid\n"
                  "parts) at 1.1-2 mu_s g of SCENE's part, at SCENE's plate period and the multiples of it given by\n"
                  "--period-factors (default 1 2), within --limits LIN ANG (each axis' peak, as plate design's;\n"
                  "default 20 150), each weighed by the information --tracks-planned K tracks of --duration S s\n"
                  "(default 5 of 10 s, from seeded starts) filmed by --camera (default: stroboscopic at phase 0.25,\n"
                  "0.1 mm and 5 mrad) would carry at SCENE's values, over --start-sets N sets of starts (default 3;\n"
                  "judged by the worst); the one whose worst-determined combination is best determined wins. JSON:\n"
                  "every candidate's motion, peaks, stick fraction, predicted sds and smallest eigenvalues, the winner; "
                  "--scene-out FILE writes SCENE with the winner's plate motion\n"
                  "(film it: plate simulate FILE ... --observe CAMERA.json). Exit 4 if no candidate could be simulated.\n") {
        scene_file(scene);
        words("--tracks", tracks, 1, 1000, "T.csv ...", "the track files; required (but with --suggest)");
        text("--params", params, "NAMES", "the parameters, comma-separated; required");
        text("--dynamics", dynamics, "full|u", "the model fitted (default full)");
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--starts", o.starts, 1, 1000, "starts of the search");
        whole("--seed", o.seed, 0, 1'000'000'000'000L, "seed of the drawn starts");
        whole("--max-iterations", o.max_iterations, 1, 10000, "Levenberg-Marquardt iterations per start");
        number("--time-limit", o.time_limit, "seconds for the whole search");
        number("--settle", o.settle_periods, "plate periods of each track left out at its start");
        number("--rtol", o.rtol, "the simulation's tolerance");
        number("--pieces", o.segment_seconds, "seconds of the pieces the search fits first (0: none)");
        whole("--coarse", o.coarse_iterations, 0, 100, "coarse steps before the pieces (0: none)");
        whole("--wide", o.wide_iterations, 0, 1000, "wide steps after the search (0: none)");
        whole("--cells", o.cell_samples, 0, 10000, "points drawn about the fit for the cells' spread (0: none)");
        flag("--no-envelope", no_envelope, "the within-cell sds not widened to the secants' over several cells");
        whole("--threads", o.threads, 1, 1024, "simulations in parallel (the fit is the same on any number)");
        text("--profile", profile, "NAMES|all", "profile likelihood of these fitted parameters");
        whole("--profile-steps", po.max_steps, 1, 1000, "--profile: re-minimisations per side");
        number("--profile-time-limit", po.time_limit, "--profile: seconds for every profile");
        flag("--suggest", suggest, "propose the plate motion to film instead of fitting");
        text("--camera", camera, "CAMERA.json", "--suggest: the camera that will film");
        numbers("--limits", limits, 2, 2, "LIN ANG", "--suggest: each axis' peak [m/s^2, rad/s^2]");
        whole("--tracks-planned", so.tracks, 1, 1000, "--suggest: tracks that will be filmed");
        whole("--start-sets", so.start_sets, 1, 100, "--suggest: sets of their starts each motion is judged over (its worst)");
        numbers("--period-factors", so.period_factors, 1, 100, "F ...",
                "--suggest: the plate periods tried, in units of SCENE's (default 1 2)");
        number("--duration", so.duration, "--suggest: seconds of each");
        text("--scene-out", scene_out, "FILE", "--suggest: SCENE with the suggested plate motion");
    }
};

std::vector<std::string> split_names(const std::string& s) {
    std::vector<std::string> v;
    std::stringstream in(s);
    for (std::string w; std::getline(in, w, ',');) v.push_back(w);
    return v;
}

// The suggestion's camera: the file given, else the (stroboscopic at phase 0.25, 0.1 mm, 5 mrad).
Camera suggest_camera(const IdentifyArgs& a, const Scene& sc) {
    if (a.has("--camera")) return load_camera(a.camera);
    Camera c;
    c.per_period = 1;
    c.phase = 0.25;
    c.noise_xy_mm = 0.1;
    c.noise_theta_mrad = sc.part.point ? 0 : 5;
    c.source = "(default camera)";
    return c;
}

int cmd_suggest(const IdentifyArgs& a, const Scene& sc, const IdentifyOptions& o, Io& cio) {
    SuggestOptions so = a.so;
    so.fit = o;
    if (a.has("--limits")) {
        so.lin_limit = a.limits[0];
        so.ang_limit = a.limits[1];
    }
    try {
        so.validate();
    } catch (const std::invalid_argument& e) {
        std::string m = e.what();   // "suggest: lin_limit: ..." -> "--limits: ..."
        const std::pair<const char*, const char*> flags[] = {{"suggest: lin_limit", "--limits"},
                                                             {"suggest: ang_limit", "--limits"},
                                                             {"suggest: tracks", "--tracks-planned"},
                                                             {"suggest: duration", "--duration"},
                                                             {"suggest: period_factors", "--period-factors"}};
        for (const auto& [name, flag] : flags)
            if (m.rfind(name, 0) == 0) m = flag + m.substr(std::string(name).size());
        throw UsageError(m);
    }
    const Camera cam = suggest_camera(a, sc);
    const SuggestSummary s = suggest_motion(sc, cam, so);
    if (a.has("--scene-out") && s.best >= 0)
        write_file_atomic(a.scene_out, [&](std::ostream& out) { out << scene_to_json(s.suggested).dump(2) << "\n"; });
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << suggest_json(s, so).dump(2) << "\n"; }, cio.out);
    return s.best >= 0 ? 0 : 4;
}

int cmd_identify(const IdentifyArgs& a, Io& cio) {
    if (!a.suggest && !a.has("--tracks")) throw UsageError("missing --tracks T.csv ...");
    if (!a.has("--params")) throw UsageError("missing --params NAMES");
    if (a.dynamics != "full" && a.dynamics != "u") throw UsageError("--dynamics: full or u");
    const Scene sc = scene_arg(a.scene, cio);
    IdentifyOptions o = a.o;
    o.envelope = !a.no_envelope;
    o.params = split_names(a.params);
    o.level = a.dynamics == "u" ? Dynamics::U : Dynamics::Full;
    try {
        o.validate();
        check_parameter_names(sc, o.params);
        check_pieces(sc, o);
    } catch (const std::invalid_argument& e) {
        const std::string m = e.what();
        if (m.rfind("identify: segment_seconds", 0) == 0) throw UsageError("--pieces" + m.substr(25));
        throw UsageError("--params/options: " + m);
    }
    if (a.suggest) {
        if (a.has("--tracks")) throw UsageError("--suggest plans tracks: give --tracks-planned, not --tracks");
        return cmd_suggest(a, sc, o, cio);
    }
    for (const char* f :
         {"--camera", "--limits", "--tracks-planned", "--duration", "--scene-out", "--start-sets", "--period-factors"})
        if (a.has(f)) throw UsageError(std::string(f) + ": only with --suggest");
    std::vector<Track> tracks;
    for (const std::string& f : a.tracks) tracks.push_back(read_track_csv(f));
    check_tracks(sc, tracks, o);
    ProfileOptions po = a.po;
    if (a.has("--profile") && a.profile != "all") po.params = split_names(a.profile);
    if (a.has("--profile")) try {
            po.validate();
            for (const std::string& name : po.params)
                if (std::find(o.params.begin(), o.params.end(), name) == o.params.end())
                    throw std::invalid_argument(name + " is not among --params");
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--profile: ") + e.what());
        }
    else
        for (const char* f : {"--profile-steps", "--profile-time-limit"})
            if (a.has(f)) throw UsageError(std::string(f) + ": only with --profile");
    const IdentifySummary s = identify(sc, tracks, o);
    if (!s.explains_tracks)
        cio.err << "plate identify: warning: the fit does not explain the tracks (reduced chi-square " << s.reduced_chi2
                << ", p = " << s.p_value << " < " << kFitPValueFloor
                << "): a local minimum (its intervals mean nothing; more --starts restart its static coefficients), a model the "
                   "tracks contradict, or the cameras' noise sds too small (the intervals too narrow)\n";
    const nlohmann::json j =
        a.has("--profile") ? identify_json(s, o, profile_likelihood(sc, tracks, o, s, po), po) : identify_json(s, o);
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    return 0;
}

}   // namespace

Command add_identify(CLI::App& app) { return make_command<IdentifyArgs>(app, cmd_identify); }

}   // namespace plate::cli
