// The design summary as JSON (design_target.hpp): what `plate design` prints.
#include "internal.hpp"

#include <nlohmann/json.hpp>

namespace plate {

namespace {

nlohmann::json complex_json(const std::complex<double>& z) { return {z.real(), z.imag()}; }

}   // namespace

nlohmann::json design_summary_json(const DesignSummary& d, const Scene& part_scene, const DesignTarget& t,
                                   const DesignOptions& opt, const std::string& scene_path) {
    const bool transport = t.kind == DesignTargetKind::Transport, rigid = !part_scene.part.point;
    nlohmann::json j;
    j["target"] = {{"kind", design_target_kind(t)}};
    if (transport)
        j["target"]["velocity"] = {t.velocity.x(), t.velocity.y()};
    else if (t.kind != DesignTargetKind::Orient && t.kind != DesignTargetKind::Registered)
        j["target"]["at"] = {t.at.x(), t.at.y()};
    if (rigid) j["target"]["theta"] = t.theta;
    if (t.kind == DesignTargetKind::LineSink) j["target"]["direction"] = t.theta;
    if (t.kind == DesignTargetKind::Registered) j["target"]["values"] = t.values;
    if (!opt.axes.empty()) {   // (the search's freedom, where narrowed)
        j["axes"] = nlohmann::json::array();
        for (Axis ax : opt.axes) j["axes"].push_back(axis_name(ax));
    }
    if (opt.max_harmonic > 0) j["max_harmonic"] = opt.max_harmonic;
    j["verified"] = d.verified;
    if (!d.verified) j["failure"] = d.failure;
    j["scene"] = scene_path;
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
                pulls.push_back({{"theta", p.theta},
                                 {"position_zero", {p.zero.x(), p.zero.y()}},
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
                                {"eigenvalues",
                                 {complex_json(c.point.eigenvalues[0]), complex_json(c.point.eigenvalues[1]),
                                  complex_json(c.point.eigenvalues[2])}},
                                {"basin_share", c.basin_share}});
            j["competing_fixed_points"] = comp;
        } else if (!line) {
            j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1]};
            j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]),
                                            complex_json(d.fixed_point_eigenvalues[1])};
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
                            {"seconds", r.seconds},
                            {"end_distance", r.end_distance}};
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
        nlohmann::json x = {{"seconds", h.seconds},
                            {"end_distance", h.end_distance},
                            {"end", rigid ? nlohmann::json{h.end[0], h.end[1], h.end[2]} : nlohmann::json{h.end[0], h.end[1]}}};
        if (!h.stop.empty()) x["stop"] = h.stop;
        j["hold"] = x;
    }
    j["coning_rate"] = d.coning;
    j["min_vertical_acceleration_margin_over_g"] = d.min_vertical_margin;
    j["limits"] = {opt.lin_limit, opt.ang_limit};   // (peaks: linear [m/s^2], angular [rad/s^2])
    // The designed signal's peak per axis over the period (axis_peaks): what the limits bound.
    j["peaks"] = {{"x_m_per_s2", d.peaks[0]},    {"y_m_per_s2", d.peaks[1]},    {"z_m_per_s2", d.peaks[2]},
                  {"rx_rad_per_s2", d.peaks[3]}, {"ry_rad_per_s2", d.peaks[4]}, {"rz_rad_per_s2", d.peaks[5]}};
    // The plate's corners (corner_peaks): the limits asked (0: none) and the designed motion's peaks.
    j["corner_limits"] = {{"displacement_m", opt.corner_displacement_limit}, {"velocity_m_per_s", opt.corner_velocity_limit}};
    j["corner_peaks"] = {{"half_size_m", {d.corner_half_size.x(), d.corner_half_size.y()}},
                         {"displacement_m", d.corner_peaks.displacement},
                         {"velocity_m_per_s", d.corner_peaks.velocity}};
    j["starts"] = d.starts;
    j["evaluations"] = d.evaluations;
    j["limit_cycles"] = d.cycles;
    j["seconds"] = d.seconds;
    j["notes"] = d.notes;
    if (opt.robust) {   // (the Monte Carlo's JSON as plate robustness writes it, without its per-draw rows)
        nlohmann::json r = {
            {"spec", opt.robust->source}, {"radius_m", opt.robust_radius}, {"share", opt.robust_share}, {"arrive_s", opt.arrive}};
        if (d.predicted_radius95 > 0) r["search_first_order_radius95_mm"] = 1e3 * d.predicted_radius95;
        if (d.robustness) {
            RobustnessOptions ro;
            ro.horizon = opt.arrive;
            ro.arrive_distance = opt.verify_distance;
            nlohmann::json mc = robustness_json(*d.robustness, ro, *opt.robust);
            mc.erase("per_draw");
            r["monte_carlo"] = mc;
        }
        j["robust"] = r;
    }
    return j;
}

}   // namespace plate
