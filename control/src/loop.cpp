// The loop: a period at a time, decide from the camera's newest frame, run the true plate through the
// full dynamics from the carried state, film; then the summary, the CSV and the JSON.
#include "internal.hpp"

#include "plate/output.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <stdexcept>

namespace plate {

void ControlOptions::validate() const {
    if (!(duration > 0) || !std::isfinite(duration)) throw std::invalid_argument("duration: expected a number > 0");
}

void detail::summarise(ControlSummary& s, const Goal& goal) {
    const auto& rows = s.rows;
    s.final_error = goal.error(rows.back().truth);
    s.final_theta_error = goal.theta_error(rows.back().truth);
    s.reached = goal.within(rows.back().truth) && s.stop.reason == StopReason::None && !s.interrupted;
    if (s.reached) {
        std::size_t k = rows.size();
        while (k > 0 && goal.within(rows[k - 1].truth)) --k;
        s.time_to_goal = rows[k].t;
    }
    bool entered = false;
    for (const ControlRow& r : rows) {
        if (!entered && goal.within(r.truth)) {
            entered = true;
            s.first_within = r.t;
        }
        if (entered) s.worst_overshoot = std::max(s.worst_overshoot, goal.error(r.truth));
    }
    double sum = 0;
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
        sum += rows[k].decision_seconds;
        s.decision_max = std::max(s.decision_max, rows[k].decision_seconds);
        if (k > 0 && (rows[k].motion != rows[k - 1].motion || rows[k].motion < 0)) ++s.switches;
    }
    s.decision_mean = rows.size() > 1 ? sum / static_cast<double>(rows.size() - 1) : 0;
    std::vector<double> d;
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) d.push_back(rows[k].decision_seconds);
    if (!d.empty()) {
        const std::size_t i = std::min(d.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(d.size())));
        std::nth_element(d.begin(), d.begin() + static_cast<long>(i), d.end());
        s.decision_p99 = d[i];
    }
}


// The loop's state between periods: the commanded scene, the camera, the rows, the part's plate-frame
// state (q, qd) on the last period's true plate `prev`/`last_truth`.
struct ControlLoop::State {
    Scene cmd;
    double Tt = 0;
    long periods = 0, k = 0;
    detail::LoopCamera cam;
    IntegrationOptions integration;
    Truth truth;
    std::vector<ControlRow> rows;
    StopEvent stop;
    Vec3 q, qd = Vec3::Zero();
    PlateMotion prev;
    Scene last_truth;
    State(const Scene& nominal, double Tt_, const std::optional<Camera>& camera)
        : cmd(nominal), Tt(Tt_), cam(camera, Tt_), last_truth(nominal) {}
};

ControlLoop::ControlLoop(const ControlModel& model, const Truth& truth, const std::optional<Camera>& camera, const Goal& goal,
                         const Vec3& q0, const ControlOptions& opt)
    : model_(&model), goal_(goal) {
    opt.validate();
    truth.validate();
    const double Tt = true_scene(truth, model.nominal, -1, 0).plate.T;
    const long periods = static_cast<long>(std::floor(opt.duration / Tt * (1 + 1e-12)));
    if (periods < 1 || periods > kMaxControlPeriods)
        throw std::invalid_argument("duration: expected 1 to " + std::to_string(kMaxControlPeriods) + " plate periods");
    st_ = std::make_unique<State>(model.nominal, Tt, camera);
    st_->periods = periods;
    st_->integration = opt.integration;
    st_->truth = truth;
    st_->q = q0;   // at rest on the first period's plate
    st_->rows.reserve(periods + 1);
}
ControlLoop::ControlLoop(ControlLoop&&) noexcept = default;
ControlLoop& ControlLoop::operator=(ControlLoop&&) noexcept = default;
ControlLoop::~ControlLoop() = default;

long ControlLoop::periods() const { return st_->periods; }
long ControlLoop::period() const { return st_->k; }
bool ControlLoop::done() const { return st_->k >= st_->periods || st_->stop.reason != StopReason::None; }
Observation ControlLoop::observe() const { return st_->cam.newest(st_->k * st_->Tt); }
Vec3 ControlLoop::true_pose() const { return world_pose_at_phase0(st_->last_truth, st_->q); }
const StopEvent& ControlLoop::stop() const { return st_->stop; }

void ControlLoop::step(const Decision& d, double decision_seconds) {
    State& S = *st_;
    if (done()) throw std::logic_error("the control loop has run its periods");
    if (!d.plate && (d.motion < 0 || d.motion >= model_->motions()))
        throw std::invalid_argument("decided motion " + std::to_string(d.motion) + ", not in the library");
    const long k = S.k;
    const double now = k * S.Tt;
    const Observation obs = S.cam.newest(now);
    S.cmd.plate = d.plate ? *d.plate : model_->library.motions[d.motion];
    const Scene tru = true_scene(S.truth, S.cmd, d.plate ? -1 : d.motion, k);
    if (k > 0) carry_state(tru.part, S.prev, tru.plate, S.q, S.qd);
    ControlRow row;
    row.t = now;
    if (obs.seen) row.observed = obs.q;
    row.truth = world_pose_at_phase0(tru, S.q);
    row.motion = d.plate ? -1 : d.motion;
    row.decision_seconds = decision_seconds;
    S.rows.push_back(row);
    const StopEvent stop = detail::run_period(tru, S.cam, now, S.Tt, k == 0, S.q, S.qd, S.integration);
    S.last_truth = tru;
    ++S.k;
    if (stop.reason != StopReason::None) {
        S.stop = stop;
        S.stop.t += now;
        return;
    }
    S.prev = tru.plate;
}

