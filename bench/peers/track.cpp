// The plate's trajectory as the full dynamics move it, and poses relative to it (peers.hpp).
#include "peers.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>

namespace plate::peers {

PlateTrack::PlateTrack(const PlateMotion& u, const Vec3& drift) : u_(&u), drift_(drift) {
    Vec3 phi;
    if (u.T > 0)
        u.displacement(0.0, p0_, phi);
    else
        phi.setZero();
    const double angle = phi.norm();
    R = angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle)) : Eigen::Quaterniond::Identity();
    read(0);
}

void PlateTrack::read(double time) {
    if (u_->T > 0) {
        Vec3 phi;
        u_->acceleration(time, a, alpha);
        u_->velocity(time, v, w);
        u_->displacement(time, p, phi);
    } else {
        a.setZero(), alpha.setZero(), v.setZero(), w.setZero(), p.setZero();
    }
    p += drift_ * time;
    v += drift_;
}

void PlateTrack::advance(double to) {
    // R1' = omega1^ R1 (spatial angular velocity): q' = (0, omega1) q / 2, classical RK4.
    auto rate = [&](double s, const Eigen::Quaterniond& q) {
        Vec3 pd, w1;
        u_->velocity(s, pd, w1);
        const Eigen::Quaterniond wq(0, w1.x(), w1.y(), w1.z());
        Eigen::Quaterniond d = wq * q;
        d.coeffs() *= 0.5;
        return d;
    };
    if (u_->T > 0 && to > t) {
        const int n = static_cast<int>(std::ceil((to - t) / (u_->T / 4000)));
        const double h = (to - t) / n;
        for (int i = 0; i < n; ++i) {
            const double s = t + i * h;
            auto add = [](const Eigen::Quaterniond& q, const Eigen::Quaterniond& d, double c) {
                Eigen::Quaterniond r;
                r.coeffs() = q.coeffs() + c * d.coeffs();
                return r;
            };
            const Eigen::Quaterniond k1 = rate(s, R), k2 = rate(s + h / 2, add(R, k1, h / 2)),
                                     k3 = rate(s + h / 2, add(R, k2, h / 2)), k4 = rate(s + h, add(R, k3, h));
            R.coeffs() += h / 6 * (k1.coeffs() + 2 * k2.coeffs() + 2 * k3.coeffs() + k4.coeffs());
            R.normalize();
        }
    }
    t = to;
    read(to);
}

double cpu_now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

long whole_steps(double span, double dt, std::string& failure) {
    const long n = std::lround(span / dt);
    if (n < 1 || std::abs(static_cast<double>(n) * dt - span) > 1e-9 * span) {
        failure = "the step " + std::to_string(dt) + " s does not divide " + std::to_string(span) + " s";
        return 0;
    }
    return n;
}

bool record_sample(PeerRun& r, const Part& part, const PlateTrack& plate, double t, const Vec3& x, const Eigen::Quaterniond& R,
                   double first_theta) {
    const Vec3 q = plate_frame_config(part, plate, x, R.normalized(), r.q.empty() ? first_theta : r.q.back()[2]);
    const double lift = std::abs((plate.R.conjugate() * (x - plate.p)).z() - part.s_z());
    r.max_lift = std::max(r.max_lift, lift);
    if (!q.allFinite() || lift > 0.01) {
        r.failure = "the part left the plate at t = " + std::to_string(t) + " s";
        return false;
    }
    r.t.push_back(t);
    r.q.push_back(q);
    return true;
}

BodyState at_rest_on_plate(const Part& part, const PlateTrack& plate, const Vec3& q) {
    BodyState b;
    const Vec3 s(q[0], q[1], part.s_z());
    const Vec3 Rs = plate.R * s;
    b.x = plate.p + Rs;
    b.v = plate.v + plate.w.cross(Rs);
    b.w = plate.w;
    b.R = plate.R * Eigen::Quaterniond(Eigen::AngleAxisd(q[2], Vec3::UnitZ()));
    return b;
}

Vec3 plate_frame_config(const Part&, const PlateTrack& plate, const Vec3& x, const Eigen::Quaterniond& R, double previous_theta) {
    const Vec3 rel = plate.R.conjugate() * (x - plate.p);
    const Mat3 Rrel = (plate.R.conjugate() * R).toRotationMatrix();
    double th = std::atan2(Rrel(1, 0), Rrel(0, 0));
    th += 2 * kPi * std::round((previous_theta - th) / (2 * kPi));
    return Vec3(rel.x(), rel.y(), th);
}

}   // namespace plate::peers
