// Several point parts on one plate: the parts file, the loop (one plate motion a period, each part through
// the full dynamics on the same true plate), the CSV and the JSON summary.
#include "plate/control_multi.hpp"

#include "input_reader.hpp"
#include "internal.hpp"
#include "plate/output.hpp"

#include <chrono>
#include <cmath>
#include <ostream>
#include <stdexcept>

namespace plate {

using detail::Reader;
using nlohmann::json;

void MultiParts::validate(const Scene& nominal) const {
    const Reader r{source};
    if (!nominal.part.point) r.fail("part", "multi-part control is for point parts (the scene's part is rigid)");
    if (parts.empty() || parts.size() > static_cast<std::size_t>(kMaxParts))
        r.fail("parts", "expected 1 to " + std::to_string(kMaxParts) + " parts, got " + std::to_string(parts.size()));
    if (!(tolerance > 0) || !std::isfinite(tolerance)) r.fail("tolerance", "expected a number > 0");
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const std::string f = "parts[" + std::to_string(i) + "].";
        const MultiPart& p = parts[i];
        for (const auto& [name, v] : {std::pair<const char*, Vec3>{"goal", p.goal}, {"start", p.start}})
            if (!v.allFinite() || v.head<2>().norm() > kMaxPartReach || v.z() != 0)
                r.fail(f + name, "expected two finite numbers within " + Reader::fmt(kMaxPartReach) + " m of the origin");
        if (!(p.weight > 0 && p.weight <= kMaxWeight))
            r.fail(f + "weight", "expected a number in (0, " + Reader::fmt(kMaxWeight) + "], got " + Reader::fmt(p.weight));
    }
}

Goal MultiParts::goal(std::size_t i) const {
    Goal g;
    g.q = parts.at(i).goal;
    g.tolerance = tolerance;
    g.point = true;
    return g;
}

MultiParts parse_parts(const std::string& text, const std::string& source) {
    const Reader r{source};
    const json doc = r.parse(text);
    r.only_keys(doc, "", {"parts", "tolerance"}, {"parts"});
    MultiParts ps;
    ps.source = source;
    if (doc.contains("tolerance")) ps.tolerance = r.positive(doc["tolerance"], "tolerance");
    if (!doc["parts"].is_array()) r.fail("parts", "expected an array of parts");
    const auto xy = [&](const json& v, const std::string& field) {
        if (!v.is_array() || v.size() != 2) r.fail(field, "expected [X, Y] (a point part's position, metres)");
        return Vec3(r.number(v[0], field + "[0]"), r.number(v[1], field + "[1]"), 0);
    };
    for (std::size_t i = 0; i < doc["parts"].size(); ++i) {
        const std::string f = "parts[" + std::to_string(i) + "]";
        const json& p = doc["parts"][i];
        r.only_keys(p, f, {"goal", "start", "weight"}, {"goal"});
        MultiPart part;
        part.goal = xy(p["goal"], f + ".goal");
        if (p.contains("start")) part.start = xy(p["start"], f + ".start");
        if (p.contains("weight")) part.weight = r.number(p["weight"], f + ".weight");
        ps.parts.push_back(part);
    }
    return ps;   // (validate(nominal) judges the numbers: it needs the scene)
}

MultiParts load_parts(const std::string& path) { return parse_parts(detail::read_input_file(path, "parts file"), path); }

namespace {

// One part in the loop: its camera, its rows and its plate-frame state on the last period's true plate.
struct PartState {
    detail::LoopCamera cam;
    std::vector<ControlRow> rows;
    Vec3 q, qd = Vec3::Zero();
    PartState(const std::optional<Camera>& camera, double Tt, const Vec3& q0) : cam(camera, Tt), q(q0) {}
};

// Part i's camera: the camera with seed + i (nullopt stays a perfect camera).
std::optional<Camera> part_camera(const std::optional<Camera>& camera, std::size_t i) {
    if (!camera) return camera;
    Camera c = *camera;
    c.seed += i;
    return c;
}

}   // namespace