StopEvent detail::run_period(const Scene& tru, LoopCamera& cam, double now, double Tt, bool first, Vec3& q, Vec3& qd,
                             const IntegrationOptions& integration) {
    std::vector<double> times = cam.due(now, first);
    const std::size_t frames = times.size();
    times.push_back(Tt);
    times.erase(std::unique(times.begin(), times.end()), times.end());
    const Trajectory tr = simulate_at(tru, Dynamics::Full, q, qd, times, integration);
    for (std::size_t f = 0; f < frames && f < tr.samples.size(); ++f)
        if (tr.stop.reason == StopReason::None || f + 1 < tr.samples.size()) cam.film(tru, tr.samples[f].t, tr.samples[f].q);
    q = tr.samples.back().q;
    if (tr.stop.reason == StopReason::None) qd = tr.samples.back().qd;
    return tr.stop;
}

ControlSummary ControlLoop::summary(const std::string& policy, bool interrupted) const {
    ControlSummary s;
    s.policy = policy;
    s.periods = st_->k;
    s.stop = st_->stop;
    s.interrupted = interrupted;
    s.rows = st_->rows;
    ControlRow last;
    last.t = s.stop.reason != StopReason::None ? s.stop.t : s.periods * st_->Tt;
    last.truth = true_pose();   // (a stop's: at its time, taken at phase 0)
    s.rows.push_back(last);
    detail::summarise(s, goal_);
    return s;
}

ControlSummary run_control(const ControlModel& model, Policy& policy, const Truth& truth, const std::optional<Camera>& camera,
                           const Goal& goal, const Vec3& q0, const ControlOptions& opt, const std::function<bool()>& keep_going) {
    ControlLoop loop(model, truth, camera, goal, q0, opt);
    policy.reset(model, goal);
    using clock = std::chrono::steady_clock;
    while (!loop.done()) {
        if (keep_going && !keep_going()) return loop.summary(policy.name(), true);
        const Observation obs = loop.observe();
        const auto t0 = clock::now();
        const Decision d = policy.decide(obs, loop.period());
        const double spent = std::chrono::duration<double>(clock::now() - t0).count();
        loop.step(d, spent);
    }
    return loop.summary(policy.name());
}

void write_control_csv(std::ostream& out, const ControlSummary& s, const ControlModel& model, bool point) {
    out << "t [s],obs_s_x [m],obs_s_y [m]" << (point ? "" : ",obs_theta [rad]") << ",x [m],y [m]"
        << (point ? "" : ",heading [rad]") << ",motion,decision [s]\n";
    for (const ControlRow& r : s.rows) {
        out << shortest(r.t) << ',' << shortest(r.observed.x()) << ',' << shortest(r.observed.y());
        if (!point) out << ',' << shortest(r.observed.z());
        out << ',' << shortest(r.truth.x()) << ',' << shortest(r.truth.y());
        if (!point) out << ',' << shortest(r.truth.z());
        const std::string name = &r == &s.rows.back() ? "end" : r.motion < 0 ? "own" : model.library.names[r.motion];
        out << ',' << name << ',' << shortest(r.decision_seconds) << '\n';
    }
}

nlohmann::json control_summary_json(const ControlSummary& s, const ControlModel& model, const Goal& goal) {
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    nlohmann::json j;
    j["policy"] = s.policy;
    j["goal"] = goal.point ? nlohmann::json{goal.q.x(), goal.q.y()} : nlohmann::json{goal.q.x(), goal.q.y(), goal.q.z()};
    j["tolerance_m"] = goal.tolerance;
    if (!goal.point) j["tolerance_rad"] = goal.tolerance_theta;
    j["periods"] = s.periods;
    j["period_s"] = s.periods > 0 ? s.rows[1].t - s.rows[0].t : model.T();
    j["reached"] = s.reached;
    j["time_to_goal_s"] = num(s.time_to_goal);
    j["first_within_s"] = num(s.first_within);
    j["final_error_m"] = s.final_error;
    if (!goal.point) j["final_theta_error_rad"] = s.final_theta_error;
    j["worst_overshoot_m"] = s.worst_overshoot;
    j["switches"] = s.switches;
    j["decision_mean_s"] = s.decision_mean;
    j["decision_max_s"] = s.decision_max;
    j["decision_p99_s"] = s.decision_p99;
    j["motions"] = model.library.names;
    j["stop"] = s.stop.reason == StopReason::None ? nlohmann::json(nullptr) : nlohmann::json(s.stop.describe());
    j["interrupted"] = s.interrupted;
    return j;
}

}   // namespace plate
