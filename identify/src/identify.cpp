// The fit: one Ceres residual block per track (its frames' scaled residuals; central differences of
// the hybrid simulation), Levenberg-Marquardt from several starts, the best kept.
#include "internal.hpp"

#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace plate {
namespace identify_detail {
namespace {

// Levenberg-Marquardt's damping takes each parameter's information (the diagonal of J^T J, in noise
// sds per internal unit, squared) as at least this: a direction the tracks barely see (a static
// coefficient of a part that hardly sticks: 1e-2-1e2, against 1e8 for a kinetic one) is then not
// stepped across its whole range, into a regime it does not hold (docs/decisions/identification.md).
constexpr double kMinLmDiagonal = 1e4;
using Clock = std::chrono::steady_clock;
constexpr double kStartStepMm = 1e-3, kStartStepRad = 1e-5;   // central-difference steps of a track's start

// The starts: the scene's values (clamped into the bounds), then draws within them.
std::vector<std::vector<double>> starts(const Layout& layout, const IdentifyOptions& o) {
    std::vector<std::vector<double>> out;
    std::vector<double> x0 = layout.internal(layout.scene_values());
    for (int j = 0; j < layout.size(); ++j) x0[j] = std::min(std::max(x0[j], layout.lower(j, o)), layout.upper(j, o));
    out.push_back(x0);
    Rng rng(o.seed);
    for (int k = 1; k < o.starts; ++k) {
        std::vector<double> x(layout.size());
        for (int j = 0; j < layout.size(); ++j) {
            const Param::Kind kind = layout.p[j].kind;
            if (kind == Param::Kinetic)
                x[j] = rng.uniform(std::max(o.mu_min, 0.1), std::min(o.mu_max, 1.0));
            else if (kind == Param::Static)
                x[j] = rng.uniform(0, std::min(0.3, layout.upper(j, o)));
            else
                x[j] = rng.uniform(-0.25, 0.25) * o.com_max * 1e3;
        }
        out.push_back(x);
    }
    return out;
}

// Each track's start as the solver starts it: its first frame (mm, mm, rad).
std::vector<std::vector<double>> first_frames(const std::vector<Track>& tracks, int d) {
    std::vector<std::vector<double>> q0;
    for (const Track& tr : tracks) {
        const Vec3& f = tr.q.front();
        q0.push_back({f.x() * 1e3, f.y() * 1e3, f.z()});
        q0.back().resize(d);
    }
    return q0;
}

// The named parameters no track's residuals depend on at x (their Jacobian columns exactly zero: e.g.
// a static coefficient of a part that breaks away at once and never sticks). The solver holds them:
// Levenberg-Marquardt would only wander along them at the cost of their differences.
std::vector<int> unseen_parameters(const std::vector<std::unique_ptr<TrackCost>>& costs, const std::vector<double>& x,
                                   std::vector<std::vector<double>> q0, int n) {
    std::vector<bool> seen(n, false);
    for (std::size_t t = 0; t < costs.size(); ++t) {
        const int m = costs[t]->num_residuals();
        std::vector<double> r(m), j0(static_cast<std::size_t>(m) * n);
        const double* params[2] = {x.data(), q0[t].data()};
        double* jac[2] = {j0.data(), nullptr};
        if (!costs[t]->Evaluate(params, r.data(), jac)) return {};
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < n; ++j) seen[j] = seen[j] || j0[static_cast<std::size_t>(i) * n + j] != 0;
    }
    std::vector<int> held;
    for (int j = 0; j < n; ++j)
        if (!seen[j]) held.push_back(j);
    return held;
}

// One start's search (IdentifyOptions::fit_starts_first): the tracks' starts alone, then everything, by
// `deadline` seconds after t0; x and q0 hold the result, the iterations summed over both.
Solve staged(const std::vector<TrackCost*>& costs, std::vector<double>& x, std::vector<std::vector<double>>& q0,
             const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi, const IdentifyOptions& o,
             Clock::time_point t0, double deadline) {
    const auto left = [&] { return std::max(deadline - std::chrono::duration<double>(Clock::now() - t0).count(), 1e-3); };
    const int n = static_cast<int>(x.size());
    int iterations = 0;
    if (o.fit_starts_first) {
        std::vector<int> all(n);
        for (int j = 0; j < n; ++j) all[j] = j;
        Solve first = minimise(costs, x, q0, all, lo, hi, o.max_iterations, left(), o.threads, nullptr, o.initial_trust_radius);
        if (std::chrono::duration<double>(Clock::now() - t0).count() >= deadline) return first;   // (no time left)
        iterations = first.iterations;
    }
    Solve sol = minimise(costs, x, q0, held, lo, hi, o.max_iterations, left(), o.threads, nullptr, o.initial_trust_radius);
    sol.iterations += iterations;
    // A solve with chord steps may converge on its stale Jacobian (rejected steps shrinking the trust region
    // to the tolerance): only a solve whose every Jacobian is computed anew confirms it.
    if (o.jacobian_reuse > 0 && sol.converged && std::chrono::duration<double>(Clock::now() - t0).count() < deadline) {
        for (TrackCost* c : costs) c->reuse(0);
        Solve confirm =
            minimise(costs, x, q0, held, lo, hi, o.max_iterations, left(), o.threads, nullptr, o.initial_trust_radius);
        for (TrackCost* c : costs) c->reuse(o.jacobian_reuse);
        confirm.iterations += sol.iterations;
        sol = confirm;
    }
    return sol;
}

// What the fit says at internal coordinates x and starts q0: each track's fit and the chi-square, the
// covariance and intervals from the whole Jacobian (central differences; the tracks' starts beside the
// named parameters), and each interval's check, with the best end of its paths in `better`.
void conclude(const Scene& scene, const Layout& layout, const std::vector<Track>& tracks, const IdentifyOptions& o,
              const std::vector<TrackCost*>& costs, const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
              IdentifySummary& s, PathEnd& better) {
    const int n = layout.size(), nt = static_cast<int>(tracks.size()), d = scene.part.point ? 2 : 3;
    int rows = 0;
    for (const TrackCost* c : costs) rows += c->num_residuals();
    s.tracks.clear();
    s.unidentifiable.clear();
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n + d * nt);
    s.chi2 = 0;
    for (int t = 0, row = 0; t < nt; ++t) {
        Eigen::VectorXd r;
        Eigen::MatrixXd Jx, Jq;
        if (!track_jacobian(scene, layout, tracks[t], first_used_frame(tracks[t], scene.plate.T, o.settle_periods), o, x, q0[t],
                            r, Jx, Jq))
            throw std::runtime_error("identify: the optimum's simulation stopped");
        const int m = static_cast<int>(r.size());
        J.block(row, 0, m, n) = Jx;
        J.block(row, n + d * t, m, d) = Jq;
        TrackFit f;
        f.source = tracks[t].source;
        f.frames = m / d;
        f.start = Vec3(q0[t][0] * 1e-3, q0[t][1] * 1e-3, d == 3 ? q0[t][2] : 0.0);
        double sxy = 0, sth = 0;
        for (int i = 0; i < m; ++i) {
            f.chi2 += r[i] * r[i];
            (i % d < 2 ? sxy : sth) += r[i] * r[i];
        }
        f.rms_xy_mm = std::sqrt(sxy / (2.0 * f.frames)) * tracks[t].camera.noise_xy_mm;
        f.rms_theta_mrad = d == 3 ? std::sqrt(sth / f.frames) * tracks[t].camera.noise_theta_mrad : 0.0;
        s.chi2 += f.chi2;
        s.tracks.push_back(f);
        row += m;
    }
    s.residuals = rows;
    s.dof = rows - (n + d * nt);
    s.reduced_chi2 = s.dof > 0 ? s.chi2 / s.dof : std::numeric_limits<double>::quiet_NaN();
    const Eigen::MatrixXd cov_internal = judge(layout, o, x, J, d * nt, s);
    check_linearity(layout, o, costs, x, q0, J, cov_internal, s, better);
}

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

