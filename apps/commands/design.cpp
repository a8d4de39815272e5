// plate design: the plate motion that sends a part where wanted (a sink, fixed point, orientation,
// line sink or transport), verified before it is written.
#include "commands.hpp"

#include "plate/design.hpp"
#include "plate/farm.hpp"
#include "plate/output.hpp"

#include <complex>
#include <cstdint>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct DesignArgs : Options {
    std::string scene, out;
    std::vector<std::string> target;
    std::vector<double> limits;
    double period = 0, hold = DesignOptions{}.hold, max_coning = DesignOptions{}.max_coning;
    std::uint64_t seed = 1;
    int threads = 0, starts = DesignOptions{}.starts, evaluations = DesignOptions{}.local_evaluations, harmonics = 0;
    std::string axes;
    explicit DesignArgs(CLI::App& app)
        : Options(app, "design",
                  "the plate motion that sends a part where wanted: a sink, fixed point, orientation or transport, verified",
                  "Designs a plate motion for the part of PART_SCENE (its plate block is ignored but for its period)\n"
                  "and verifies it before reporting. Targets:\n"
                  "  sink X Y          point part: the unique stable fixed point of the velocity field at (X, Y);\n"
                  "                    rigid part: its position ends at (X, Y) whatever its orientation (left free)\n"
                  "  fixed-point X Y THETA  rigid part: (X, Y, THETA) the unique stable fixed point of the twist field\n"
                  "                    (or, where that is out of reach, the target's basin share and the competing\n"
                  "                    fixed points); point part: fixed-point X Y = sink X Y\n"
                  "  orient THETA      rigid part: every start ends at orientation THETA (position free; a part\n"
                  "                    whose contacts' friction differs: by a plate that only translates)\n"
                  "  line-sink X Y PHI point part: every start ends on the line through (X, Y) along PHI [rad]\n"
                  "  transport VX VY   a uniform velocity (VX, VY) [m/s] over the plate (a rigid part: one friction\n"
                  "                    coefficient; OMEGA, a turn, is refused: see the README)\n"
                  "--limits LIN ANG: the largest amplitude of each harmonic (default 20 m/s^2, 150 rad/s^2); g plus the\n"
                  "vertical acceleration stays above 0.2 g over the plate (a constraint). NLopt COBYLA from --starts\n"
                  "seeded feasible motions (default 4 for sinks and line sinks, 16 otherwise),\n"
                  "--evaluations each (default 400). Verification: the field's fixed points on a 7x7 grid and full\n"
                  "dynamics from 20 seeded random starts; sinks and fixed points also hold: released at rest at the\n"
                  "target, the part is still within 5 mm after --hold seconds (default 120; coning, rx and ry out of\n"
                  "phase, turns the field about the plate's centre, so it limits the coning). --axes and --harmonics\n"
                  "narrow each target's motion family (sinks x, y, rx, ry at n = 1, 3; line sinks y, rx at n = 1;\n"
                  "transport and orienters x, y, z at n = 1, 2; rigid fixed points all six at n = 1, 2): the other\n"
                  "harmonics stay zero. Writes the designed\n"
                  "scene to --out and a JSON summary to stdout; exit 4 (and no scene) if the design fails verification.\n") {
        scene_file(scene, "PART_SCENE");
        words("--target", target, 2, 4, "KIND ...",
              "sink X Y, fixed-point X Y [THETA], orient THETA, line-sink X Y PHI or transport VX VY [OMEGA]; required");
        text("--out", out, "SCENE.json", "the designed scene; required");
        numbers("--limits", limits, 2, 2, "LIN ANG", "the largest harmonic amplitudes (default 20 m/s^2, 150 rad/s^2)");
        number("--period", period, "the plate's period [s]", "the part scene's");
        whole("--seed", seed, 0, 1L << 40, "the seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        whole("--starts", starts, 1, 10000, "seeded starts of the search");
        whole("--evaluations", evaluations, 1, 1'000'000, "evaluations per start");
        number("--hold", hold, "seconds a part released at the target must stay within 5 mm (0: not checked)", "120");
        number("--max-coning", max_coning, "a sink's largest coning rate [rad/s] (negative: from the hold)", "from the hold");
        text("--axes", axes, "x,y,z,rx,ry,rz", "the axes the motion may use (default: the target's own)");
        whole("--harmonics", harmonics, 1, 64, "the highest harmonic n the motion may use (default: the target's own)");
    }
};


