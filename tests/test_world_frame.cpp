// The full dynamics on a spinning and tilting plate against the world frame, where there are no
// Coriolis, centripetal or Euler terms: a frictionless part on a plate turning about z goes straight
// at constant speed and keeps its spin (closed form), and a sliding point part and a sliding rigid part
// on a plate moving in all six axes obey Newton's law m r'' = m g + N n + f, and Euler's for the rigid
// one, in W (integrated by GSL, nothing of the plate-frame derivation or the generated kernels). simulate() integrates the
// plate-frame equations (31), whose right-hand side carries those terms.
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "shipped_scenes.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <utility>
#include <cmath>
#include <vector>

using namespace plate;

namespace {

using plate_tests::scene;

// R1 at t = 0, as the full dynamics start it: the rotation by the plate's zero-mean rotation vector.
Mat3 start_orientation(const PlateMotion& u) {
    Vec3 p, phi;
    u.displacement(0, p, phi);
    return phi.norm() > 0 ? Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix() : Mat3::Identity();
}

// A plate moving along x, y, z and turning about z only: its surface stays level, R1 = R_z(psi) with
// psi the z component of the zero-mean rotation vector (rotations about one axis add up).
PlateMotion spinning_plate() {
    PlateMotion u;
    u.T = 0.05;
    // rz in phase with x: the spin omega1_z and the slip's swing s' ~ -p'_x share their phase, so the
    // Coriolis force 2 m omega1 x s' has a mean (a drift of centimetres over a few periods).
    u.harmonics = {{Axis::x, 1, 14, 0}, {Axis::y, 1, 7, 1.2}, {Axis::z, 1, 5, 0.3}, {Axis::rz, 1, 150, 0}};
    return u;
}

// A frictionless part on a level plate: no horizontal force and no torque about z act on it, so in W
// its centre of mass goes straight at constant speed and its heading psi + theta turns at a constant
// rate. The plate-frame configuration and twist at t follow from those at 0.
struct Straight {
    const PlateMotion& u;
    Vec2 r0, v0;      // the centre of mass in W at t = 0 and its velocity
    double h0 = 0;    // the heading psi + theta at t = 0
    double hd0 = 0;   // and its rate
    Straight(const PlateMotion& u, const Vec3& q0, const Vec3& qd0) : u(u) {
        Vec3 p, phi, pd, w;
        u.displacement(0, p, phi);
        u.velocity(0, pd, w);
        const Eigen::Rotation2Dd R(phi.z());
        const Vec2 d = R * q0.head<2>();
        r0 = p.head<2>() + d;
        v0 = pd.head<2>() + w.z() * Vec2(-d.y(), d.x()) + R * qd0.head<2>();
        h0 = phi.z() + q0.z();
        hd0 = w.z() + qd0.z();
    }
    void at(double t, Vec3& q, Vec3& qd) const {
        Vec3 p, phi, pd, w;
        u.displacement(t, p, phi);
        u.velocity(t, pd, w);
        const Eigen::Rotation2Dd Rinv(-phi.z());
        const Vec2 d = r0 + v0 * t - p.head<2>(), dd = v0 - pd.head<2>();
        q << Rinv * d, h0 + hd0 * t - phi.z();
        qd << Rinv * (dd - w.z() * Vec2(-d.y(), d.x())), hd0 - w.z();
    }
};

// Newton's law in W for a point part on the plate's surface sliding with kinetic friction mu: with
// d = r - p, n = R1 e_z and the slip v = d' - w1 x d,
//   r'' = -g e_z + (N/m) (n - mu v / |v|),
// N from the contact n . d = 0 held twice differentiated (n' = w1 x n, n'' = w1' x n + w1 x n'):
//   N/m = g n_z + n . p'' - n'' . d - 2 n' . d'.
// State: r, r', R1 (R1' = w1^ R1, row-major).
struct WorldPoint {
    const PlateMotion& u;
    double g, mu;
};

int world_rhs(double t, const double y[], double dy[], void* params) {
    const auto& P = *static_cast<const WorldPoint*>(params);
    Vec3 p, phi, pd, w, pdd, wd;
    P.u.displacement(t, p, phi);
    P.u.velocity(t, pd, w);
    P.u.acceleration(t, pdd, wd);
    const Vec3 r(y[0], y[1], y[2]), rd(y[3], y[4], y[5]);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(y + 6);
    const Vec3 n = R.col(2), nd = w.cross(n), ndd = wd.cross(n) + w.cross(nd);
    const Vec3 d = r - p, dd = rd - pd, v = dd - w.cross(d);
    const double N_m = P.g * n.z() + n.dot(pdd) - ndd.dot(d) - 2 * nd.dot(dd);
    const Vec3 f = v.norm() > 0 ? Vec3(-P.mu * N_m * v.normalized()) : Vec3::Zero();
    const Vec3 rdd = -P.g * Vec3::UnitZ() + N_m * n + f;
    Mat3 W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Rd = W * R;
    for (int i = 0; i < 3; ++i) {
        dy[i] = rd[i];
        dy[3 + i] = rdd[i];
    }
    std::copy(Rd.data(), Rd.data() + 9, dy + 6);
    return GSL_SUCCESS;
}

// A world-frame system from state y at t = 0 to n dt by GSL's rk8pd (absolute and relative tolerance
// 1e-13), and at each of 0, dt, ..., n dt the plate-frame (q, q') that `plate_frame` reads from the
// state and the plate's p, p', omega1 then.
template <class PlateFrame>
std::vector<std::pair<Vec3, Vec3>> in_world(const PlateMotion& u, gsl_odeiv2_system sys, double* y, double dt, int n,
                                            PlateFrame&& plate_frame) {
    gsl_odeiv2_driver* drv = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-5, 1e-13, 1e-13);
    std::vector<std::pair<Vec3, Vec3>> out;
    double t = 0;
    for (int k = 0; k <= n; ++k) {
        if (k > 0) REQUIRE(gsl_odeiv2_driver_apply(drv, &t, k * dt, y) == GSL_SUCCESS);
        Vec3 p, phi, pd, w;
        u.displacement(t, p, phi);
        u.velocity(t, pd, w);
        out.push_back(plate_frame(y, p, pd, w));
    }
    gsl_odeiv2_driver_free(drv);
    return out;
}

