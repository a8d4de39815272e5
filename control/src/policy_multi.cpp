// The `library` policy for several point parts: each period the one library motion whose predicted paths
// have the least weighted sum of the parts' distances to their goals.
#include "plate/control_multi.hpp"

#include "internal.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace plate {
namespace {

class MultiLibraryPolicy : public MultiPolicy {
public:
    MultiLibraryPolicy(const LibraryPolicyOptions& opt, Aggregate aggregate) : opt_(opt), aggregate_(aggregate) {
        opt_.validate();
    }
    std::string name() const override { return "library"; }

    void reset(const ControlModel& model, const MultiParts& parts) override {
        model_ = &model;
        parts_ = parts;
        goals_.clear();
        for (std::size_t i = 0; i < parts.parts.size(); ++i) goals_.push_back(parts.goal(i));
        chosen_.clear();
        chosen_.reserve(1024);
        still_since_ = -1;
        rest_.assign(parts.parts.size(), detail::RestAverage{});
        keeps_.assign(model.motions(), false);
        bool shapes = false, carries = false;   // some motion changes the parts' shape; some carries them without
        for (int k = 0; k < model.motions(); ++k) {
            keeps_[k] = model.fields[k].uniform;
            shapes = shapes || !keeps_[k];
            carries = carries || (keeps_[k] && k != model.library.still);
        }
        two_phase_ = opt_.two_phase && parts.parts.size() > 1 && shapes && carries;
        shaping_ = false;
    }

    Decision decide(const std::vector<Observation>& obs, long period) override {
        if (!model_) throw std::logic_error("multi-part library policy: decide() before reset()");
        if (obs.size() != goals_.size())
            throw std::invalid_argument("multi-part library policy: " + std::to_string(obs.size()) + " observations for " +
                                        std::to_string(goals_.size()) + " parts");
        const int still = model_->library.still;
        int pick = still >= 0 ? still : 0;   // a part not seen yet: hold still if the library can
        bool seen = true;
        for (const Observation& o : obs) seen = seen && o.seen;
        if (seen) {
            std::vector<Vec3> q;
            for (std::size_t i = 0; i < obs.size(); ++i) q.push_back(estimate(i, obs[i], period));
            pick = choose(q);
        }
        if (static_cast<long>(chosen_.size()) <= period) chosen_.resize(period + 1, pick);
        chosen_[period] = pick;
        if (pick != still) {
            still_since_ = -1;
        } else if (still_since_ < 0) {
            still_since_ = period;
            for (detail::RestAverage& r : rest_) r.restart();
        }
        return {pick, std::nullopt};
    }

private:
    // Where part i is at the decision's time: its frames averaged from the second still period on, else
    // its frame predicted forward over the latency.
    Vec3 estimate(std::size_t i, const Observation& obs, long period) {
        const double T = model_->T();
        if (still_since_ >= 0 && obs.state_time >= (still_since_ + 1) * T - 1e-9 * T) return rest_[i].add(obs);
        return detail::predict_forward(*model_, chosen_, obs, period);
    }

    // The weighted sum (or the largest: Aggregate::max) over the parts of the mean distance over the horizon on motion k kept,
    // the first period from `current`.
    double cost(const std::vector<Vec3>& q0, int current, int k) const {
        const ControlModel& m = *model_;
        double total = 0;
        for (std::size_t i = 0; i < q0.size(); ++i) {
            Vec3 q = q0[i];
            double sum = 0;
            for (int h = 0; h < opt_.horizon; ++h) {
                q += m.step(h == 0 ? current : k, k, q);
                sum += goals_[i].distance(q);
            }
            const double part = parts_.parts[i].weight * (sum / opt_.horizon);
            total = aggregate_ == Aggregate::sum ? total + part : std::max(total, part);
        }
        return total;
    }