// --target KIND NUMBERS... (`target`, KIND first) as a DesignTarget for `part` (a rigid part's
// fixed-point takes X Y THETA, a point part's X Y); a UsageError with the usage otherwise.
DesignTarget parse_target(const std::vector<std::string>& target, const Scene& part) {
    const std::string kind = target[0];
    DesignTarget t;
    std::vector<double> v;
    for (std::size_t i = 1; i < target.size(); ++i) v.push_back(parse_num("--target", target[i]));
    const std::size_t want = kind == "orient" ? 1 : (kind == "fixed-point" && !part.part.point) || kind == "line-sink" ? 3 : 2;
    const std::string usage = "expected sink X Y, fixed-point X Y (point part) or X Y THETA (rigid part), orient THETA, "
                              "line-sink X Y PHI or transport VX VY [OMEGA]";
    if (v.size() != want && !(kind == "transport" && v.size() == 3)) throw UsageError("--target " + kind + ": " + usage);
    if (kind == "sink" || kind == "fixed-point") {
        t.kind = kind == "sink" ? DesignTargetKind::Sink : DesignTargetKind::FixedPoint;
        t.at = Vec2(v[0], v[1]);
        if (v.size() == 3) t.theta = v[2];
    } else if (kind == "orient") {
        t.kind = DesignTargetKind::Orient;
        t.theta = v[0];
    } else if (kind == "line-sink") {
        t.kind = DesignTargetKind::LineSink;
        t.at = Vec2(v[0], v[1]);
        t.theta = v[2];
    } else if (kind == "transport") {
        t.kind = DesignTargetKind::Transport;
        t.velocity = Vec2(v[0], v[1]);
        if (v.size() == 3) t.omega = v[2];
    } else {
        throw UsageError("--target: " + usage + ", got '" + kind + "'");
    }
    return t;
}

// The search's and the verification's options from the command line, checked (UsageError).
DesignOptions design_options(const DesignArgs& a) {
    DesignOptions o;
    if (a.has("--limits")) {
        o.lin_limit = a.limits[0];
        o.ang_limit = a.limits[1];
    }
    if (!(o.lin_limit >= 0 && o.ang_limit >= 0 && o.lin_limit <= kMaxAmplitude && o.ang_limit <= kMaxAmplitude))
        throw UsageError("--limits: expected amplitudes from 0 to " + fmt(kMaxAmplitude));
    o.period = a.period;
    if (a.has("--period") && !(o.period >= kPeriodRange[0] && o.period <= kPeriodRange[1]))
        throw UsageError("--period: expected " + fmt(kPeriodRange[0]) + " to " + fmt(kPeriodRange[1]) + " s");
    if (!(a.hold >= 0 && a.hold <= 3600)) throw UsageError("--hold: expected 0 to 3600 s");
    o.hold = a.hold;
    o.max_coning = a.max_coning;   // (any finite number: negative asks for the hold's limit)
    o.seed = a.seed;
    o.threads = a.threads;
    o.starts = a.starts;
    o.local_evaluations = a.evaluations;
    if (a.has("--harmonics")) o.max_harmonic = a.harmonics;
    if (a.has("--axes")) {
        std::istringstream in(a.axes);
        std::string name;
        while (std::getline(in, name, ',')) {
            bool found = false;
            for (int k = 0; k < 6; ++k)
                if (name == axis_name(static_cast<Axis>(k))) {
                    o.axes.push_back(static_cast<Axis>(k));
                    found = true;
                }
            if (!found) throw UsageError("--axes: expected a comma-separated list of x, y, z, rx, ry, rz, got '" + name + "'");
        }
        if (o.axes.empty()) throw UsageError("--axes: expected at least one of x, y, z, rx, ry, rz");
    }
    return o;
}

nlohmann::json complex_json(const std::complex<double>& z) { return {z.real(), z.imag()}; }