// The point part's plate-frame (s, s') at t = 0, dt, ..., n dt from Newton's law in W (in_world).
std::vector<std::pair<Vec3, Vec3>> world_point(const Scene& sc, const Vec2& s0, const Vec2& sd0, double dt, int n) {
    WorldPoint P{sc.plate, sc.g, sc.part.friction().kinetic(0)};
    Vec3 p, phi, pd, w;
    sc.plate.displacement(0, p, phi);
    sc.plate.velocity(0, pd, w);
    const Mat3 R = start_orientation(sc.plate);
    const Vec3 d = R * Vec3(s0.x(), s0.y(), 0);
    const Vec3 r = p + d, rd = pd + w.cross(d) + R * Vec3(sd0.x(), sd0.y(), 0);
    double y[15] = {r[0], r[1], r[2], rd[0], rd[1], rd[2]};
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(y + 6) = R;
    return in_world(sc.plate, {world_rhs, nullptr, 15, &P}, y, dt, n,
                    [](const double* z, const Vec3& pk, const Vec3& pdk, const Vec3& wk) {
                        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Rt(z + 6);
                        const Vec3 dk = Vec3(z[0], z[1], z[2]) - pk, ddk = Vec3(z[3], z[4], z[5]) - pdk;
                        return std::make_pair(Vec3(Rt.transpose() * dk), Vec3(Rt.transpose() * (ddk - wk.cross(dk))));
                    });
}


