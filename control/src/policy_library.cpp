// The `library` policy: each period the library motion that, kept, stays nearest the goal (a rigid part:
// turn first, then steer the position with the motions that keep its orientation).
#include "internal.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace plate {

void LibraryPolicyOptions::validate() const {
    if (!(stop_radius >= 0) || !std::isfinite(stop_radius)) throw std::invalid_argument("stop_radius: expected a number >= 0");
    if (!(hysteresis >= 0) || !std::isfinite(hysteresis)) throw std::invalid_argument("hysteresis: expected a number >= 0");
    if (horizon < 1 || horizon > kMaxHorizon)
        throw std::invalid_argument("horizon: expected 1 to " + std::to_string(kMaxHorizon) + " periods");
    if (!(turn_exit > 0) || !(turn_enter > turn_exit) || !(turn_enter <= 1))
        throw std::invalid_argument("turn_enter, turn_exit: expected 0 < turn_exit < turn_enter <= 1");
}

namespace {

class LibraryPolicy : public Policy {
public:
    explicit LibraryPolicy(const LibraryPolicyOptions& opt) : opt_(opt) { opt_.validate(); }
    std::string name() const override { return "library"; }

    void reset(const ControlModel& model, const Goal& goal) override {
        model_ = &model;
        goal_ = goal;
        chosen_.clear();
        chosen_.reserve(1024);
        still_since_ = -1;
        rest_ = detail::RestAverage{};
        keeps_.assign(model.motions(), false);
        bool turns = false, carries = false;   // some motion turns the part; some carries it without
        for (int k = 0; k < model.motions(); ++k) {
            keeps_[k] = model.fields[k].uniform;
            turns = turns || !keeps_[k];
            carries = carries || (keeps_[k] && k != model.library.still);
        }
        rigid_ = opt_.two_phase && !model.nominal.part.point && turns && carries;
        position_goal_ = goal;
        position_goal_.point = true;   // its distance: the position's alone
        turning_ = false;
        keep_since_ = 0;
        theta_sum_ = 0;
        theta_frames_ = 0;
        theta_stamp_ = -1;
    }

    Decision decide(const Observation& obs, long period) override {
        if (!model_) throw std::logic_error("library policy: decide() before reset()");
        const ControlModel& m = *model_;
        const int still = m.library.still;
        int pick = still >= 0 ? still : 0;   // nothing seen yet: hold still if the library can
        if (obs.seen) pick = rigid_ ? choose_rigid(obs, period) : choose(estimate(obs, period), goal_, false);
        if (static_cast<long>(chosen_.size()) <= period) chosen_.resize(period + 1, pick);
        chosen_[period] = pick;
        if (pick != still) {
            still_since_ = -1;
        } else if (still_since_ < 0) {
            still_since_ = period;
            rest_.restart();
        }
        return {pick, std::nullopt};
    }

private:
    // Where the part is at the decision's time. On the still plate the part comes to rest within a period
    // and stays: from the second period on, the frames it shows are averaged (the camera's noise
    // shrinks as 1/sqrt(n), and a noisy frame alone does not start the plate again).
    Vec3 estimate(const Observation& obs, long period) {
        const double T = model_->T();
        if (still_since_ >= 0 && obs.state_time >= (still_since_ + 1) * T - 1e-9 * T) return rest_.add(obs);
        return detail::predict_forward(*model_, chosen_, obs, period);
    }

    // The mean distance to the goal over the next `horizon` periods on motion k kept, the first period
    // from `current` (its switch's kick, ControlModel::transitions). Kept, a motion that overshoots or
    // that lands near the goal only by switching again costs more than one that stays there.
    // (theta: true, the mean orientation error instead of the goal's distance.)
    double horizon_cost(Vec3 q, int current, int k, const Goal& goal, bool theta = false) const {
        const ControlModel& m = *model_;
        double sum = 0;
        for (int h = 0; h < opt_.horizon; ++h) {
            q += m.step(h == 0 ? current : k, k, q);
            sum += theta ? goal.theta_error(q) : goal.distance(q);
        }
        return sum / opt_.horizon;
    }