bool TrackCost::Evaluate(double const* const* parameters, double* r, double** jacobians) const {
    if (!residuals(parameters[0], parameters[1], r)) return false;
    if (!jacobians) return true;
    const int m = num_residuals();
    const bool whole = jacobians[0] && jacobians[1] && profiled_ < 0;   // what a chord step can reuse
    if (whole && reused_ < reuse_) {
        ++reused_;
        for (int b = 0; b < 2; ++b) std::copy(kept_[b].begin(), kept_[b].end(), jacobians[b]);
        return true;
    }
    std::vector<double> plus(m), minus(m);
    for (int b = 0; b < 2; ++b) {
        if (!jacobians[b]) continue;
        const int n = b == 0 ? layout_.size() : dim_;
        std::vector<double> x(parameters[b], parameters[b] + n);
        for (int j = 0; j < n; ++j) {
            if (b == 0 && j == profiled_) {   // held along the profile
                for (int i = 0; i < m; ++i) jacobians[b][i * n + j] = 0;
                continue;
            }
            const double h = b == 0 ? layout_.step(j) : (j < 2 ? kStartStepMm : kStartStepRad);
            const double x0 = x[j];
            // One-sided at a bound (a static excess at 0: below it the part would have static < kinetic).
            const bool up = b != 0 || x0 + h <= hi_[j];
            const bool down = (central_ || !up) && (b != 0 || x0 - h >= lo_[j]);
            const double* blocks[2] = {parameters[0], parameters[1]};
            blocks[b] = x.data();
            x[j] = x0 + (up ? h : 0);
            if (up && !residuals(blocks[0], blocks[1], plus.data())) return false;
            x[j] = x0 - (down ? h : 0);
            if (down && !residuals(blocks[0], blocks[1], minus.data())) return false;
            x[j] = x0;
            const double span = (up ? h : 0) + (down ? h : 0);
            for (int i = 0; i < m; ++i) jacobians[b][i * n + j] = ((up ? plus[i] : r[i]) - (down ? minus[i] : r[i])) / span;
        }
    }
    if (whole && reuse_ > 0) {
        reused_ = 0;
        kept_[0].assign(jacobians[0], jacobians[0] + static_cast<std::size_t>(m) * layout_.size());
        kept_[1].assign(jacobians[1], jacobians[1] + static_cast<std::size_t>(m) * dim_);
    }
    return true;
}