// Newton-Euler in W for a rigid part flat on the plate, its three contacts x_i = r + rho_i (rho_i = Rp c_i)
// sliding with kinetic friction: contact i pushes N_i (n - mu_i v_i / |v_i|), v_i = r' + wp x rho_i -
// p' - w1 x (x_i - p) its slip, so
//   m r'' = -m g e_z + sum_i N_i e_i,   Jw wp' + wp x Jw wp = sum_i rho_i x N_i e_i   (Jw = Rp J Rp^T),
// and the N_i keep every contact on the surface, n . (x_i - p) = 0 twice differentiated:
//   n . (r'' + wp' x rho_i + wp x (wp x rho_i) - p'') + 2 n' . d_i' + n'' . d_i = 0,
// linear in N. State: r, r', Rp, wp, R1 (27).
struct WorldRigid {
    const Scene& sc;
};

int rigid_rhs(double t, const double y[], double dy[], void* params) {
    const Scene& sc = static_cast<const WorldRigid*>(params)->sc;
    const Part& P = sc.part;
    using RowMat = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    Vec3 p, phi, pd, w, pdd, wd;
    sc.plate.displacement(t, p, phi);
    sc.plate.velocity(t, pd, w);
    sc.plate.acceleration(t, pdd, wd);
    const Vec3 r(y[0], y[1], y[2]), rd(y[3], y[4], y[5]), wp(y[15], y[16], y[17]);
    const Eigen::Map<const RowMat> Rp(y + 6), R1(y + 18);
    const Mat3 Jw = Rp * P.J * Rp.transpose(), Jinv = Jw.inverse();
    const Vec3 n = R1.col(2), nd = w.cross(n), ndd = wd.cross(n) + w.cross(nd);
    const Vec3 a0 = -sc.g * Vec3::UnitZ(), b0 = Jinv * (-wp.cross(Jw * wp));
    Vec3 rho[3], e[3];
    Mat3 M;
    Vec3 rhs;
    for (int i = 0; i < 3; ++i) {
        rho[i] = Rp * P.c[i];
        const Vec3 d = r + rho[i] - p, dd = rd + wp.cross(rho[i]) - pd, v = dd - w.cross(d);
        e[i] = n - P.friction().kinetic(i) * v.normalized();
        rhs[i] =
            n.dot(pdd) - n.dot(wp.cross(wp.cross(rho[i]))) - 2 * nd.dot(dd) - ndd.dot(d) - n.dot(a0) - n.dot(b0.cross(rho[i]));
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) M(i, j) = n.dot(e[j] / P.m) + n.dot((Jinv * rho[j].cross(e[j])).cross(rho[i]));
    const Vec3 N = M.partialPivLu().solve(rhs);
    Vec3 rdd = a0, wpd = b0;
    for (int j = 0; j < 3; ++j) {
        rdd += N[j] * e[j] / P.m;
        wpd += N[j] * (Jinv * rho[j].cross(e[j]));
    }
    auto hat = [](const Vec3& a) {
        Mat3 A;
        A << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
        return A;
    };
    const RowMat Rpd = hat(wp) * Rp, R1d = hat(w) * R1;
    for (int i = 0; i < 3; ++i) {
        dy[i] = rd[i];
        dy[3 + i] = rdd[i];
        dy[15 + i] = wpd[i];
    }
    std::copy(Rpd.data(), Rpd.data() + 9, dy + 6);
    std::copy(R1d.data(), R1d.data() + 9, dy + 18);
    return GSL_SUCCESS;
}

