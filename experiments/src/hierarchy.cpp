#include "plate/hierarchy.hpp"

#include "plate/field.hpp"
#include "plate/simulate.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace plate {

const char* part_model_name(PartModel p) {
    switch (p) {
        case PartModel::Point:
            return "point";
        case PartModel::Thin:
            return "thin";
        case PartModel::Thick:
            return "thick";
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
        if (r.ok)
            o << "error " << r.error << ", " << r.seconds << " s";
        else
            o << "did not run to the end (" << r.note << ")";
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
    r.work = tr.stats.rhs_evals;
    r.ok = tr.stop.reason == StopReason::None && !tr.samples.empty();
    if (!r.ok)
        r.note = tr.stop.describe();
    else
        q_end = tr.samples.back().q;
    return r;
}

}   // namespace

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
            if (r.ok)
                r.error = std::max(
                    {std::abs(q[0] - q_ref[0]) / rho, std::abs(q[1] - q_ref[1]) / rho, std::abs(wrap_angle(q[2] - q_ref[2]))});
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

}   // namespace plate

namespace plate {

double ModelEstimate::growth() const {
    const double x = lambda * duration;
    return std::abs(x) > 1e-8 ? std::expm1(x) / x : 1.0;
}

double ModelEstimate::part_term(PartModel p, PartModel own) const {
    if (p == own) return 0;
    return growth() * (p == PartModel::Point ? e_point : p == PartModel::Thin ? e_thin : 0);
}

double ModelEstimate::dynamics_term(Dynamics d) const {
    const double u = growth() * (eps_U * xi * duration + u_transient);
    if (d == Dynamics::Full) return 0;
    if (d == Dynamics::U) return u;
    return u + offset + excursion;
}

ModelEstimate estimate_model_errors(const Scene& sc, const Vec3& q0, double duration) {
    ModelEstimate e;
    e.duration = duration;
    const double rho = sc.part.rho(), T = sc.plate.T, w = sc.plate.omega();
    // The own part's cycle from rest, recorded: its twist, the transient's offset, the excursion.
    LimitCycleOptions lo;
    lo.record = true;
    const LimitCycleSummary lc = limit_cycle(sc, q0, lo);
    if (!lc.converged) {
        e.note = "no cycle at q0: " + (lc.stop.reason != StopReason::None ? lc.stop.describe() : std::string("not converged"));
        return e;
    }
    auto scaled = [&](const Vec3& v) { return std::max(v.head<2>().norm() / rho, std::abs(v[2])); };
    e.work += lc.stats.rhs_evals;
    e.xi = scaled(lc.twist);
    // A recorded run's transient offset from the curve: its displacement X = int q' dt (trapezoidal
    // on the recorded steps) less xi_a times its duration.
    auto offset_of = [](const LimitCycleSummary& c) {
        Vec3 X = Vec3::Zero();
        for (std::size_t i = 1; i < c.path.size(); ++i)
            X += 0.5 * (c.path[i].qd + c.path[i - 1].qd) * (c.path[i].t - c.path[i - 1].t);
        return Vec3(X - c.twist * c.path.back().t);
    };
    const double t_last = lc.path.back().t;
    const Vec3 own_offset = offset_of(lc);
    e.offset = scaled(own_offset);
    e.transient = scaled(own_offset + lc.twist * t_last);
    // The excursion about the curve within the last period.
    Vec3 disp = Vec3::Zero();
    for (std::size_t i = 1; i < lc.path.size(); ++i) {
        if (lc.path[i - 1].t < t_last - T - 1e-12) continue;
        disp += (0.5 * (lc.path[i].qd + lc.path[i - 1].qd) - lc.twist) * (lc.path[i].t - lc.path[i - 1].t);
        e.excursion = std::max(e.excursion, scaled(disp));
    }
    // The simplified parts' cycles at q0 from rest, as the reference starts: their drift differs by
    // |xi_p - xi| D, and their transients end displaced by the difference of the offsets.
    const double inf = std::numeric_limits<double>::infinity();
    if (!sc.part.point) {
        const LimitCycleSummary pt = limit_cycle(simplified(sc, PartModel::Point), q0, lo);
        e.work += pt.stats.rhs_evals;
        e.e_point = pt.converged ? std::max((pt.twist - lc.twist).head<2>().norm() / rho, std::abs(lc.twist[2])) * duration +
                                       std::max((offset_of(pt) - own_offset).head<2>().norm() / rho, std::abs(own_offset[2]))
                                 : inf;
        if (!sc.part.thin()) {
            const LimitCycleSummary th = limit_cycle(simplified(sc, PartModel::Thin), q0, lo);
            e.work += th.stats.rhs_evals;
            e.e_thin = th.converged ? scaled(th.twist - lc.twist) * duration + scaled(offset_of(th) - own_offset) : inf;
        }
    }
    // What U-dynamics drop, against friction's mu g.
    // The tilt comes from rotations about horizontal axes; the plate's angular velocity (Coriolis,
    // centripetal) from every rotation, a spin about z included.
    double tilt = 0, w1 = 0;
    bool rotates = false;
    for (const auto& h : sc.plate.harmonics) {
        if (h.axis == Axis::rx || h.axis == Axis::ry) tilt += std::abs(h.amp) / std::pow(h.n * w, 2);
        if (h.axis == Axis::rx || h.axis == Axis::ry || h.axis == Axis::rz) {
            w1 += std::abs(h.amp) / (h.n * w);
            rotates = rotates || h.amp != 0;
        }
    }
    const double mu = sc.part.point ? sc.part.friction().kinetic(0) : sc.part.friction().kinetic().mean();
    const double s = std::hypot(q0[0], q0[1]) + 0.05 * rho;
    e.eps_U = (sc.g * tilt + 2 * w1 * sc.v_ref() + w1 * w1 * s) / std::max(mu * sc.g, 1e-12);
    // From rest the two differ most in the transient (the tilted plate delays the break-away and
    // shifts the phase the cycle is entered at): run both through it, a few periods, and compare.
    if (rotates) {
        const double t_tr = std::min(duration, std::max(2.0, static_cast<double>(lc.periods)) * T);
        const Trajectory tu = simulate(sc, Dynamics::U, q0, Vec3::Zero(), t_tr, t_tr);
        const Trajectory tf = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), t_tr, t_tr);
        e.work += tu.stats.rhs_evals + tf.stats.rhs_evals;
        if (tu.stop.reason != StopReason::None || tf.stop.reason != StopReason::None || tu.samples.empty() ||
            tf.samples.empty()) {
            e.u_transient = inf;
        } else {
            const Vec3 d = tu.samples.back().q - tf.samples.back().q;
            e.u_transient = std::max(d.head<2>().norm() / rho, std::abs(wrap_angle(d[2])));
        }
    }
    // Where the field spreads neighbouring paths (a positive eigenvalue of its Jacobian at q0, by
    // central differences in (s / rho, theta)), an error made along the way grows: Gronwall's
    // factor (e^{lambda D} - 1) / (lambda D) multiplies the drift terms.
    {
        Mat3 J = Mat3::Zero();
        Vec3 warm = lc.qd_start;
        const double h = 1e-3;
        bool ok = true;
        for (int j = 0; j < (sc.part.point ? 2 : 3) && ok; ++j) {
            Vec3 dq = Vec3::Zero();
            dq[j] = j < 2 ? h * rho : h;
            LimitCycleOptions fo;
            try {
                const Vec3 a = field_at(sc, q0 + dq, fo, &warm, &e.work), b = field_at(sc, q0 - dq, fo, &warm, &e.work);
                J.col(j) = Vec3((a[0] - b[0]) / rho, (a[1] - b[1]) / rho, a[2] - b[2]) / (2 * h);
            } catch (const FieldUndefined&) {
                ok = false;
            }
        }
        if (sc.part.point) J.row(2).setZero();
        e.lambda = ok ? Eigen::EigenSolver<Mat3>(J).eigenvalues().real().maxCoeff() : 0.0;
    }
    e.ok = true;
    return e;
}