// The design's JSON summary (standard output): the target (`kind` as given), the search's narrowed
// freedom, the verification's findings and runs, the limits and the work; `scene` is --out.
nlohmann::json summary_json(const std::string& kind, const DesignTarget& t, const DesignOptions& o,
                            const DesignSummary& d, bool rigid, const std::string& scene) {
    const bool transport = t.kind == DesignTargetKind::Transport;
    nlohmann::json j;
    j["target"] = {{"kind", kind}};
    if (transport) j["target"]["velocity"] = {t.velocity.x(), t.velocity.y()};
    else if (t.kind != DesignTargetKind::Orient) j["target"]["at"] = {t.at.x(), t.at.y()};
    if (rigid) j["target"]["theta"] = t.theta;
    if (t.kind == DesignTargetKind::LineSink) j["target"]["direction"] = t.theta;
    if (!o.axes.empty()) {   // (the search's freedom, where narrowed)
        j["axes"] = nlohmann::json::array();
        for (Axis ax : o.axes) j["axes"].push_back(axis_name(ax));
    }
    if (o.max_harmonic > 0) j["max_harmonic"] = o.max_harmonic;
    j["verified"] = d.verified;
    if (!d.verified) j["failure"] = d.failure;
    j["scene"] = scene;
    const bool line = t.kind == DesignTargetKind::LineSink, rigid_sink = rigid && t.kind == DesignTargetKind::Sink;
    if (!transport) {
        // (a line sink has a line of fixed points, not one: there the flag says the line attracts with no
        // drift along it; a rigid sink's, that the position's field vanishes at the target at every
        // orientation of the grid -- the design's Newton checks, not a search of the grid for other zeros)
        j[line ? "line_attracts" : rigid_sink ? "position_zero_at_target_for_every_orientation" : "unique"] = d.unique;
        j["convergence_rate_per_s"] = d.rate;
        if (t.kind == DesignTargetKind::LineSink)   // (the grid's largest speed along the line, and its bound)
            j["speed_along_line"] = {{"largest_on_grid", d.transport_spread}, {"tolerance", d.transport_tolerance}};
        if (t.kind == DesignTargetKind::Orient) {
            // (position free: the orientation, and the velocity the part travels at there)
            j["orientation"] = d.fixed_point[2];
            j["velocity_at_orientation"] = {d.transport_mean.x(), d.transport_mean.y()};
        }
        if (rigid && t.kind == DesignTargetKind::Sink) {
            // (the orientation is free: where the position's field vanishes at each orientation)
            nlohmann::json pulls = nlohmann::json::array();
            for (const auto& p : d.pulls)
                pulls.push_back({{"theta", p.theta}, {"position_zero", {p.zero.x(), p.zero.y()}},
                                 {"eigenvalues", {complex_json(p.eigenvalues[0]), complex_json(p.eigenvalues[1])}}});
            j["position_pull_per_orientation"] = pulls;
        } else if (rigid) {
            j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1], d.fixed_point[2]};
            j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]),
                                            complex_json(d.fixed_point_eigenvalues[1]),
                                            complex_json(d.fixed_point_eigenvalues[2])};
            j["basin_share"] = d.basin_share;
            if (d.basin_share_bound < 1) j["basin_share_bound"] = d.basin_share_bound;
            nlohmann::json comp = nlohmann::json::array();
            for (const auto& c : d.competitors)
                comp.push_back({{"at", {c.point.q[0], c.point.q[1], c.point.q[2]}},
                                {"eigenvalues", {complex_json(c.point.eigenvalues[0]), complex_json(c.point.eigenvalues[1]),
                                                 complex_json(c.point.eigenvalues[2])}},
                                {"basin_share", c.basin_share}});
            j["competing_fixed_points"] = comp;
        } else if (!line) {
            j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1]};
            j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]), complex_json(d.fixed_point_eigenvalues[1])};
        }
        if (!rigid_sink) j["fixed_points_on_grid"] = fixed_points_sentence(d.fixed_points);   // (no grid search for those)
    } else {
        j["mean_velocity"] = {d.transport_mean.x(), d.transport_mean.y()};
        if (rigid) j["largest_turn_rate"] = d.transport_turn;   // (theta' on the grid, rad/s)
        j["spread"] = d.transport_spread;
        j["tolerance"] = d.transport_tolerance;
    }
    nlohmann::json runs = nlohmann::json::array();
    for (const DesignStartRun& r : d.runs) {
        nlohmann::json x = {{"start", rigid ? nlohmann::json{r.x, r.y, r.theta} : nlohmann::json{r.x, r.y}},
                            {"end", rigid ? nlohmann::json{r.end[0], r.end[1], r.end[2]} : nlohmann::json{r.end[0], r.end[1]}},
                            {"seconds", r.seconds}, {"end_distance", r.end_distance}};
        if (r.from > 0) {   // (transport: judged over [from, seconds])
            x["from"] = r.from;
            x["at_from"] = nlohmann::json{r.at_from[0], r.at_from[1]};
        }
        if (!r.stop.empty()) x["stop"] = r.stop;
        runs.push_back(x);
    }
    j["full_dynamics_runs"] = runs;
    j["worst_end_distance"] = d.worst_end_distance;
    if (d.held.seconds > 0) {   // (sinks and fixed points)
        const DesignStartRun& h = d.held;
        nlohmann::json x = {{"seconds", h.seconds}, {"end_distance", h.end_distance},
                            {"end", rigid ? nlohmann::json{h.end[0], h.end[1], h.end[2]} : nlohmann::json{h.end[0], h.end[1]}}};
        if (!h.stop.empty()) x["stop"] = h.stop;
        j["hold"] = x;
    }
    j["coning_rate"] = d.coning;
    j["min_vertical_acceleration_margin_over_g"] = d.min_vertical_margin;
    j["limits"] = {o.lin_limit, o.ang_limit};
    j["starts"] = d.starts;
    j["evaluations"] = d.evaluations;
    j["limit_cycles"] = d.cycles;
    j["seconds"] = d.seconds;
    j["notes"] = d.notes;
    return j;
}