// The rigid part's plate-frame (q, q') at t = 0, dt, ..., n dt from Newton-Euler in W (in_world).
std::vector<std::pair<Vec3, Vec3>> world_rigid(const Scene& sc, const Vec3& q0, const Vec3& qd0, double dt, int n) {
    using RowMat = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    WorldRigid P{sc};
    Vec3 p, phi, pd, w;
    sc.plate.displacement(0, p, phi);
    sc.plate.velocity(0, pd, w);
    const Mat3 R1 = start_orientation(sc.plate), Rp = R1 * Eigen::AngleAxisd(q0.z(), Vec3::UnitZ()).toRotationMatrix();
    const Vec3 d = R1 * Vec3(q0.x(), q0.y(), sc.part.s_z());
    const Vec3 r = p + d, rd = pd + w.cross(d) + R1 * Vec3(qd0.x(), qd0.y(), 0), wp = w + R1 * Vec3(0, 0, qd0.z());
    double y[27] = {r[0], r[1], r[2], rd[0], rd[1], rd[2]};
    Eigen::Map<RowMat>(y + 6) = Rp;
    for (int i = 0; i < 3; ++i) y[15 + i] = wp[i];
    Eigen::Map<RowMat>(y + 18) = R1;
    return in_world(
        sc.plate, {rigid_rhs, nullptr, 27, &P}, y, dt, n, [](const double* z, const Vec3& pk, const Vec3& pdk, const Vec3& wk) {
            const Eigen::Map<const RowMat> Rpk(z + 6), R1k(z + 18);
            const Mat3 rel = R1k.transpose() * Rpk;   // R_z(theta) while the part lies flat
            const Vec3 dk = Vec3(z[0], z[1], z[2]) - pk, ddk = Vec3(z[3], z[4], z[5]) - pdk - wk.cross(dk);
            const Vec3 s = R1k.transpose() * dk, sd = R1k.transpose() * ddk;
            const Vec3 wrel = R1k.transpose() * (Vec3(z[15], z[16], z[17]) - wk);
            return std::make_pair(Vec3(s.x(), s.y(), std::atan2(rel(1, 0), rel(0, 0))), Vec3(sd.x(), sd.y(), wrel.z()));
        });
}

}   // namespace

TEST_CASE("a frictionless part on a plate spinning about z goes straight in the world frame", "[trajectory][full][world]") {
    for (const char* name : {"fig1_point", "fig4"}) {
        Scene sc = scene(name);
        sc.part.mu.setZero();
        sc.plate = spinning_plate();
        const Vec3 q0(0.02, -0.01, sc.part.point ? 0.0 : 0.5), qd0(0.05, 0.03, sc.part.point ? 0.0 : 0.4);
        const double dur = 10 * sc.plate.T, dt = sc.plate.T / 4;
        IntegrationOptions io;
        io.rtol = 1e-10;
        const Trajectory tr = simulate(sc, Dynamics::Full, q0, qd0, dur, dt, io);
        REQUIRE(tr.stop.reason == StopReason::None);
        REQUIRE(tr.samples.size() == 41u);
        const Straight line(sc.plate, q0, qd0);
        double worst_q = 0, worst_qd = 0, moved = 0;
        for (const Sample& smp : tr.samples) {
            Vec3 q, qd;
            line.at(smp.t, q, qd);
            const int k = sc.part.point ? 2 : 3;   // (a point part has no heading)
            worst_q = std::max(worst_q, (smp.q - q).head(k).cwiseAbs().maxCoeff());
            worst_qd = std::max(worst_qd, (smp.qd - qd).head(k).cwiseAbs().maxCoeff());
            moved = std::max(moved, (smp.q - q0).head<2>().norm());
        }
        INFO(name << ": largest errors " << worst_q << " (m, rad), " << worst_qd << " (m/s, rad/s); moved " << moved << " m");
        // At rtol 1e-10 the engine meets the closed form to rounding: measured 1.9e-12 (m, rad) and
        // 2.4e-11 (m/s, rad/s) at most over both parts; bounds 6e-12 and 8e-11. (The plate-frame terms
        // matter: in W the part moves 3.7 cm in a straight line; the Coriolis term's sign flipped
        // leaves it 4.0e-2 m off.)
        CHECK(worst_q < 6e-12);
        CHECK(worst_qd < 8e-11);
        CHECK(moved > 0.03);
    }
}