    // The parts' shape error: sum_i w_i |e_i - e_mean|, e_i = q_i - g_i (positions), e_mean their weighted
    // mean. A uniform field moves every e_i alike and leaves it as it is; two parts of equal weight:
    // |(p_2 - p_1) - (g_2 - g_1)|, how far their separation is from the goals'.
    double shape_error(const std::vector<Vec3>& q) const {
        Vec2 mean = Vec2::Zero();
        double w = 0, sum = 0;
        for (std::size_t i = 0; i < q.size(); ++i) {
            mean += parts_.parts[i].weight * (q[i] - goals_[i].q).head<2>();
            w += parts_.parts[i].weight;
        }
        mean /= w;
        for (std::size_t i = 0; i < q.size(); ++i) sum += parts_.parts[i].weight * ((q[i] - goals_[i].q).head<2>() - mean).norm();
        return sum;
    }

    // The mean shape error over the horizon on motion k kept, the first period from `current`.
    double shape_cost(std::vector<Vec3> q, int current, int k) const {
        double sum = 0;
        for (int h = 0; h < opt_.horizon; ++h) {
            for (Vec3& p : q) p += model_->step(h == 0 ? current : k, k, p);
            sum += shape_error(q);
        }
        return sum / opt_.horizon;
    }

    // Two phases (LibraryPolicyOptions::two_phase, several parts): while the shape error exceeds turn_enter
    // of the tolerance, the motion that changes the shape (a field that is not uniform) whose shape error,
    // kept for the horizon, is least on average, until within turn_exit or until none lands nearer; then the
    // parts are carried with the motions that keep the shape (the uniform fields: transports, the still plate)
    // or keep its error within turn_enter over the horizon (a sink whose fixed point both goals share).
    int choose(const std::vector<Vec3>& q) {
        const ControlModel& m = *model_;
        const int still = m.library.still, current = chosen_.empty() ? -1 : chosen_.back();
        // Every part inside the stop radius: the still plate (left when one is beyond radius + hysteresis).
        double d = 0;
        for (std::size_t i = 0; i < q.size(); ++i) d = std::max(d, goals_[i].distance(q[i]));
        if (still >= 0 && (d < opt_.stop_radius || (current == still && d < opt_.stop_radius + opt_.hysteresis))) return still;
        if (two_phase_) {
            const double e = shape_error(q), tol = parts_.tolerance;
            if (shaping_ && e < opt_.turn_exit * tol)
                shaping_ = false;
            else if (!shaping_ && e > opt_.turn_enter * tol)
                shaping_ = true;
            if (shaping_) {
                int best = 0;
                double best_cost = std::numeric_limits<double>::infinity();
                for (int k = 0; k < m.motions(); ++k) {
                    if (keeps_[k]) continue;
                    const double c = shape_cost(q, current, k);
                    if (c < best_cost) {
                        best_cost = c;
                        best = k;
                    }
                }
                if (best_cost < e || e > opt_.turn_enter * tol) return best;
                shaping_ = false;
            }
        }
        int best = 0;
        double best_cost = std::numeric_limits<double>::infinity(), current_cost = best_cost;
        for (int k = 0; k < m.motions(); ++k) {
            if (two_phase_ && !keeps_[k] && shape_cost(q, current, k) > opt_.turn_enter * parts_.tolerance) continue;
            const double c = cost(q, current, k);
            if (k == current) current_cost = c;
            if (c < best_cost) {
                best_cost = c;
                best = k;
            }
        }
        return current >= 0 && current != still && current_cost <= best_cost + opt_.hysteresis ? current : best;
    }

    LibraryPolicyOptions opt_;
    Aggregate aggregate_;
    const ControlModel* model_ = nullptr;
    MultiParts parts_;
    std::vector<Goal> goals_;
    std::vector<int> chosen_;   // the motion chosen for each period so far
    long still_since_ = -1;     // the period the current stretch on the still plate began (-1: moving)
    std::vector<detail::RestAverage> rest_;
    // Two phases: which motions keep the shape (uniform fields), whether they are used, the phase.
    std::vector<bool> keeps_;
    bool two_phase_ = false, shaping_ = false;
};

}   // namespace

std::unique_ptr<MultiPolicy> make_multi_library_policy(const LibraryPolicyOptions& opt, Aggregate aggregate) {
    return std::make_unique<MultiLibraryPolicy>(opt, aggregate);
}

}   // namespace plate