MultiControlSummary run_multi_control(const ControlModel& model, MultiPolicy& policy, const Truth& truth,
                                      const std::optional<Camera>& camera, const MultiParts& parts, const ControlOptions& opt,
                                      const std::function<bool()>& keep_going) {
    opt.validate();
    truth.validate();
    parts.validate(model.nominal);
    const double Tt = true_scene(truth, model.nominal, -1, 0).plate.T;
    const long periods = static_cast<long>(std::floor(opt.duration / Tt * (1 + 1e-12)));
    if (periods < 1 || periods > kMaxControlPeriods)
        throw std::invalid_argument("duration: expected 1 to " + std::to_string(kMaxControlPeriods) + " plate periods");
    std::vector<PartState> ps;
    for (std::size_t i = 0; i < parts.parts.size(); ++i) ps.emplace_back(part_camera(camera, i), Tt, parts.parts[i].start);
    policy.reset(model, parts);
    MultiControlSummary out;
    out.policy = policy.name();
    Scene cmd = model.nominal, last_truth = model.nominal;
    PlateMotion prev;
    using clock = std::chrono::steady_clock;
    long k = 0;
    for (; k < periods && out.stop.reason == StopReason::None; ++k) {
        if (keep_going && !keep_going()) {
            out.interrupted = true;
            break;
        }
        const double now = k * Tt;
        std::vector<Observation> obs;
        for (const PartState& p : ps) obs.push_back(p.cam.newest(now));
        const auto t0 = clock::now();
        const Decision d = policy.decide(obs, k);
        const double spent = std::chrono::duration<double>(clock::now() - t0).count();
        if (!d.plate && (d.motion < 0 || d.motion >= model.motions()))
            throw std::invalid_argument("decided motion " + std::to_string(d.motion) + ", not in the library");
        cmd.plate = d.plate ? *d.plate : model.library.motions[d.motion];
        const Scene tru = true_scene(truth, cmd, d.plate ? -1 : d.motion, k);
        for (std::size_t i = 0; i < ps.size(); ++i) {
            PartState& p = ps[i];
            if (k > 0) carry_state(tru.part, prev, tru.plate, p.q, p.qd);
            ControlRow row;
            row.t = now;
            if (obs[i].seen) row.observed = obs[i].q;
            row.truth = world_pose_at_phase0(tru, p.q);
            row.motion = d.plate ? -1 : d.motion;
            row.decision_seconds = spent;
            p.rows.push_back(row);
            const StopEvent stop = detail::run_period(tru, p.cam, now, Tt, k == 0, p.q, p.qd, opt.integration);
            if (stop.reason != StopReason::None && out.stop.reason == StopReason::None) {
                out.stop = stop;
                out.stop.t += now;
            }
        }
        last_truth = tru;
        prev = tru.plate;
    }
    out.periods = k;
    out.reached = !out.interrupted && out.stop.reason == StopReason::None;
    out.time_to_goal = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) {
        ControlSummary s;
        s.policy = out.policy;
        s.periods = k;
        s.stop = out.stop;
        s.interrupted = out.interrupted;
        s.rows = std::move(ps[i].rows);
        ControlRow last;
        last.t = out.stop.reason != StopReason::None ? out.stop.t : k * Tt;
        last.truth = world_pose_at_phase0(last_truth, ps[i].q);
        s.rows.push_back(last);
        detail::summarise(s, parts.goal(i));
        out.reached = out.reached && s.reached;
        out.time_to_goal = std::max(out.time_to_goal, s.time_to_goal);   // (NaN once one is NaN)
        if (!s.reached) out.time_to_goal = std::numeric_limits<double>::quiet_NaN();
        out.parts.push_back(std::move(s));
    }
    const ControlSummary& s0 = out.parts.front();
    out.switches = s0.switches;
    out.decision_mean = s0.decision_mean;
    out.decision_max = s0.decision_max;
    out.decision_p99 = s0.decision_p99;
    return out;
}

void write_multi_control_csv(std::ostream& out, const MultiControlSummary& s, const ControlModel& model) {
    out << "t [s]";
    for (std::size_t i = 1; i <= s.parts.size(); ++i)
        out << ",obs_s_x_" << i << " [m],obs_s_y_" << i << " [m],x_" << i << " [m],y_" << i << " [m]";
    out << ",motion,decision [s]\n";
    const std::vector<ControlRow>& rows0 = s.parts.front().rows;
    for (std::size_t k = 0; k < rows0.size(); ++k) {
        out << shortest(rows0[k].t);
        for (const ControlSummary& p : s.parts) {
            const ControlRow& r = p.rows[k];
            out << ',' << shortest(r.observed.x()) << ',' << shortest(r.observed.y()) << ',' << shortest(r.truth.x()) << ','
                << shortest(r.truth.y());
        }
        const ControlRow& r = rows0[k];
        const std::string name = k + 1 == rows0.size() ? "end" : r.motion < 0 ? "own" : model.library.names[r.motion];
        out << ',' << name << ',' << shortest(r.decision_seconds) << '\n';
    }
}

nlohmann::json multi_control_summary_json(const MultiControlSummary& s, const ControlModel& model, const MultiParts& parts) {
    auto num = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
    json j;
    j["policy"] = s.policy;
    j["tolerance_m"] = parts.tolerance;
    j["periods"] = s.periods;
    j["period_s"] = s.periods > 0 ? s.parts.front().rows[1].t - s.parts.front().rows[0].t : model.T();
    j["reached"] = s.reached;
    j["time_to_goal_s"] = num(s.time_to_goal);
    json list = json::array();
    for (std::size_t i = 0; i < s.parts.size(); ++i) {
        const ControlSummary& p = s.parts[i];
        const MultiPart& mp = parts.parts[i];
        list.push_back({{"goal", {mp.goal.x(), mp.goal.y()}},
                        {"start", {mp.start.x(), mp.start.y()}},
                        {"weight", mp.weight},
                        {"reached", p.reached},
                        {"time_to_goal_s", num(p.time_to_goal)},
                        {"first_within_s", num(p.first_within)},
                        {"final_error_m", p.final_error},
                        {"worst_overshoot_m", p.worst_overshoot}});
    }
    j["parts"] = list;
    j["switches"] = s.switches;
    j["decision_mean_s"] = s.decision_mean;
    j["decision_max_s"] = s.decision_max;
    j["decision_p99_s"] = s.decision_p99;
    j["motions"] = model.library.names;
    j["stop"] = s.stop.reason == StopReason::None ? json(nullptr) : json(s.stop.describe());
    j["interrupted"] = s.interrupted;
    return j;
}

}   // namespace plate
