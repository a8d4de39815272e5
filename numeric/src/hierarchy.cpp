#include "plate/hierarchy.hpp"

#include "plate/field.hpp"
#include "plate/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace plate {

const char* part_model_name(PartModel p) {
    switch (p) {
        case PartModel::Point: return "point";
        case PartModel::Thin: return "thin";
        case PartModel::Thick: return "thick";
    }
    return "?";
}

std::string Rung::name() const { return std::string(part_model_name(part)) + " / " + dynamics_name(dynamics); }

Scene simplified(const Scene& sc, PartModel p) {
    Scene s = sc;
    if (p == PartModel::Thick || sc.part.point) return s;
    if (p == PartModel::Point) {
        // One contact at the centre of mass carrying the whole weight, with the contacts' mean friction.
        s.part.point = true;
        s.part.mu = Vec3(sc.part.mu.mean(), 0, 0);
        return s;
    }
    // Thin: the contacts moved up into the plane of the centre of mass, the products of inertia
    // that couple the normal forces to the rotation dropped (Appendix A).
    for (auto& c : s.part.c) c.z() = 0;
    s.part.J(0, 2) = s.part.J(2, 0) = 0;
    s.part.J(1, 2) = s.part.J(2, 1) = 0;
    return s;
}

std::string ModelChoice::explain() const {
    std::ostringstream o;
    o.precision(3);
    o << "auto model (tolerance " << tol << "): picked " << picked.name()
      << (any_simplification ? "" : " (no simplification is within the tolerance)") << "\n";
    for (const auto& r : rungs) {
        o << "  " << r.name() << ": ";
        if (r.ok) o << "error " << r.error << ", " << r.seconds << " s";
        else o << "did not run to the end (" << r.note << ")";
        o << "\n";
    }
    return o.str();
}

const Rung& ModelChoice::pick(double t) const {
    const Rung& ref = rungs.back();
    for (const auto& r : rungs)
        if (&r != &ref && r.ok && r.error <= t && r.seconds < ref.seconds) return r;
    return ref;
}

namespace {

// Where the part is after `duration`, by one rung.
Rung run_rung(const Scene& sc, PartModel p, Dynamics d, const Vec3& q0, double duration, Vec3& q_end) {
    Rung r;
    r.part = p;
    r.dynamics = d;
    const Scene s = simplified(sc, p);
    const auto t0 = std::chrono::steady_clock::now();
    Trajectory tr;
    if (d == Dynamics::ReducedU) {
        LimitCycleOptions lo;
        tr = field_curve(s, q0, duration, duration, lo, std::min(s.plate.T, duration / 20));
    } else {
        tr = simulate(s, d, q0, Vec3::Zero(), duration, duration);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.ok = tr.stop.reason == StopReason::None && !tr.samples.empty();
    if (!r.ok) r.note = tr.stop.describe();
    else q_end = tr.samples.back().q;
    return r;
}

}  // namespace

ModelChoice choose_model(const Scene& sc, const Vec3& q0, double duration, double tol) {
    ModelChoice mc;
    mc.tol = tol;
    std::vector<PartModel> parts{PartModel::Point};
    if (!sc.part.point) {
        parts.push_back(PartModel::Thin);
        if (!sc.part.thin()) parts.push_back(PartModel::Thick);
    }
    const PartModel own = parts.back();
    Vec3 q_ref;
    Rung ref = run_rung(sc, own, Dynamics::Full, q0, duration, q_ref);
    if (!ref.ok) {
        // The reference leaves the model (sticking, contact loss): no simplification can be judged.
        mc.picked = ref;
        mc.rungs = {ref};
        return mc;
    }
    const double rho = sc.part.rho();
    for (Dynamics d : {Dynamics::ReducedU, Dynamics::U, Dynamics::Full}) {
        for (PartModel p : parts) {
            if (p == own && d == Dynamics::Full) continue;
            Vec3 q;
            Rung r = run_rung(sc, p, d, q0, duration, q);
            if (r.ok) r.error = std::max({std::abs(q[0] - q_ref[0]) / rho, std::abs(q[1] - q_ref[1]) / rho,
                                          std::abs(wrap_angle(q[2] - q_ref[2]))});
            mc.rungs.push_back(r);
        }
    }
    std::sort(mc.rungs.begin(), mc.rungs.end(), [](const Rung& a, const Rung& b) { return a.seconds < b.seconds; });
    mc.rungs.push_back(ref);
    const Rung& picked = mc.pick(tol);
    mc.picked = picked;
    mc.any_simplification = &picked != &mc.rungs.back();
    return mc;
}

}  // namespace plate
