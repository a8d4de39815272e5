// A track's residual block (TrackCost): its residuals, its Jacobians by differences of the hybrid
// simulation, and the Levenberg-Marquardt solve over every track (minimise), whose simulations at a
// point run as one set of tasks (PointSimulations).
#include "internal.hpp"

#include "plate/tasks.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace plate::identify_detail {
namespace {

// Levenberg-Marquardt's damping takes each parameter's information (the diagonal of J^T J, in noise
// sds per internal unit, squared) as at least this: a direction the tracks barely see (a static
// coefficient of a part that hardly sticks: 1e-2-1e2, against 1e8 for a kinetic one) is then not
// stepped across its whole range, into a regime it does not hold (docs/decisions/identification.md).
constexpr double kMinLmDiagonal = 1e4;

}   // namespace

TrackCost::TrackCost(const Scene& scene, const Layout& layout, const Track& track, int first, const IdentifyOptions& o,
                     bool central)
    : scene_(scene), layout_(layout), track_(track), first_(first), o_(o), central_(central) {
    dim_ = track.point ? 2 : 3;
    reuse_ = central ? 0 : o.jacobian_reuse;
    mutable_parameter_block_sizes()->push_back(layout.size());
    mutable_parameter_block_sizes()->push_back(dim_);
    set_num_residuals(dim_ * (static_cast<int>(track.t.size()) - first));
    opt_.rtol = o.rtol;
    for (int j = 0; j < layout.size(); ++j) {
        lo_.push_back(layout.lower(j, o));
        hi_.push_back(layout.upper(j, o));
    }
}

void TrackCost::profile(int j, const std::vector<double>& lo, const std::vector<double>& hi) {
    profiled_ = j;
    lo_ = lo;
    hi_ = hi;
}

bool TrackCost::internal_of(const double* z, std::vector<double>& x) const {
    x.assign(z, z + layout_.size());
    const int j = profiled_;
    if (j < 0) return true;
    const Param::Kind kind = layout_.p[j].kind;
    if (kind == Param::ComX || kind == Param::ComY) x[j] = z[j] * 1e3;
    if (kind != Param::Static) return true;
    x[j] = 0;
    const double base = layout_.natural(x)[j];   // the kinetic coefficient(s) the static one must exceed
    x[j] = z[j] - base;
    if (x[j] < -1e-12) return false;
    x[j] = std::max(x[j], 0.0);
    return true;
}

bool TrackCost::residuals(const double* z, const double* q0, double* r) const {
    std::vector<double> x;
    if (!internal_of(z, x)) return false;
    const Scene s = at(scene_, layout_, x);
    const Vec3 q(q0[0] * 1e-3, q0[1] * 1e-3, dim_ == 3 ? q0[2] : 0.0);
    std::vector<Vec3> pred;
    ++sims_;
    if (!predict(s, track_, o_.level, q, opt_, pred)) return false;
    const double sxy = track_.camera.noise_xy_mm * 1e-3, sth = track_.camera.noise_theta_mrad * 1e-3;
    for (std::size_t k = first_; k < pred.size(); ++k) {
        const Vec3 d = pred[k] - track_.q[k];
        double* rk = r + dim_ * (k - first_);
        rk[0] = d.x() / sxy;
        rk[1] = d.y() / sxy;
        if (dim_ == 3) rk[2] = std::remainder(d.z(), 2 * kPi) / sth;
    }
    return true;
}

std::vector<TrackCost::Column> TrackCost::columns(const double* const* parameters, bool block0, bool block1) const {
    std::vector<Column> out;
    for (int b = 0; b < 2; ++b) {
        if (!(b == 0 ? block0 : block1)) continue;
        const int n = b == 0 ? layout_.size() : dim_;
        for (int j = 0; j < n; ++j) {
            Column c;
            c.b = b;
            c.j = j;
            if (b == 0 && j == profiled_) {   // held along the profile: its column zero
                out.push_back(c);
                continue;
            }
            c.h = b == 0 ? layout_.step(j) : start_step(j);
            const double x0 = parameters[b][j];
            // One-sided at a bound (a static excess at 0: below it the part would have static < kinetic).
            c.up = b != 0 || x0 + c.h <= hi_[j];
            c.down = (central_ || !c.up) && (b != 0 || x0 - c.h >= lo_[j]);
            out.push_back(c);
        }
    }
    return out;
}

