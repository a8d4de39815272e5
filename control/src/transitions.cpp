// The first period after a switch (ControlModel::transitions): the part leaves one motion's cycle with
// its velocity, which the next motion's cycle does not share, so that period's step is not xi T.
#include "plate/control.hpp"

#include "internal.hpp"

#include "plate/scene_io.hpp"

#include <stdexcept>

namespace plate {

namespace {

// The part's plate-frame velocity at phase 0 on motion `sc`'s cycle near q: the nominal full dynamics
// from rest at q for kSettlePeriods periods (a still plate: at rest).
Vec3 cycle_velocity(const Scene& sc, const Vec3& q, const IntegrationOptions& io) {
    if (sc.plate.harmonics.empty()) return Vec3::Zero();
    const Trajectory tr = simulate_at(sc, Dynamics::Full, q, Vec3::Zero(), {kSettlePeriods * sc.plate.T}, io);
    if (tr.stop.reason != StopReason::None) throw InputError(sc.name + ": " + tr.stop.describe() + " while settling");
    return tr.samples.back().qd;
}

// The world displacement over the first period on b of a part at q that was on a's cycle (velocity v_a).
Vec3 first_period_step(const Scene& a, const Scene& b, const Vec3& q, const Vec3& v_a, const IntegrationOptions& io) {
    Vec3 s = q, sd = v_a;
    const Vec3 start = world_pose_at_phase0(a, s);
    carry_state(b.part, a.plate, b.plate, s, sd);
    const Trajectory tr = simulate_at(b, Dynamics::Full, s, sd, {b.plate.T}, io);
    if (tr.stop.reason != StopReason::None) throw InputError(b.name + ": " + tr.stop.describe() + " after a switch");
    return world_pose_at_phase0(b, tr.samples.back().q) - start;
}

}   // namespace

Vec3 world_pose_at_phase0(const Scene& sc, const Vec3& q) {
    PlateOrientation R1(sc.plate);
    return world_pose(sc, 0, q, R1.at(0));
}

namespace detail {

void add_transitions(ControlModel& m, const ControlModelOptions& opt) {
    const int M = m.motions();
    m.transitions.assign(static_cast<std::size_t>(M) * M, MotionField{});
    const IntegrationOptions io;
    const bool grid_pairs = opt.grid_transitions.value_or(m.nominal.part.point);
    GridSpec g = opt.grid;
    if (m.nominal.part.point) g.nth = 1;
    for (int a = 0; a < M; ++a) {
        Scene sa = m.nominal;
        sa.plate = m.library.motions[a];
        // a's cycle velocity: one for a uniform field, else one per grid point.
        std::vector<Vec3> v_a;
        if (m.fields[a].uniform)
            v_a.assign(g.size(), cycle_velocity(sa, Vec3::Zero(), io));
        else if (grid_pairs)
            for (int n = 0; n < g.size(); ++n)
                v_a.push_back(cycle_velocity(sa, g.at(n / (g.ny * g.nth), n / g.nth % g.ny, n % g.nth), io));
        for (int b = 0; b < M; ++b) {
            if (a == b) continue;
            Scene sb = m.nominal;
            sb.plate = m.library.motions[b];
            MotionField& f = m.transitions[a * M + b];
            // Stored as a velocity (step / T), so that at() reads it as the fields are read.
            if (m.fields[a].uniform && m.fields[b].uniform) {
                f.uniform = true;
                f.twist = {first_period_step(sa, sb, Vec3::Zero(), v_a[0], io) / m.T()};
                continue;
            }
            if (!grid_pairs) continue;   // left empty: ControlModel::step takes b's field
            f.grid = g;
            f.twist.resize(g.size());
            for (int i = 0; i < g.nx; ++i)
                for (int j = 0; j < g.ny; ++j)
                    for (int k = 0; k < g.nth; ++k)
                        f.twist[g.index(i, j, k)] = first_period_step(sa, sb, g.at(i, j, k), v_a[g.index(i, j, k)], io) / m.T();
        }
    }
}

}   // namespace detail

}   // namespace plate
