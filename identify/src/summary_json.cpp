// The identification's summary as JSON (plate identify --out).
#include "plate/identify.hpp"

#include <cmath>

namespace plate {
namespace {

using json = nlohmann::json;

// A number, or null where it is not finite (JSON has no NaN).
json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}   // namespace

json identify_json(const IdentifySummary& s, const IdentifyOptions& o) {
    json params = json::array();
    for (const FittedParameter& p : s.params) {
        json j{{"name", p.name}, {"unit", p.unit}, {"estimate", p.estimate}, {"at_bound", p.at_bound}};
        if (p.identifiable) {
            j["sd"] = num(p.sd);
            j["interval95"] = {num(p.lo), num(p.hi)};
        } else {
            j["sd"] = nullptr;
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
              {"rtol", o.rtol}};
    return json{{"parameters", params},
                {"covariance", {{"names", names}, {"matrix", cov}}},
                {"identifiability", unid.empty() ? json("every parameter identifiable from these tracks") : unid},
                {"tracks", tracks},
                {"chi2", s.chi2},
                {"residuals", s.residuals},
                {"dof", s.dof},
                {"reduced_chi2", num(s.reduced_chi2)},
                {"solver",
                 {{"method", "Ceres Levenberg-Marquardt, central differences of the simulation"},
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

}   // namespace plate
