// Internal to the control library: what its files share beyond the public API (the transition table, the
// loop's camera, the summary of rows, the latency bridged by prediction).
#pragma once

#include "plate/control.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <vector>

namespace plate::detail {

// Fills m.transitions (control.hpp) from m.fields: pairs of uniform fields once, others on opt.grid.
void add_transitions(ControlModel& m, const ControlModelOptions& opt);

// A frame the camera took: when it arrives (its stamp) and what it shows.
struct Frame {
    double stamp, state_time;
    Vec3 q;
};

// The camera of the loop: one stroboscopic frame per period of the true plate (period Tt), drawing its
// drop and noise per frame in the order observe.hpp's film() does.
class LoopCamera {
public:
    LoopCamera(const std::optional<Camera>& cam, double Tt) : cam_(cam.value_or(Camera{})), Tt_(Tt), rng_(cam_.seed) {
        if (!cam) {
            cam_.per_period = 1;
        } else {
            cam_.validate();
            if (!cam_.stroboscopic() || cam_.per_period != 1)
                throw InputError(cam_.source + ": stroboscopic.per_period: the loop's camera takes one frame per plate period");
        }
        // The first frame whose state time is >= 0.
        while (state_time(next_) < -1e-12 * Tt_) ++next_;
    }
    // The frames whose state times lie in (t0, t0 + Tt] (t0 = 0 also takes the start's), as times within
    // the period.
    std::vector<double> due(double t0, bool first) const {
        std::vector<double> out;
        for (long j = next_;; ++j) {
            const double s = state_time(j) - t0;
            if (s > Tt_ * (1 + 1e-12)) break;
            if (s > 0 || (first && s >= -1e-12 * Tt_)) out.push_back(std::clamp(s, 0.0, Tt_));
        }
        return out;
    }
    // Films the next frame: the state q (plate frame) of `sc` at time tau within its period.
    void film(const Scene& sc, double tau, const Vec3& q) {
        const double stamp = stamp_of(next_++);
        const bool dropped = rng_.uniform() < cam_.drop;
        const double sd = cam_.noise_xy_mm * 1e-3, sdt = cam_.noise_theta_mrad * 1e-3;
        const Vec3 e(standard_normal(rng_) * sd, standard_normal(rng_) * sd, standard_normal(rng_) * sdt);
        if (dropped) return;
        Vec3 x = q;
        if (cam_.frame == CameraFrame::world) {
            PlateOrientation R1(sc.plate);
            x = world_pose(sc, tau, q, R1.at(tau));
        }
        x += e;
        if (sc.part.point) x.z() = 0;
        frames_.push_back({stamp, stamp - cam_.latency, x});
    }
    // The newest frame stamped at or before t.
    Observation newest(double t) const {
        Observation o;
        o.t = t;
        for (auto it = frames_.rbegin(); it != frames_.rend(); ++it)
            if (it->stamp <= t + 1e-12 * Tt_) {
                o.seen = true;
                o.stamp = it->stamp;
                o.state_time = it->state_time;
                o.q = it->q;
                break;
            }
        return o;
    }

private:
    double stamp_of(long j) const { return (j + cam_.phase) * Tt_; }
    double state_time(long j) const { return stamp_of(j) - cam_.latency; }
    Camera cam_;
    double Tt_;
    Rng rng_;
    long next_ = 0;
    std::vector<Frame> frames_;
};

// One period of the true plate `tru` for one part: the full dynamics from its plate-frame (q, qd) at t = now
// (period `first`: also the start's frame), the camera filming the frames due within it; (q, qd) become the
// period's end (qd left as it was when the dynamics stopped). Returns the stop (its t within the period).
StopEvent run_period(const Scene& tru, LoopCamera& cam, double now, double Tt, bool first, Vec3& q, Vec3& qd,
                     const IntegrationOptions& integration);

// A part's frames averaged while it rests on the still plate: from the still stretch's second period on the
// part is at rest, and the camera's noise shrinks as 1/sqrt(n). (The last frame's stamp survives a restart.)
struct RestAverage {
    Vec3 sum = Vec3::Zero();
    int frames = 0;
    double last_stamp = -1;
    void restart() {
        sum.setZero();
        frames = 0;
    }
    Vec3 add(const Observation& obs) {
        if (obs.stamp != last_stamp) {
            sum += obs.q;
            ++frames;
            last_stamp = obs.stamp;
        }
        return sum / frames;
    }
};

// Time to goal, first entry, worst overshoot, switches and decision times of s.rows (ControlSummary).
void summarise(ControlSummary& s, const Goal& goal);

// The observed configuration carried forward from the time it shows to the decision's, k T, along the
// model's steps of the motion chosen for each period in between (`chosen`; one Euler step per period or
// part of one).
Vec3 predict_forward(const ControlModel& m, const std::vector<int>& chosen, const Observation& obs, long period);

}   // namespace plate::detail