int cmd_design(const DesignArgs& a, Io& cio) {
    launched_farm(cio, a.threads);
    const Scene part = scene_arg(a.scene, cio);
    if (!a.has("--target")) throw UsageError("missing --target KIND A B");
    if (!a.has("--out")) throw UsageError("missing --out SCENE.json");
    const DesignTarget t = parse_target(a.target, part);
    DesignOptions o = design_options(a);
    // Under mpirun the starts, the verification field's planes and the verification runs are shared
    // over the ranks; every rank follows the same path, rank 0 writes.
    if (cio.farm) o.tasks = sweep::farm_tasks(*cio.farm);
    DesignSummary d;
    try {
        d = design(part, t, o);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    if (cio.farm && !cio.farm->root()) return d.verified ? 0 : 4;
    const bool rigid = !part.part.point;
    const nlohmann::json j = summary_json(a.target[0], t, o, d, rigid, a.out);
    if (d.verified) {
        write_file_atomic(a.out, [&](std::ostream& out) { out << scene_to_json(d.scene).dump(2) << "\n"; });
        for (const std::string& w : scene_warnings(d.scene)) cio.err << "warning: designed scene: " << w << "\n";
    }
    cio.out << j.dump(2) << std::endl;
    if (!d.verified) {
        cio.err << "plate design: " << a.scene << ": the design failed verification: " << d.failure << " (no scene written)"
                << std::endl;
        return 4;
    }
    if (rigid && t.kind == DesignTargetKind::FixedPoint && !d.unique) {   // (verified, but say it plainly)
        cio.err << "plate design: " << a.scene << ": not unique: the target holds " << d.basin_share
                << " of the random starts";
        for (const auto& c : d.competitors)
            cio.err << "; a stable fixed point at (" << c.point.q[0] << ", " << c.point.q[1] << ", " << c.point.q[2]
                    << ") holds " << c.basin_share;
        cio.err << std::endl;
    }
    return 0;
}

}  // namespace

Command add_design(CLI::App& app) { return make_command<DesignArgs>(app, cmd_design); }

}  // namespace plate::cli
