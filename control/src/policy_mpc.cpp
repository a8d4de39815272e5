// The `mpc` policy (control.hpp): a receding-horizon search over sequences of library motions on the
// model's steps, corrected online by a gain and a drift fitted to the frames.
#include "plate/control.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace plate {

void MpcPolicyOptions::validate() const {
    if (horizon < 1 || horizon > kMaxMpcHorizon)
        throw std::invalid_argument("horizon: expected 1 to " + std::to_string(kMaxMpcHorizon) + " periods");
    if (!(switch_cost >= 0) || !std::isfinite(switch_cost)) throw std::invalid_argument("switch_cost: expected a number >= 0");
    if (!(forgetting > 0 && forgetting <= 1)) throw std::invalid_argument("forgetting: expected a number in (0, 1]");
    if (!(prior_travel > 0) || !std::isfinite(prior_travel)) throw std::invalid_argument("prior_travel: expected a number > 0");
    if (!(prior_frames > 0) || !std::isfinite(prior_frames)) throw std::invalid_argument("prior_frames: expected a number > 0");
    if (!(stop_radius >= 0) || !std::isfinite(stop_radius)) throw std::invalid_argument("stop_radius: expected a number >= 0");
    if (!(hysteresis >= 0) || !std::isfinite(hysteresis)) throw std::invalid_argument("hysteresis: expected a number >= 0");
}

namespace {

class MpcPolicy : public Policy {
public:
    explicit MpcPolicy(const MpcPolicyOptions& opt) : opt_(opt) { opt_.validate(); }
    std::string name() const override { return "mpc"; }

    void reset(const ControlModel& model, const Goal& goal) override {
        long sequences = 1;
        for (int h = 0; h < opt_.horizon; ++h) {
            sequences *= model.motions();
            if (sequences > kMaxMpcSequences)
                throw std::invalid_argument("mpc: " + std::to_string(model.motions()) + " motions over a horizon of " +
                                            std::to_string(opt_.horizon) + " periods are more than " +
                                            std::to_string(kMaxMpcSequences) + " sequences: shorten the horizon");
        }
        model_ = &model;
        goal_ = goal;
        chosen_.clear();
        chosen_.reserve(1024);
        normal_.setZero();
        rhs_.setZero();
        estimate_ = {};
        have_frame_ = false;
        last_stamp_ = -1;
    }

    Decision decide(const Observation& obs, long period) override {
        if (!model_) throw std::logic_error("mpc policy: decide() before reset()");
        const ControlModel& m = *model_;
        const int still = m.library.still, current = chosen_.empty() ? -1 : chosen_.back();
        int pick = still >= 0 ? still : 0;
        if (obs.seen) {
            if (opt_.correct && obs.stamp != last_stamp_) fit(obs);
            const Vec3 q = advance(obs.q, obs.state_time, period * m.T());
            const double d = goal_.distance(q);
            if (still >= 0 && (d < opt_.stop_radius || (current == still && d < opt_.stop_radius + opt_.hysteresis)))
                pick = still;
            else
                pick = search(q, current);
        }
        if (static_cast<long>(chosen_.size()) <= period) chosen_.resize(period + 1, pick);
        chosen_[period] = pick;
        return {pick, std::nullopt};
    }

    MpcEstimate estimate() const { return estimate_; }

private:
    // One period's corrected step on motion `to` after `from`.
    Vec3 step(int from, int to, const Vec3& q) const {
        Vec3 s = estimate_.gain * model_->step(from, to, q);
        s.x() += estimate_.drift.x();
        s.y() += estimate_.drift.y();
        return s;
    }

    // q at time t0 carried to t1 along the motions chosen for the periods in between (a share of a period
    // by its share of the step): on the corrected model, or the nominal one (the fit's regressor).
    Vec3 advance(Vec3 q, double t0, double t1, bool corrected = true) const {
        const double T = model_->T();
        double t = t0;
        while (t < t1 - 1e-9 * T) {
            const long j = static_cast<long>(std::floor(t / T + 1e-9));
            const double end = std::min((j + 1) * T, t1);
            if (j >= 0 && j < static_cast<long>(chosen_.size())) {
                const int from = j > 0 ? chosen_[j - 1] : -1;
                q += (corrected ? step(from, chosen_[j], q) : model_->step(from, chosen_[j], q)) * ((end - t) / T);
            }
            t = end;
        }
        return q;
    }