std::string APrioriChoice::explain() const {
    std::ostringstream o;
    o.precision(3);
    o << "auto model, decided up front: picked " << picked.name() << " (predicted error " << predicted << ")";
    if (verified) o << "; verified against the full model: measured error " << measured;
    o << "\n  estimates: |xi| " << estimate.xi << "/s, point " << estimate.e_point << ", thin " << estimate.e_thin << ", eps_U "
      << estimate.eps_U << ", transient offset " << estimate.offset << ", excursion " << estimate.excursion
      << (estimate.ok ? "" : " (" + estimate.note + ")") << "\n";
    return o.str();
}

double a_priori_pick(const Scene& sc, const ModelEstimate& est, double tol, PartModel& part, Dynamics& dynamics) {
    std::vector<PartModel> parts{PartModel::Point};
    if (!sc.part.point) {
        parts.push_back(PartModel::Thin);
        if (!sc.part.thin()) parts.push_back(PartModel::Thick);
    }
    const PartModel own = parts.back();
    part = own;
    dynamics = Dynamics::Full;
    if (!est.ok) return 0;
    for (Dynamics d : {Dynamics::ReducedU, Dynamics::U, Dynamics::Full})
        for (PartModel p : parts) {
            if (p == own && d == Dynamics::Full) continue;
            if (est.predicted(p, own, d) <= tol) {
                part = p;
                dynamics = d;
                return est.predicted(p, own, d);
            }
        }
    return 0;
}

APrioriChoice choose_model_a_priori(const Scene& sc, const Vec3& q0, double duration, double tol, bool verify) {
    APrioriChoice c;
    c.estimate = estimate_model_errors(sc, q0, duration);
    PartModel pick_p;
    Dynamics pick_d;
    c.predicted = a_priori_pick(sc, c.estimate, tol, pick_p, pick_d);
    const PartModel own = sc.part.point ? PartModel::Point : sc.part.thin() ? PartModel::Thin : PartModel::Thick;
    Vec3 q;
    c.picked = run_rung(sc, pick_p, pick_d, q0, duration, q);
    if (verify && !(pick_p == own && pick_d == Dynamics::Full)) {
        Vec3 q_ref;
        const Rung ref = run_rung(sc, own, Dynamics::Full, q0, duration, q_ref);
        c.reference_seconds = ref.seconds;
        c.reference_work = ref.work;
        if (ref.ok && c.picked.ok) {
            const double rho = sc.part.rho();
            c.verified = true;
            c.measured = std::max(
                {std::abs(q[0] - q_ref[0]) / rho, std::abs(q[1] - q_ref[1]) / rho, std::abs(wrap_angle(q[2] - q_ref[2]))});
            c.picked.error = c.measured;
        }
    }
    return c;
}

ModelPick pick_model(const Scene& sc, const Vec3& q0, double duration, double tol) {
    ModelPick m;
    m.estimate = estimate_model_errors(sc, q0, duration);
    m.predicted = a_priori_pick(sc, m.estimate, tol, m.rung.part, m.rung.dynamics);
    m.scene = simplified(sc, m.rung.part);
    return m;
}

}   // namespace plate