bool TrackCost::moved(const double* const* parameters, const Column& c, bool upper, double* out) const {
    const int n = c.b == 0 ? layout_.size() : dim_;
    std::vector<double> x(parameters[c.b], parameters[c.b] + n);
    x[c.j] += upper ? c.h : -c.h;
    const double* blocks[2] = {parameters[0], parameters[1]};
    blocks[c.b] = x.data();
    return residuals(blocks[0], blocks[1], out);
}

void TrackCost::difference(const Column& c, const double* r, const double* plus, const double* minus, double* jacobian) const {
    const int m = num_residuals(), n = c.b == 0 ? layout_.size() : dim_;
    const double span = (c.up ? c.h : 0) + (c.down ? c.h : 0);
    for (int i = 0; i < m; ++i)
        jacobian[i * n + c.j] = span > 0 ? ((c.up ? plus[i] : r[i]) - (c.down ? minus[i] : r[i])) / span : 0.0;
}

bool TrackCost::reuse_kept(double* const* jacobians) const {
    if (!(jacobians[0] && jacobians[1] && profiled_ < 0 && reused_ < reuse_)) return false;
    ++reused_;
    for (int b = 0; b < 2; ++b) std::copy(kept_[b].begin(), kept_[b].end(), jacobians[b]);
    return true;
}

void TrackCost::keep(double* const* jacobians) const {
    if (!(jacobians[0] && jacobians[1] && profiled_ < 0 && reuse_ > 0)) return;
    reused_ = 0;
    const int m = num_residuals();
    kept_[0].assign(jacobians[0], jacobians[0] + static_cast<std::size_t>(m) * layout_.size());
    kept_[1].assign(jacobians[1], jacobians[1] + static_cast<std::size_t>(m) * dim_);
}

bool TrackCost::Evaluate(double const* const* parameters, double* r, double** jacobians) const {
    const int m = num_residuals();
    if (prepared_) {   // (PointSimulations ran this point's simulations, every track's together)
        if (!prepared_->ok) return false;
        std::copy(prepared_->r.begin(), prepared_->r.end(), r);
        for (int b = 0; jacobians && b < 2; ++b)
            if (jacobians[b]) std::copy(prepared_->jacobian[b].begin(), prepared_->jacobian[b].end(), jacobians[b]);
        return true;
    }
    if (!residuals(parameters[0], parameters[1], r)) return false;
    if (!jacobians || reuse_kept(jacobians)) return true;
    std::vector<double> plus(m), minus(m);
    for (const Column& c : columns(parameters, jacobians[0], jacobians[1])) {
        if (c.up && !moved(parameters, c, true, plus.data())) return false;
        if (c.down && !moved(parameters, c, false, minus.data())) return false;
        difference(c, r, plus.data(), minus.data(), jacobians[c.b]);
    }
    keep(jacobians);
    return true;
}

// --- every track's simulations at a point, at once --------------------------------------------------

PointSimulations::PointSimulations(const std::vector<TrackCost*>& costs, const std::vector<double>& x,
                                   const std::vector<std::vector<double>>& q0, bool x_held, int threads)
    : costs_(costs), x_(x), q0_(q0), x_held_(x_held), threads_(threads), prepared_(costs.size()) {
    for (std::size_t t = 0; t < costs.size(); ++t) costs[t]->use(&prepared_[t]);
}

PointSimulations::~PointSimulations() {
    for (TrackCost* c : costs_) c->use(nullptr);
}