    int choose(const Vec3& q, const Goal& goal, bool keeping_only) {
        const ControlModel& m = *model_;
        const int still = m.library.still, current = chosen_.empty() ? -1 : chosen_.back();
        // Inside the stop radius the still plate (left again only beyond the radius plus the hysteresis).
        const double d = goal.distance(q);
        if (still >= 0 && (d < opt_.stop_radius || (current == still && d < opt_.stop_radius + opt_.hysteresis))) return still;
        int best = 0;
        double best_cost = std::numeric_limits<double>::infinity(), current_cost = best_cost;
        for (int k = 0; k < m.motions(); ++k) {
            if (keeping_only && !keeps_[k]) continue;
            const double cost = horizon_cost(q, current, k, goal);
            if (k == current) current_cost = cost;
            if (cost < best_cost) {
                best_cost = cost;
                best = k;
            }
        }
        return current >= 0 && current != still && current_cost <= best_cost + opt_.hysteresis ? current : best;
    }

    // A rigid part's two phases (LibraryPolicyOptions::two_phase): turn while the orientation is off, then
    // steer the position with the motions that keep it.
    int choose_rigid(const Observation& obs, long period) {
        const ControlModel& m = *model_;
        const double T = m.T(), tol = goal_.tolerance_theta;
        Vec3 q = estimate(obs, period);
        // Since the turning ended the orientation has not changed: the frames showing it are averaged.
        if (!turning_ && obs.state_time >= keep_since_ * T - 1e-9 * T) {
            if (obs.stamp != theta_stamp_) {
                theta_sum_ += wrap_angle(obs.q.z() - goal_.q.z());
                ++theta_frames_;
                theta_stamp_ = obs.stamp;
            }
            q.z() = goal_.q.z() + theta_sum_ / theta_frames_;
        }
        const double e = goal_.theta_error(q);
        if (turning_ && e < opt_.turn_exit * tol)
            stop_turning(period);
        else if (!turning_ && e > opt_.turn_enter * tol) {
            turning_ = true;
        }
        if (turning_) {
            const int current = chosen_.empty() ? -1 : chosen_.back();
            int best = 0;
            double best_cost = std::numeric_limits<double>::infinity();
            for (int k = 0; k < m.motions(); ++k) {
                if (keeps_[k]) continue;
                const double cost = horizon_cost(q, current, k, goal_, true);
                if (cost < best_cost) {
                    best_cost = cost;
                    best = k;
                }
            }
            // Within turn_enter and no turn lands nearer (their steps too coarse here): stop turning.
            if (best_cost < e || e > opt_.turn_enter * tol) return best;
            stop_turning(period);
        }
        return choose(q, position_goal_, true);
    }

    // The orientation is kept from period k on: its frames are averaged from then.
    void stop_turning(long k) {
        turning_ = false;
        keep_since_ = k;
        theta_sum_ = 0;
        theta_frames_ = 0;
    }

    LibraryPolicyOptions opt_;
    const ControlModel* model_ = nullptr;
    Goal goal_;
    std::vector<int> chosen_;    // the motion chosen for each period so far
    long still_since_ = -1;      // the period the current stretch on the still plate began (-1: moving)
    detail::RestAverage rest_;   // the frames while the part rests on the still plate
    // Rigid parts, two phases: which motions keep the orientation, the phase, and the orientation's frames
    // since the turning ended (period keep_since_).
    std::vector<bool> keeps_;
    bool rigid_ = false, turning_ = false;
    Goal position_goal_;
    long keep_since_ = 0;
    double theta_sum_ = 0;
    int theta_frames_ = 0;
    double theta_stamp_ = -1;
};

}   // namespace

Vec3 detail::predict_forward(const ControlModel& m, const std::vector<int>& chosen, const Observation& obs, long period) {
    const double T = m.T(), now = period * T;
    Vec3 q = obs.q;
    double t = obs.state_time;
    while (t < now - 1e-9 * T) {
        const long j = static_cast<long>(std::floor(t / T + 1e-9));
        const double end = std::min((j + 1) * T, now);
        if (j >= 0 && j < static_cast<long>(chosen.size()))
            q += m.step(j > 0 ? chosen[j - 1] : -1, chosen[j], q) * ((end - t) / T);
        t = end;
    }
    return q;
}

std::unique_ptr<Policy> make_library_policy(const LibraryPolicyOptions& opt) { return std::make_unique<LibraryPolicy>(opt); }

}   // namespace plate