TEST_CASE("a point part sliding on a plate that moves in all six axes obeys Newton's law in the world frame",
          "[trajectory][full][world]") {
    Scene sc = scene("fig1_point");
    sc.plate.harmonics = {{Axis::x, 1, 14, 0},    {Axis::y, 1, 7, 1.2},    {Axis::z, 1, 5, 0.3},
                          {Axis::rx, 1, 80, 2.0}, {Axis::ry, 1, 100, 4.7}, {Axis::rz, 1, 150, 0}};
    const Vec2 s0(0.02, -0.01), sd0(0.4, -0.3);
    const double dt = sc.plate.T / 4;
    const int n = 8;   // two periods: the slip stays far from zero (checked below)
    IntegrationOptions io;
    io.rtol = 1e-10;
    const Trajectory tr = simulate(sc, Dynamics::Full, Vec3(s0.x(), s0.y(), 0), Vec3(sd0.x(), sd0.y(), 0), n * dt, dt, io);
    REQUIRE(tr.stop.reason == StopReason::None);
    REQUIRE(tr.samples.size() == static_cast<std::size_t>(n + 1));
    CHECK(tr.events.empty());   // sliding throughout
    const auto ref = world_point(sc, s0, sd0, dt, n);
    double worst_q = 0, worst_qd = 0;
    for (int k = 0; k <= n; ++k) {
        worst_q = std::max(worst_q, (tr.samples[k].q.head<2>() - ref[k].first.head<2>()).cwiseAbs().maxCoeff());
        worst_qd = std::max(worst_qd, (tr.samples[k].qd.head<2>() - ref[k].second.head<2>()).cwiseAbs().maxCoeff());
        CHECK(std::abs(ref[k].first.z()) < 1e-12);   // (the reference keeps the part on the surface)
    }
    // Measured 8.4e-14 m and 2.5e-12 m/s at most (the engine at rtol 1e-10, the reference at 1e-13);
    // bounds 3e-13 and 8e-12.
    CHECK(worst_q < 3e-13);
    CHECK(worst_qd < 8e-12);
}

TEST_CASE("a rigid part sliding on a plate that moves in all six axes obeys Newton-Euler in the world frame",
          "[trajectory][full][world]") {
    Scene sc = scene("fig4");
    sc.plate.harmonics = {{Axis::x, 1, 14, 0},    {Axis::y, 1, 7, 1.2},    {Axis::z, 1, 5, 0.3},
                          {Axis::rx, 1, 80, 2.0}, {Axis::ry, 1, 100, 4.7}, {Axis::rz, 1, 150, 0}};
    const Vec3 q0(0.02, -0.01, 0.5), qd0(0.4, -0.3, 6);
    const double dt = sc.plate.T / 4;
    const int n = 8;
    IntegrationOptions io;
    io.rtol = 1e-10;
    const Trajectory tr = simulate(sc, Dynamics::Full, q0, qd0, n * dt, dt, io);
    REQUIRE(tr.stop.reason == StopReason::None);
    REQUIRE(tr.samples.size() == static_cast<std::size_t>(n + 1));
    CHECK(tr.events.empty());   // every contact slides throughout
    const auto ref = world_rigid(sc, q0, qd0, dt, n);
    double worst_q = 0, worst_qd = 0;
    for (int k = 0; k <= n; ++k) {
        worst_q = std::max(worst_q, (tr.samples[k].q - ref[k].first).cwiseAbs().maxCoeff());
        worst_qd = std::max(worst_qd, (tr.samples[k].qd - ref[k].second).cwiseAbs().maxCoeff());
    }
    // Measured 1.0e-12 (m, rad) and 6.1e-11 (m/s, rad/s) at most; bounds 3e-12 and 2e-10.
    CHECK(worst_q < 3e-12);
    CHECK(worst_qd < 2e-10);
}