void PointSimulations::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
    const int nt = static_cast<int>(costs_.size());
    struct Task {
        int t, c;   // track, column (-1: the residuals at the point)
        bool upper;
    };
    std::vector<Task> tasks;
    std::vector<std::vector<TrackCost::Column>> columns(static_cast<std::size_t>(nt));
    std::vector<std::vector<std::array<int, 2>>> sides(static_cast<std::size_t>(nt));   // a column's tasks, + and -
    std::vector<std::array<double*, 2>> jac(static_cast<std::size_t>(nt), {nullptr, nullptr});
    std::vector<int> at_point(static_cast<std::size_t>(nt), -1);   // the task of the residuals at the point
    // Ceres also calls a point new where its line search accepts the step it has just evaluated: the
    // same bits are the same point.
    const bool same = !new_evaluation_point || (x_ == last_x_ && q0_ == last_q0_);
    last_x_ = x_;
    last_q0_ = q0_;
    for (int t = 0; t < nt; ++t) {
        Prepared& p = prepared_[static_cast<std::size_t>(t)];
        const TrackCost& cost = *costs_[static_cast<std::size_t>(t)];
        const int m = cost.num_residuals();
        if (!same || !p.ok) {
            p.r.resize(static_cast<std::size_t>(m));
            at_point[t] = static_cast<int>(tasks.size());
            tasks.push_back({t, -1, false});
        }
        if (!evaluate_jacobians) continue;
        const std::vector<int>& sizes = cost.parameter_block_sizes();
        for (int b = 0; b < 2; ++b) p.jacobian[b].resize(static_cast<std::size_t>(m) * static_cast<std::size_t>(sizes[b]));
        jac[t] = {x_held_ ? nullptr : p.jacobian[0].data(), p.jacobian[1].data()};
        if (cost.reuse_kept(jac[t].data())) continue;
        const double* params[2] = {x_.data(), q0_[static_cast<std::size_t>(t)].data()};
        columns[t] = cost.columns(params, !x_held_, true);
        for (int c = 0; c < static_cast<int>(columns[t].size()); ++c) {
            std::array<int, 2> side = {-1, -1};
            for (int k = 0; k < 2; ++k)
                if (k == 0 ? columns[t][c].up : columns[t][c].down) {
                    side[k] = static_cast<int>(tasks.size());
                    tasks.push_back({t, c, k == 0});
                }
            sides[t].push_back(side);
        }
    }
    std::vector<std::vector<double>> out(tasks.size());
    std::vector<char> ok(tasks.size(), 0);
    thread_tasks(std::max(1, std::min(threads_, static_cast<int>(tasks.size()))))(
        static_cast<int>(tasks.size()),
        [&](int i) {
            const Task& k = tasks[static_cast<std::size_t>(i)];
            const TrackCost& cost = *costs_[static_cast<std::size_t>(k.t)];
            const double* params[2] = {x_.data(), q0_[static_cast<std::size_t>(k.t)].data()};
            if (k.c < 0) {
                ok[i] = cost.residuals(params[0], params[1], prepared_[static_cast<std::size_t>(k.t)].r.data());
            } else {
                out[i].resize(static_cast<std::size_t>(cost.num_residuals()));
                ok[i] = cost.moved(params, columns[k.t][k.c], k.upper, out[i].data());
            }
            return std::string();
        },
        [](int, const std::string&) {});
    // Each track's verdict, and its Jacobians' columns from their tasks (a column without one: zero).
    for (int t = 0; t < nt; ++t) {
        Prepared& p = prepared_[static_cast<std::size_t>(t)];
        if (at_point[t] >= 0) p.ok = ok[at_point[t]];
        for (const std::array<int, 2>& side : sides[t])
            for (int i : side) p.ok = p.ok && (i < 0 || ok[i]);
        if (!p.ok || columns[t].empty()) continue;
        const TrackCost& cost = *costs_[static_cast<std::size_t>(t)];
        for (std::size_t c = 0; c < columns[t].size(); ++c) {
            const std::array<int, 2>& side = sides[t][c];
            cost.difference(columns[t][c], p.r.data(), side[0] < 0 ? nullptr : out[side[0]].data(),
                            side[1] < 0 ? nullptr : out[side[1]].data(), jac[t][columns[t][c].b]);
        }
        cost.keep(jac[t].data());
    }
}

