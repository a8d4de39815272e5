// The identification's summary as JSON (plate identify --out).
#include "internal.hpp"
#include "plate/identify.hpp"
#include "plate/profile.hpp"

#include <cmath>
#include <iterator>
#include <vector>

namespace plate {
namespace {

using json = nlohmann::json;

// A number, or null where it is not finite (JSON has no NaN).
json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}   // namespace

static_assert(kFitPValueFloor == 1e-3, "identify_json's goodness_of_fit meaning says 0.001");

json identify_json(const IdentifySummary& s, const IdentifyOptions& o) {
    json params = json::array();
    for (const FittedParameter& p : s.params) {
        json j{{"name", p.name}, {"unit", p.unit}, {"estimate", p.estimate}, {"at_bound", p.at_bound}};
        if (p.identifiable) {
            j["sd"] = num(p.sd);
            j["sd_cells"] = num(p.sd_cells);
            j["sd_envelope"] = num(p.sd_envelope);
            j["interval95"] = {num(p.lo), num(p.hi)};
            j["interval95_check"] = {{"of",
                                      "the interval within the fit's cell: estimate -+ 1.96 sqrt(sd^2 - sd_cells^2 - "
                                      "sd_envelope^2)"},
                                     {"dchi2_at_ends", {num(p.dchi2_lo), num(p.dchi2_hi)}},
                                     {"quadratic_dchi2", kProfileThreshold95},
                                     {"verdict", to_string(p.linearity)}};
        } else {
            j["sd"] = nullptr;
            j["sd_cells"] = nullptr;
            j["sd_envelope"] = nullptr;
            j["interval95"] = nullptr;
            j["identifiable"] = "not identifiable from these tracks";
        }
        params.push_back(j);
    }
    json names = json::array(), cov = json::array();
    for (const FittedParameter& p : s.params) names.push_back(p.name);
    for (int i = 0; i < s.covariance.rows(); ++i) {
        json row = json::array();
        for (int k = 0; k < s.covariance.cols(); ++k) row.push_back(num(s.covariance(i, k)));
        cov.push_back(row);
    }
    json unid = json::array();
    for (const Unidentifiable& u : s.unidentifiable) {
        json comb = json::object();
        for (const auto& [name, w] : u.combination) comb[name] = w;
        unid.push_back({{"combination", comb},
                        {"half_width95_of_range", num(u.half_width)},
                        {"verdict", "not identifiable from these tracks"}});
    }
    json tracks = json::array();
    for (const TrackFit& t : s.tracks)
        tracks.push_back({{"file", t.source},
                          {"frames", t.frames},
                          {"start", {t.start.x(), t.start.y(), t.start.z()}},
                          {"rms_xy_mm", t.rms_xy_mm},
                          {"rms_theta_mrad", t.rms_theta_mrad},
                          {"chi2", t.chi2}});
    json opts{{"params", o.params},
              {"dynamics", o.level == Dynamics::Full ? "full" : "u"},
              {"starts", o.starts},
              {"seed", o.seed},
              {"max_iterations", o.max_iterations},
              {"time_limit_s", o.time_limit},
              {"settle_periods", o.settle_periods},
              {"pieces_s", o.segment_seconds},
              {"pieces_settle_periods", o.segment_settle_periods},
              {"initial_trust_radius", o.initial_trust_radius},
              {"jacobian_reuse", o.jacobian_reuse},
              {"hops", o.hops},
              {"cell_samples", o.cell_samples},
              {"envelope_factors", o.envelope ? json(std::vector<double>(std::begin(identify_detail::kEnvelopeFactors),
                                                                         std::end(identify_detail::kEnvelopeFactors)))
                                              : json::array()},
              {"wide_iterations", o.wide_iterations},
              {"rtol", o.rtol}};
    return json{
        {"parameters", params},
        {"covariance", {{"names", names}, {"matrix", cov}}},
        {"identifiability", unid.empty() ? json("every parameter identifiable from these tracks") : unid},
        {"tracks", tracks},
        {"chi2", s.chi2},
        {"residuals", s.residuals},
        {"dof", s.dof},
        {"reduced_chi2", num(s.reduced_chi2)},
        {"goodness_of_fit",   // (the meaning's 0.001: kFitPValueFloor, asserted above)
         {{"p_value", num(s.p_value)},
          {"explains_tracks", s.explains_tracks},
          {"meaning",
           "P(chi-square of dof degrees >= chi2), with the cameras' noise sds exact: below 0.001 the estimate does not "
           "explain the tracks -- a local minimum (its intervals mean nothing), a model they contradict, or noise sds too "
           "small (the intervals too narrow by about sqrt(reduced_chi2)); null: no degrees of freedom, not judged"}}},
        {"solver",
         {{"method", std::string("Ceres Levenberg-Marquardt; the search by ") + (o.central_search ? "central" : "forward") +
                         " differences of the simulation, the covariance by central ones"},
          {"coarse_iterations", s.coarse_iterations},
          {"coarse_seconds", s.coarse_seconds},
          {"cells_seconds", s.cells_seconds},
          {"envelope_seconds", s.envelope_seconds},
          {"wide_iterations", s.wide_iterations},
          {"wide_chi2_drop", s.wide_chi2_drop},
          {"wide_seconds", s.wide_seconds},
          {"pieces", s.pieces},
          {"piece_iterations", s.piece_iterations},
          {"hops", s.hops},
          {"piece_seconds", s.piece_seconds},
          {"starts_run", s.starts_run},
          {"best_start", s.best_start},
          {"held_unseen", s.held},
          {"start_chi2", s.start_costs},
          {"iterations", s.iterations},
          {"termination", s.termination},
          {"converged", s.converged}}},
        {"seconds", s.seconds},
        {"options", opts}};
}

json identify_json(const IdentifySummary& s, const IdentifyOptions& o, const ProfileSummary& p, const ProfileOptions& po) {
    json j = identify_json(s, o);
    json profiles = json::array();
    for (const ParameterProfile& pr : p.profiles) {
        json points = json::array();
        for (const ProfilePoint& q : pr.points) points.push_back({q.value, q.dchi2});
        const json interval{{"lo", pr.lo}, {"lo_end", to_string(pr.lo_end)}, {"hi", pr.hi}, {"hi_end", to_string(pr.hi_end)}};
        profiles.push_back({{"name", pr.name},
                            {"unit", pr.unit},
                            {"estimate", pr.estimate},
                            {"points", points},
                            {"points_columns", {"value [" + pr.unit + "]", "chi2 - chi2_min"}},
                            {"bounds", {pr.bound_lo, pr.bound_hi}},
                            {"interval95", interval},
                            {"chi2_drop", pr.chi2_drop},
                            {"simulations", pr.simulations},
                            {"seconds", pr.seconds}});
        for (json& q : j["parameters"]) {
            if (q["name"] != pr.name) continue;
            q["interval95_linearised"] = q["interval95"];
            q["interval95_profile"] = interval;
            q["interval_method"] = pr.interval_is_profile ? "profile likelihood" : "linearised";
            q["profile_verdict"] = pr.verdict;
            if (pr.interval_is_profile) q["interval95"] = pr.identifiable ? json{pr.lo_reported, pr.hi_reported} : json(nullptr);
            if (!pr.identifiable)
                q["identifiable"] = "not identifiable from these tracks";
            else if (q.contains("identifiable") && pr.interval_is_profile)
                q.erase("identifiable");
        }
    }
    j["profiles"] = profiles;
    j["profile"] = {{"threshold_dchi2", kProfileThreshold95},
                    {"chi2_min", p.chi2_min},
                    {"simulations", p.simulations},
                    {"seconds", p.seconds},
                    {"options",
                     {{"max_steps", po.max_steps},
                      {"max_iterations", po.max_iterations},
                      {"max_simulations", po.max_simulations},
                      {"time_limit_s", po.time_limit},
                      {"agreement", po.agreement}}}};
    return j;
}

}   // namespace plate