Solve minimise(const std::vector<TrackCost*>& costs, std::vector<double>& x, std::vector<std::vector<double>>& q0,
               const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi, int max_iterations,
               double seconds, int threads, ceres::IterationCallback* callback, double initial_radius) {
    const int n = static_cast<int>(x.size());
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
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
    so.num_threads = threads;
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

bool track_jacobian(const Scene& scene, const Layout& layout, const Track& track, int first, const IdentifyOptions& o,
                    const std::vector<double>& x, const std::vector<double>& q0, Eigen::VectorXd& r, Eigen::MatrixXd& Jx,
                    Eigen::MatrixXd& Jq) {
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const TrackCost cost(scene, layout, track, first, o, true);
    const int m = cost.num_residuals(), n = layout.size(), d = track.point ? 2 : 3;
    std::vector<double> rr(m), j0(static_cast<std::size_t>(m) * n), j1(static_cast<std::size_t>(m) * d);
    const double* params[2] = {x.data(), q0.data()};
    double* jac[2] = {j0.data(), j1.data()};
    if (!cost.Evaluate(params, rr.data(), jac)) return false;
    r = Eigen::Map<const Eigen::VectorXd>(rr.data(), m);
    Jx = Eigen::Map<const RowMajor>(j0.data(), m, n);
    Jq = Eigen::Map<const RowMajor>(j1.data(), m, d);
    return true;
}

}   // namespace identify_detail

void IdentifyOptions::validate() const {
    auto bad = [](const std::string& what) { throw std::invalid_argument("identify: " + what); };
    if (params.empty()) bad("params: no parameter to fit");
    if (level != Dynamics::Full && level != Dynamics::U) bad("level: full or U dynamics");
    if (starts < 1 || starts > 1000) bad("starts: from 1 to 1000");
    if (max_iterations < 1 || max_iterations > 10000) bad("max_iterations: from 1 to 10000");
    if (!(time_limit > 0 && time_limit <= 1e6)) bad("time_limit: a positive number of seconds up to 1e6");
    if (!(settle_periods >= 0 && settle_periods <= 1e6)) bad("settle_periods: from 0 to 1e6");
    if (!(rtol > 0 && rtol <= 1e-3)) bad("rtol: in (0, 1e-3]");
    if (!(segment_seconds >= 0 && segment_seconds <= 1e6)) bad("segment_seconds: from 0 (none) to 1e6 s");
    if (!(initial_trust_radius >= 1 && initial_trust_radius <= 1e12)) bad("initial_trust_radius: from 1 to 1e12");
    if (jacobian_reuse < 0 || jacobian_reuse > 100) bad("jacobian_reuse: from 0 to 100");
    if (hops < 0 || hops > 100) bad("hops: from 0 to 100");
    if (!(segment_settle_periods >= 0 && segment_settle_periods <= 1e6)) bad("segment_settle_periods: from 0 to 1e6");
    if (threads < 1 || threads > 1024) bad("threads: from 1 to 1024");
    if (!(mu_min > 0 && mu_min < mu_max && mu_max <= 10)) bad("mu_min, mu_max: 0 < mu_min < mu_max <= 10");
    if (!(com_max > 0 && com_max <= 1)) bad("com_max: in (0, 1] m");
}