Solve minimise(const std::vector<TrackCost*>& costs, std::vector<double>& x, std::vector<std::vector<double>>& q0,
               const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi, int max_iterations,
               double seconds, int threads, ceres::IterationCallback* callback, double initial_radius) {
    const int n = static_cast<int>(x.size());
    // Every track's simulations at a point as one set of tasks on the threads (Ceres' own threads
    // would share them out by track: 5 tracks on 2 threads keep 83 % of them busy).
    PointSimulations sims(costs, x, q0, static_cast<int>(held.size()) == n, threads);
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.evaluation_callback = &sims;
    ceres::Problem problem(po);
    for (std::size_t t = 0; t < costs.size(); ++t) {
        costs[t]->fresh_jacobian();
        problem.AddResidualBlock(costs[t], nullptr, x.data(), q0[t].data());
    }
    if (static_cast<int>(held.size()) == n)
        problem.SetParameterBlockConstant(x.data());
    else if (!held.empty())
        problem.SetManifold(x.data(), new ceres::SubsetManifold(n, held));
    for (int j = 0; j < n; ++j) {
        problem.SetParameterLowerBound(x.data(), j, lo[j]);
        problem.SetParameterUpperBound(x.data(), j, hi[j]);
    }
    ceres::Solver::Options so;
    so.minimizer_type = ceres::TRUST_REGION;
    so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    so.linear_solver_type = ceres::DENSE_QR;
    so.min_lm_diagonal = kMinLmDiagonal;
    // With bounds Ceres follows each step with a line search; cubic interpolation asks for the gradient,
    // so for every track's Jacobian, at every trial point: quadratic needs only the residuals there.
    so.line_search_interpolation_type = ceres::QUADRATIC;
    so.initial_trust_region_radius = initial_radius;
    so.max_num_iterations = max_iterations;
    so.max_solver_time_in_seconds = seconds;
    so.num_threads = 1;   // (the blocks only copy what `sims` prepared)
    // Converged when an iteration changes the chi-square by under 1e-6 of itself (about 1e-6 dof,
    // far below its sd sqrt(2 dof) at the truth) or the parameters by under 1e-6 of themselves:
    // tighter, the search only wanders along directions the tracks hardly see.
    so.function_tolerance = 1e-6;
    so.parameter_tolerance = 1e-6;
    so.logging_type = ceres::SILENT;
    if (callback) so.callbacks.push_back(callback);
    ceres::Solver::Summary sum;
    ceres::Solve(so, &problem, &sum);
    Solve out;
    out.chi2 = 2 * sum.final_cost;
    out.usable = sum.IsSolutionUsable();
    out.converged = sum.termination_type == ceres::CONVERGENCE;
    out.iterations = static_cast<int>(sum.iterations.size()) - 1;
    out.termination = std::string(ceres::TerminationTypeToString(sum.termination_type)) + ": " + sum.message;
    return out;
}

bool tracks_jacobians(const Scene& scene, const Layout& layout, const std::vector<Track>& tracks, const std::vector<int>& first,
                      const IdentifyOptions& o, const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
                      int threads, std::vector<Eigen::VectorXd>& r, std::vector<Eigen::MatrixXd>& Jx,
                      std::vector<Eigen::MatrixXd>& Jq) {
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const std::size_t nt = tracks.size();
    std::vector<std::unique_ptr<TrackCost>> costs;
    std::vector<TrackCost*> ptrs;
    for (std::size_t t = 0; t < nt; ++t) {
        costs.push_back(std::make_unique<TrackCost>(scene, layout, tracks[t], first[t], o, true));
        ptrs.push_back(costs.back().get());
    }
    PointSimulations sims(ptrs, x, q0, false, threads);
    sims.PrepareForEvaluation(true, true);
    r.resize(nt);
    Jx.resize(nt);
    Jq.resize(nt);
    for (std::size_t t = 0; t < nt; ++t) {
        const int m = costs[t]->num_residuals(), n = layout.size(), d = tracks[t].point ? 2 : 3;
        std::vector<double> rr(m), j0(static_cast<std::size_t>(m) * n), j1(static_cast<std::size_t>(m) * d);
        const double* params[2] = {x.data(), q0[t].data()};
        double* jac[2] = {j0.data(), j1.data()};
        if (!costs[t]->Evaluate(params, rr.data(), jac)) return false;   // (copies what `sims` prepared)
        r[t] = Eigen::Map<const Eigen::VectorXd>(rr.data(), m);
        Jx[t] = Eigen::Map<const RowMajor>(j0.data(), m, n);
        Jq[t] = Eigen::Map<const RowMajor>(j1.data(), m, d);
    }
    return true;
}

bool track_jacobian(const Scene& scene, const Layout& layout, const Track& track, int first, const IdentifyOptions& o,
                    const std::vector<double>& x, const std::vector<double>& q0, Eigen::VectorXd& r, Eigen::MatrixXd& Jx,
                    Eigen::MatrixXd& Jq) {
    std::vector<Eigen::VectorXd> rs;
    std::vector<Eigen::MatrixXd> Jxs, Jqs;
    if (!tracks_jacobians(scene, layout, {track}, {first}, o, x, {q0}, 1, rs, Jxs, Jqs)) return false;
    r = rs[0];
    Jx = Jxs[0];
    Jq = Jqs[0];
    return true;
}

}   // namespace plate::identify_detail
