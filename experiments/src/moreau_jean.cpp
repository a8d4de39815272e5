// Moreau-Jean time stepping with Siconos' frictional contact solver (moreau_jean.hpp).
#include "plate/moreau_jean.hpp"

#include "plate/dynamics.hpp"
#include "so3.hpp"   // hat, exp_so3 (numeric/src)

#include <siconos/numerics/FrictionContactProblem.h>
#include <siconos/numerics/Friction_cst.h>
#include <siconos/numerics/NonSmoothDrivers.h>
#include <siconos/numerics/NumericsMatrix.h>
#include <siconos/numerics/SolverOptions.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace plate {

namespace {

// Siconos' problem and options, freed on every path. The problem owns W, q and mu (allocated
// with malloc, as frictionContactProblem_free expects).
struct Fc3d {
    FrictionContactProblem* problem = nullptr;
    SolverOptions* options = nullptr;
    Fc3d(int nc, const MoreauJeanOptions& opt) {
        auto* q = static_cast<double*>(std::calloc(3 * nc, sizeof(double)));
        auto* mu = static_cast<double*>(std::calloc(nc, sizeof(double)));
        problem = frictionContactProblem_new_with_data(3, nc, NM_create(NM_DENSE, 3 * nc, 3 * nc), q, mu);
        options = solver_options_create(SICONOS_FRICTION_3D_NSGS);
        options->dparam[SICONOS_DPARAM_TOL] = opt.solver_tol;
        options->iparam[SICONOS_IPARAM_MAX_ITER] = opt.max_iterations;
    }
    ~Fc3d() {
#if PLATE_SICONOS_OPTIONS_LEAK
        // Siconos 4.4/4.5's solver_options_delete frees the members, not the structures themselves
        // (valgrind: the options' and their NSGS local solver's 120 bytes each were lost; fixed
        // after 4.5, where freeing them here would free them twice: CMakeLists.txt sets this by
        // the library's soname).
        SolverOptions* local = options->numberOfInternalSolvers > 0 ? options->internalSolvers[0] : nullptr;
        solver_options_delete(options);
        std::free(local);
        std::free(options);
#else
        solver_options_delete(options);
#endif
        frictionContactProblem_free(problem);
    }
    Fc3d(const Fc3d&) = delete;
    Fc3d& operator=(const Fc3d&) = delete;
};

}   // namespace

MoreauJeanSummary moreau_jean_u(const Scene& sc, const Vec3& q0, double duration, const MoreauJeanOptions& opt) {
    if (!(duration > 0) || opt.steps_per_period < 1)
        throw std::invalid_argument("moreau_jean_u: duration and steps_per_period must be positive");
    const Part& P = sc.part;
    const int nc = P.contacts();
    const int dof = P.point ? 3 : 6;   // a point part is a particle
    const int n = 3 * nc;              // impulses: (N, T1, T2) per contact
    const double h = sc.plate.T / static_cast<double>(opt.steps_per_period);
    const long steps = std::lround(duration / h);

    Vec3 x(q0[0], q0[1], P.s_z());   // centre of mass, plate frame
    Mat3 R = rot_z(q0[2]);           // S -> P
    Vec3 v = Vec3::Zero(), w = Vec3::Zero();
    double theta = q0[2];

    P.friction().require_single("Moreau-Jean (Siconos' Coulomb cone)");
    Fc3d fc(nc, opt);
    for (int i = 0; i < nc; ++i) fc.problem->mu[i] = P.friction().kinetic(i);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n), u = Eigen::VectorXd::Zero(n);   // warm start: last step's
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, dof), Minv = Eigen::MatrixXd::Zero(dof, dof), W(n, n);
    Eigen::VectorXd Vf(dof), V(dof);
    Minv.topLeftCorner<3, 3>() = Mat3::Identity() / P.m;   // the rotational block follows R below

    MoreauJeanSummary out;
    long sweeps = 0;
    for (long k = 0; k < steps; ++k) {
        Vec3 pdd, wd;
        sc.plate.acceleration((static_cast<double>(k) + 0.5) * h, pdd, wd);
        // The free motion over the step: gravity and the frame's fictitious force and torque.
        const Vec3 F = -P.m * sc.g * Vec3::UnitZ() - P.m * (pdd + wd.cross(x));
        Vf.head<3>() = v + h / P.m * F;
        if (!P.point) {
            const Mat3 JP = R * P.J * R.transpose();
            const Mat3 JPi = JP.inverse();
            const Vec3 tau = -JP * wd - w.cross(JP * w);
            Vf.tail<3>() = w + h * JPi * tau;
            Minv.bottomRightCorner<3, 3>() = JPi;
        }
        // Contact i's velocity v + w x r_i = [I, -hat(r_i)] V, rows in Siconos' order (N = z, T1 = x, T2 = y).
        for (int i = 0; i < nc; ++i) {
            Eigen::Matrix<double, 3, 6> Hi = Eigen::Matrix<double, 3, 6>::Zero();
            Hi.leftCols<3>().setIdentity();
            if (!P.point) Hi.rightCols<3>() = -detail::hat(R * P.c[i]);
            H.row(3 * i) = Hi.row(2).head(dof);
            H.row(3 * i + 1) = Hi.row(0).head(dof);
            H.row(3 * i + 2) = Hi.row(1).head(dof);
        }
        W = H * Minv * H.transpose();
        Eigen::Map<Eigen::VectorXd>(fc.problem->q, n) = H * Vf;
        Eigen::Map<Eigen::MatrixXd>(fc.problem->M->matrix0, n, n) = W;   // column-major, as NM_DENSE
        if (fc3d_driver(fc.problem, r.data(), u.data(), fc.options) != 0) ++out.solver_failures;
        sweeps += fc.options->iparam[SICONOS_IPARAM_ITER_DONE];
        out.max_residual = std::max(out.max_residual, fc.options->dparam[SICONOS_DPARAM_RESIDU]);
        V = Vf + Minv * H.transpose() * r;
        v = V.head<3>();
        if (!P.point) w = V.tail<3>();
        x += h * v;
        R = detail::exp_so3(h * w) * R;
        theta += std::remainder(std::atan2(R(1, 0), R(0, 0)) - theta, 2 * kPi);
        for (int i = 0; i < nc; ++i) out.max_gap = std::max(out.max_gap, (x + R * (P.point ? Vec3::Zero() : P.c[i])).z());
    }
    out.q = Vec3(x.x(), x.y(), P.point ? 0.0 : theta);
    out.qd = Vec3(v.x(), v.y(), P.point ? 0.0 : w.z());
    out.steps = steps;
    out.mean_iterations = steps ? static_cast<double>(sweeps) / static_cast<double>(steps) : 0;
    return out;
}

}   // namespace plate