void check_tracks(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o) {
    if (tracks.empty()) throw std::invalid_argument("identify: no track");
    for (const Track& tr : tracks) {
        const std::string src = tr.source.empty() ? std::string("(track)") : tr.source;
        check_track_scene(tr, scene);
        if (tr.point != scene.part.point)
            throw InputError(src + ": a " + (tr.point ? "point" : "rigid") + " part's track for the scene's " +
                             (scene.part.point ? "point" : "rigid") + " part");
        const std::string camera_line = tr.scene_id_line ? ":" + std::to_string(tr.scene_id_line + 1) : "";
        if (!(tr.camera.noise_xy_mm > 0) || (!tr.point && !(tr.camera.noise_theta_mrad > 0)))
            throw InputError(src + camera_line +
                             ": the camera has no noise: identification weighs each frame by the noise's sd (give it)");
        const int first = identify_detail::first_used_frame(tr, scene.plate.T, o.settle_periods);
        const int used = static_cast<int>(tr.t.size()) - first;
        if (used < kMinTrackFrames) {
            const std::string line = tr.lines.empty() ? "" : ":" + std::to_string(tr.lines.back());
            throw InputError(src + line + ": " + std::to_string(used) + " frames after the first " +
                             std::to_string(o.settle_periods) + " periods (at least " + std::to_string(kMinTrackFrames) +
                             " are needed)");
        }
    }
}

void check_pieces(const Scene& scene, const IdentifyOptions& o) {
    if (o.segment_seconds > 0 && std::max(1L, std::lround(o.segment_seconds / scene.plate.T)) <= o.segment_settle_periods) {
        char m[200];
        std::snprintf(m, sizeof m,
                      "identify: segment_seconds: pieces of %g s are no longer than the %g periods of %g s each leaves out",
                      o.segment_seconds, o.segment_settle_periods, scene.plate.T);
        throw std::invalid_argument(m);
    }
}