    // A new frame: the pair with the previous one enters the forgotten least squares for (gain, drift).
    void fit(const Observation& obs) {
        last_stamp_ = obs.stamp;
        if (have_frame_ && obs.state_time > frame_time_) {
            const Vec3 seen = obs.q - frame_q_;
            const Vec3 model = advance(frame_q_, frame_time_, obs.state_time, false) - frame_q_;
            const double periods = (obs.state_time - frame_time_) / model_->T();
            normal_ *= opt_.forgetting;
            rhs_ *= opt_.forgetting;
            for (int a = 0; a < 2; ++a) {
                Eigen::Vector3d phi(model[a], a == 0 ? periods : 0.0, a == 1 ? periods : 0.0);
                normal_ += phi * phi.transpose();
                rhs_ += phi * seen[a];
            }
            if (!model_->nominal.part.point) {   // a rigid part's turn: the same gain, in radians weighted to metres
                const double w = goal_.theta_weight;
                const Eigen::Vector3d phi(w * model[2], 0.0, 0.0);
                normal_ += phi * phi.transpose();
                rhs_ += phi * (w * wrap_angle(seen[2]));
            }
            ++estimate_.frames;
            const double pg = opt_.prior_travel * opt_.prior_travel, pd = opt_.prior_frames;
            const Eigen::Matrix3d prior = Eigen::Vector3d(pg, pd, pd).asDiagonal();
            const Eigen::Vector3d theta = (normal_ + prior).ldlt().solve(rhs_ + prior * Eigen::Vector3d(1, 0, 0));
            estimate_.gain = theta[0];
            estimate_.drift = Vec2(theta[1], theta[2]);
        }
        have_frame_ = true;
        frame_q_ = obs.q;
        frame_time_ = obs.state_time;
    }

    // The best sequence's first motion: depth-first over the tree of sequences, the cost of a prefix
    // carried down (distance after each period, switch_cost per switch; the mean over the horizon).
    int search(const Vec3& q, int current) {
        best_cost_ = std::numeric_limits<double>::infinity();
        best_first_ = 0;
        descend(q, current, 0, 0.0, -1);
        return best_first_;
    }
    void descend(const Vec3& q, int previous, int depth, double cost, int first) {
        if (depth == opt_.horizon) {
            if (cost < best_cost_) {
                best_cost_ = cost;
                best_first_ = first;
            }
            return;
        }
        if (cost >= best_cost_) return;   // (costs only grow down the tree)
        for (int k = 0; k < model_->motions(); ++k) {
            const Vec3 next = q + step(previous, k, q);
            const double c =
                cost + (goal_.distance(next) + (previous >= 0 && k != previous ? opt_.switch_cost : 0.0)) / opt_.horizon;
            descend(next, k, depth + 1, c, depth == 0 ? k : first);
        }
    }

    MpcPolicyOptions opt_;
    const ControlModel* model_ = nullptr;
    Goal goal_;
    std::vector<int> chosen_;
    Eigen::Matrix3d normal_ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs_ = Eigen::Vector3d::Zero();
    MpcEstimate estimate_;
    bool have_frame_ = false;
    Vec3 frame_q_ = Vec3::Zero();
    double frame_time_ = 0, last_stamp_ = -1;
    double best_cost_ = 0;
    int best_first_ = 0;
};

}   // namespace

std::unique_ptr<Policy> make_mpc_policy(const MpcPolicyOptions& opt) { return std::make_unique<MpcPolicy>(opt); }

MpcEstimate mpc_estimate(const Policy& mpc) {
    const auto* p = dynamic_cast<const MpcPolicy*>(&mpc);
    if (!p) throw std::invalid_argument("mpc_estimate: not an mpc policy");
    return p->estimate();
}

}   // namespace plate
