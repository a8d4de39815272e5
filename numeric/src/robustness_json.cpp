// The robustness summary as JSON (robustness.hpp).
#include "plate/robustness.hpp"

#include <algorithm>
#include <cmath>

namespace plate {
namespace {

using nlohmann::json;

json arrival_value(double t) {
    if (std::isnan(t)) return "undefined";
    if (std::isinf(t)) return nullptr;
    return t;
}

json arrivals(const std::vector<double>& v) {
    json a = json::array();
    for (double t : v) a.push_back(arrival_value(t));
    return a;
}

json vec(const Vec3& v, bool point) { return point ? json::array({v[0], v[1]}) : json::array({v[0], v[1], v[2]}); }

// Over every start of every draw that has them: how many arrived within the horizon, the median and
// the 95th percentile of the arrival times (a start that did not arrive counts as later than any).
json arrival_statistics(const std::vector<DrawResult>& draws, bool full, double horizon) {
    std::vector<double> t;
    int undefined = 0;
    for (const DrawResult& d : draws)
        for (double x : full ? d.arrival_full : d.arrival) {
            if (std::isnan(x))
                ++undefined;
            else
                t.push_back(x);
        }
    std::sort(t.begin(), t.end());
    const auto arrived = std::count_if(t.begin(), t.end(), [](double x) { return std::isfinite(x); });
    auto quantile = [&](double q) -> json {
        if (t.empty()) return nullptr;
        const std::size_t k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(t.size()))) - 1;
        return arrival_value(t[std::min(k, t.size() - 1)]);
    };
    const int n = static_cast<int>(t.size()) + undefined;
    const Share s = wilson(static_cast<int>(arrived), n);
    return {{"runs", n},
            {"arrived", arrived},
            {"undefined", undefined},
            {"share", n ? json(s.value) : json(nullptr)},
            {"share_interval95", {s.low, s.high}},
            {"median_s", quantile(0.5)},
            {"p95_s", quantile(0.95)},
            {"horizon_s", horizon}};
}

json draw_json(const DrawResult& d, bool point) {
    json j = {{"outcome", outcome_name(d.outcome)}, {"arrival_s", arrivals(d.arrival)}};
    if (d.index != std::numeric_limits<std::uint64_t>::max()) j["index"] = d.index;
    if (!d.note.empty()) j["note"] = d.note;
    if (d.matched) {
        j[point ? "fixed_point_m" : "fixed_point_m_m_rad"] = vec(d.fixed_point, point);
        j["rate_per_s"] = d.rate;
    }
    if (!d.arrival_full.empty()) j["arrival_full_s"] = arrivals(d.arrival_full);
    return j;
}

json matrix(const Eigen::Matrix3d& m, bool point) {
    json a = json::array();
    const int n = point ? 2 : 3;
    for (int i = 0; i < n; ++i) {
        json row = json::array();
        for (int k = 0; k < n; ++k) row.push_back(m(i, k));
        a.push_back(row);
    }
    return a;
}

json sensitivity_json(const RobustnessSummary& s, bool point) {
    std::vector<const Sensitivity*> order;
    for (const Sensitivity& x : s.sensitivities)
        if (x.parameter.standard_deviation > 0) order.push_back(&x);
    std::stable_sort(order.begin(), order.end(),
                     [](const Sensitivity* a, const Sensitivity* b) { return a->variance_share > b->variance_share; });
    json params = json::array();
    for (const Sensitivity* x : order)
        params.push_back({{"name", x->parameter.name},
                          {"unit", x->parameter.unit},
                          {"standard_deviation", x->parameter.standard_deviation},
                          {"dq_dp", vec(x->dq, point)},
                          {"dq_dp_units", point ? "m per unit" : "m, m, rad per unit"},
                          {"position_variance_share", x->variance_share}});
    json j = {{"seconds", s.sensitivity_seconds},
              {"jacobian_per_s", matrix(s.jacobian, point)},
              {"predicted_covariance", matrix(s.predicted_covariance, point)},
              {"predicted_radius95_mm", 1e3 * s.predicted_radius95},
              {"linear_error_median", s.linear_error_median},
              {"linear_error_max", s.linear_error_max},
              {"nonlinear_draws", s.nonlinear_draws},
              {"parameters", params}};
    if (!point) j["predicted_angle95_rad"] = s.predicted_angle95;
    if (s.radius95 > 0) j["radius95_predicted_over_monte_carlo"] = s.predicted_radius95 / s.radius95;
    if (!point && s.angle95 > 0) j["angle95_predicted_over_monte_carlo"] = s.predicted_angle95 / s.angle95;
    return j;
}

}   // namespace

json robustness_json(const RobustnessSummary& s, const RobustnessOptions& opt, const UncertaintySpec& spec) {
    const bool point = s.nominal.part.point;
    const int n = static_cast<int>(s.draws.size());
    json outcomes = json::object();
    for (int k = 0; k < kOutcomes; ++k) {
        const Share sh = wilson(s.counts[k], n);
        outcomes[outcome_name(static_cast<Outcome>(k))] = {
            {"count", s.counts[k]}, {"probability", sh.value}, {"interval95", {sh.low, sh.high}}};
    }
    std::vector<double> rates;
    for (const DrawResult& d : s.draws)
        if (d.matched) rates.push_back(d.rate);
    std::sort(rates.begin(), rates.end());
    json rate = nullptr;
    if (!rates.empty()) rate = {{"min", rates.front()}, {"median", rates[rates.size() / 2]}, {"max", rates.back()}};
    json starts = json::array(), draws = json::array();
    for (const Vec3& q : s.starts) starts.push_back(vec(q, point));
    for (const DrawResult& d : s.draws) draws.push_back(draw_json(d, point));
    const int matched = static_cast<int>(rates.size());
    json spread = {{"draws", matched}};
    if (matched > 0) {
        spread["mean_offset_mm"] = {1e3 * s.mean_offset[0], 1e3 * s.mean_offset[1]};
        spread["radius95_mm"] = 1e3 * s.radius95;
        spread["covariance"] = matrix(s.covariance, point);
        if (!point) {
            spread["mean_offset_rad"] = s.mean_offset[2];
            spread["angle95_rad"] = s.angle95;
        }
    }
    json j = {{"scene", s.nominal.name},
              {"uncertainty", spec.source},
              {"seed", spec.seed},
              {"draws", n},
              {point ? "target_m" : "target_m_m_rad", vec(s.target, point)},
              {"match", {{"distance_m", opt.match_distance}, {"angle_rad", opt.match_angle}}},
              {"arrive", {{"distance_m", opt.arrive_distance}, {"angle_rad", opt.arrive_angle}, {"horizon_s", opt.horizon}}},
              {"nominal", draw_json(s.nominal_result, point)},
              {"outcomes", outcomes},
              {"spread", spread},
              {"covariance_units", point ? "m^2" : "m^2 (x, y), m rad, rad^2 (theta)"},
              {"rate_per_s", rate},
              {"arrival",
               {{"field", arrival_statistics(s.draws, false, opt.horizon)},
                {"full_dynamics", arrival_statistics(s.draws, true, opt.horizon)}}},
              {"starts", starts},
              {"notes", s.notes},
              {"seconds", s.seconds},
              {"per_draw", draws}};
    if (!s.sensitivities.empty()) j["sensitivity"] = sensitivity_json(s, point);
    return j;
}

}   // namespace plate