IdentifySummary identify(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o) {
    using namespace identify_detail;
    const auto t0 = Clock::now();
    o.validate();
    const Layout layout(scene, o.params);
    check_tracks(scene, tracks, o);
    check_pieces(scene, o);
    const int n = layout.size(), nt = static_cast<int>(tracks.size()), d = scene.part.point ? 2 : 3;
    std::vector<int> firsts;
    for (const Track& tr : tracks) firsts.push_back(first_used_frame(tr, scene.plate.T, o.settle_periods));
    std::vector<std::unique_ptr<TrackCost>> costs;
    for (std::size_t t = 0; t < tracks.size(); ++t)
        costs.push_back(std::make_unique<TrackCost>(scene, layout, tracks[t], firsts[t], o, o.central_search));

    IdentifySummary s;
    // A start whose chi-square lies within 3 sds of its mean at the truth (dof + 3 sqrt(2 dof)) fits as
    // well as the noise allows: the later starts are not run.
    int rows = 0;
    for (const auto& c : costs) rows += c->num_residuals();
    const double enough = (rows - n - d * nt) + 3 * std::sqrt(2.0 * std::max(rows - n - d * nt, 1));
    std::vector<double> best;
    std::vector<std::vector<double>> best_q0;
    double best_cost = std::numeric_limits<double>::infinity();
    const std::vector<std::vector<double>> xs = starts(layout, o);
    const std::vector<int> held = unseen_parameters(costs, xs[0], first_frames(tracks, d), n);
    s.held = static_cast<int>(held.size());
    std::vector<TrackCost*> cost_ptrs;
    for (const auto& c : costs) cost_ptrs.push_back(c.get());
    // The pieces of the first stage: none if no track is as long as two pieces, or if the plate turns about
    // more than one axis (its orientation then drifts from period to period, coning: a piece re-timed by
    // whole periods would start under another one). A track's first piece starts where the track does; a
    // later one from rest, its first periods left out (and none the track's own settle leaves out).
    int turning = 0;
    for (int a = 3; a < 6; ++a) {
        bool on = false;
        for (const Harmonic& h : scene.plate.harmonics) on = on || (static_cast<int>(h.axis) == a && h.amp != 0);
        turning += on;
    }
    std::vector<double> shifts;
    std::vector<Track> pieces;
    std::vector<int> piece_firsts;
    if (o.segment_seconds > 0 && turning <= 1) {
        const std::vector<Track> cut = segments(tracks, scene.plate.T, o.segment_seconds, shifts);
        for (std::size_t i = 0; cut.size() > tracks.size() && i < cut.size(); ++i) {
            const double settle = shifts[i] > 0 ? std::max(o.segment_settle_periods, o.settle_periods - shifts[i] / scene.plate.T)
                                                : o.settle_periods;
            const int first = first_used_frame(cut[i], scene.plate.T, settle);
            if (static_cast<int>(cut[i].t.size()) - first < kMinTrackFrames) continue;
            pieces.push_back(cut[i]);
            piece_firsts.push_back(first);
        }
    }
    std::vector<std::unique_ptr<TrackCost>> piece_costs;
    std::vector<TrackCost*> piece_ptrs;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        piece_costs.push_back(std::make_unique<TrackCost>(scene, layout, pieces[i], piece_firsts[i], o, o.central_search));
        piece_ptrs.push_back(piece_costs.back().get());
    }
    std::vector<double> lo, hi;
    for (int j = 0; j < n; ++j) {
        lo.push_back(layout.lower(j, o));
        hi.push_back(layout.upper(j, o));
    }
    for (int k = 0; k < static_cast<int>(xs.size()); ++k) {
        if (std::chrono::duration<double>(Clock::now() - t0).count() >= o.time_limit) break;
        std::vector<double> x = xs[k];
        Solve on_pieces;
        double piece_seconds = 0;
        if (!piece_ptrs.empty()) {
            const auto p_start = Clock::now();
            std::vector<std::vector<double>> p0 = first_frames(pieces, d);
            // (at most half the time left: the whole tracks' stage decides the result)
            const double now = std::chrono::duration<double>(p_start - t0).count();
            on_pieces = staged(piece_ptrs, x, p0, held, lo, hi, o, t0, now + 0.5 * (o.time_limit - now));
            piece_seconds = std::chrono::duration<double>(Clock::now() - p_start).count();
        }
        std::vector<std::vector<double>> q0 = first_frames(tracks, d);
        const Solve sol = staged(cost_ptrs, x, q0, held, lo, hi, o, t0, o.time_limit);
        ++s.starts_run;
        s.start_costs.push_back(sol.chi2);
        if (sol.usable && sol.chi2 < best_cost) {
            best_cost = sol.chi2;
            best = x;
            best_q0 = q0;
            s.best_start = k;
            s.iterations = sol.iterations;
            s.pieces = static_cast<int>(pieces.size());
            s.piece_iterations = on_pieces.iterations;
            s.piece_seconds = piece_seconds;
            s.termination = sol.termination;
            s.converged = sol.converged;
        }
        if (best_cost <= enough) break;
    }
    if (best.empty()) throw std::runtime_error("identify: no start gave a usable fit (every simulation stopped?)");

    // The fit's verdict at the best start's optimum; then, while the interval check finds a fit better by
    // more than one chi-square unit at an end of its paths (the search stopped in a cell of the chi-square
    // that a step of 1.96 sd leaves: docs/decisions/identification.md, "Hops"), the search goes on from there.
    PathEnd better;
    conclude(scene, layout, tracks, o, cost_ptrs, best, best_q0, s, better);
    for (int hop = 0; hop < o.hops && better.chi2 < s.chi2 - 1; ++hop) {
        if (std::chrono::duration<double>(Clock::now() - t0).count() >= o.time_limit) break;
        std::vector<double> x = better.x;
        std::vector<std::vector<double>> q0 = better.q0;
        const Solve sol = staged(cost_ptrs, x, q0, held, lo, hi, o, t0, o.time_limit);
        if (!sol.usable || !(sol.chi2 < s.chi2)) break;
        IdentifySummary hopped = s;
        ++hopped.hops;
        hopped.iterations += sol.iterations;
        hopped.termination = sol.termination;
        hopped.converged = sol.converged;
        try {
            conclude(scene, layout, tracks, o, cost_ptrs, x, q0, hopped, better);
        } catch (const std::runtime_error&) {   // (a simulation at the hop's optimum stopped: the fit before it stands)
            break;
        }
        s = hopped;
        best = x;
        best_q0 = q0;
    }
    s.fitted = at(scene, layout, best);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

}   // namespace plate
