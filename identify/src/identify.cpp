// The fit: one Ceres residual block per track (its frames' scaled residuals; central differences of
// the hybrid simulation), Levenberg-Marquardt from several starts, the best kept.
#include "internal.hpp"

#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <ceres/ceres.h>
#include <gsl/gsl_cdf.h>

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

using Clock = std::chrono::steady_clock;

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

// The wide steps (IdentifyOptions::wide_iterations; docs/decisions/identification.md, "Wide steps across the
// cells" and "Line steps over the cells"), from the best fit (x, q0, its chi-square chi2), in two rungs:
// coarse_steps' wide Levenberg-Marquardt, then line_steps. After each, where it lowered the chi-square by more
// than 1 (as the hops ask: less is no evidence of a better fit, and moves the fit to a neighbouring cell for
// nothing), the fine search runs from there; x, q0 and chi2 take its end where that search is usable and lower
// (else the fit stays). Within o.time_limit.
void wide_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const std::vector<int>& held,
                const std::vector<double>& lo, const std::vector<double>& hi, const IdentifyOptions& o, Clock::time_point t0,
                std::vector<double>& x, std::vector<std::vector<double>>& q0, double& chi2, IdentifySummary& s) {
    const auto start = Clock::now();
    const auto left = [&] { return o.time_limit - std::chrono::duration<double>(Clock::now() - t0).count(); };
    if (o.wide_iterations == 0 || left() <= 0) return;
    for (const bool line : {false, true}) {
        if (left() <= 0) break;
        std::vector<double> y = x;
        std::vector<std::vector<double>> qy = q0;
        const CoarseResult rung =
            line ? line_steps(costs, layout, o, y, qy, held, lo, hi, left(), o.wide_iterations)
                 : coarse_steps(costs, layout, o, y, qy, held, lo, hi, left(), o.wide_iterations, kWideFactor, true);
        if (!(rung.iterations > 0 && rung.chi2_after < chi2 - 1 && left() > 0)) continue;
        // (the fine search's end confirmed by Jacobians computed anew, as staged's)
        for (TrackCost* c : costs) c->reuse(0);
        const Solve fine =
            minimise(costs, y, qy, held, lo, hi, o.max_iterations, left(), o.threads, nullptr, o.initial_trust_radius);
        for (TrackCost* c : costs) c->reuse(o.jacobian_reuse);
        if (!(fine.usable && fine.chi2 < chi2)) continue;
        s.wide_iterations += rung.iterations;
        s.wide_chi2_drop += chi2 - fine.chi2;
        s.iterations += fine.iterations;
        s.termination = fine.termination;
        s.converged = fine.converged;
        x = y;
        q0 = qy;
        chi2 = fine.chi2;
    }
    s.wide_seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

// What conclude() leaves for the cells' spread: the whole Jacobian, the residuals and the linearised
// covariance (internal coordinates) at the fit.
struct AtFit {
    Eigen::MatrixXd J, cov_internal;
    Eigen::VectorXd r0;
};

// What the fit says at internal coordinates x and starts q0: each track's fit and the chi-square, the
// covariance and intervals from the whole Jacobian (central differences; the tracks' starts beside the
// named parameters), and each interval's check, with the best end of its paths in `better`.
void conclude(const Scene& scene, const Layout& layout, const std::vector<Track>& tracks, const IdentifyOptions& o,
              const std::vector<TrackCost*>& costs, const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
              IdentifySummary& s, PathEnd& better, AtFit& at_fit) {
    const int n = layout.size(), nt = static_cast<int>(tracks.size()), d = scene.part.point ? 2 : 3;
    int rows = 0;
    for (const TrackCost* c : costs) rows += c->num_residuals();
    s.tracks.clear();
    s.unidentifiable.clear();
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n + d * nt);
    s.chi2 = 0;
    std::vector<int> first;
    for (const Track& tr : tracks) first.push_back(first_used_frame(tr, scene.plate.T, o.settle_periods));
    std::vector<Eigen::VectorXd> rs;
    std::vector<Eigen::MatrixXd> Jxs, Jqs;
    if (!tracks_jacobians(scene, layout, tracks, first, o, x, q0, o.threads, rs, Jxs, Jqs))
        throw std::runtime_error("identify: the optimum's simulation stopped");
    for (int t = 0, row = 0; t < nt; ++t) {
        const Eigen::VectorXd& r = rs[t];
        const int m = static_cast<int>(r.size());
        J.block(row, 0, m, n) = Jxs[t];
        J.block(row, n + d * t, m, d) = Jqs[t];
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
    // (a non-finite chi-square would make GSL's error handler abort: it explains nothing)
    s.p_value = s.dof <= 0              ? std::numeric_limits<double>::quiet_NaN()
                : std::isfinite(s.chi2) ? gsl_cdf_chisq_Q(s.chi2, s.dof)
                                        : 0.0;
    s.explains_tracks = !(s.p_value < kFitPValueFloor);
    const Eigen::MatrixXd cov_internal = judge(layout, o, x, J, d * nt, s);
    check_linearity(layout, o, costs, x, q0, J, cov_internal, s, better);
    at_fit.r0.resize(rows);
    for (int t = 0, row = 0; t < nt; row += static_cast<int>(rs[t].size()), ++t) at_fit.r0.segment(row, rs[t].size()) = rs[t];
    at_fit.J = std::move(J);
    at_fit.cov_internal = cov_internal;
}

// After the fit at (best, best_q0), judged in s: while the interval check finds a fit better by more than
// one chi-square unit at an end of its paths (the search stopped in a cell of the chi-square that a step
// of 1.96 sd leaves: docs/decisions/identification.md, "Hops"), the search goes on from there.
void hops(const Scene& scene, const Layout& layout, const std::vector<Track>& tracks, const IdentifyOptions& o,
          const std::vector<TrackCost*>& costs, const std::vector<int>& held, const std::vector<double>& lo,
          const std::vector<double>& hi, Clock::time_point t0, IdentifySummary& s, std::vector<double>& best,
          std::vector<std::vector<double>>& best_q0, PathEnd& better, AtFit& at_fit) {
    for (int hop = 0; hop < o.hops && better.chi2 < s.chi2 - 1; ++hop) {
        if (std::chrono::duration<double>(Clock::now() - t0).count() >= o.time_limit) break;
        std::vector<double> x = better.x;
        std::vector<std::vector<double>> q0 = better.q0;
        const Solve sol = staged(costs, x, q0, held, lo, hi, o, t0, o.time_limit);
        if (!sol.usable || !(sol.chi2 < s.chi2)) break;
        IdentifySummary hopped = s;
        AtFit hopped_at;
        ++hopped.hops;
        hopped.iterations += sol.iterations;
        hopped.termination = sol.termination;
        hopped.converged = sol.converged;
        try {
            conclude(scene, layout, tracks, o, costs, x, q0, hopped, better, hopped_at);
        } catch (const std::runtime_error&) {   // (a simulation at the hop's optimum stopped: the fit before it stands)
            break;
        }
        s = hopped;
        at_fit = std::move(hopped_at);
        best = x;
        best_q0 = q0;
    }
}

}   // namespace

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
    if (coarse_iterations < 0 || coarse_iterations > 100) bad("coarse_iterations: from 0 to 100");
    if (wide_iterations < 0 || wide_iterations > 1000) bad("wide_iterations: from 0 to 1000");
    if (cell_samples < 0 || cell_samples > 10000) bad("cell_samples: from 0 to 10000");
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
        // (a later start: the best fit's kinetic coefficients and offsets, the static ones the scene's for the
        // second, drawn after it)
        std::vector<double> x = k > 0 && !best.empty() ? restart(layout, best, xs[k == 1 ? 0 : k], xs[k]) : xs[k];
        CoarseResult coarse;
        if (o.coarse_iterations > 0) {   // (at most a quarter of the time left)
            std::vector<std::vector<double>> at_first = first_frames(tracks, d);
            coarse = coarse_steps(cost_ptrs, layout, o, x, at_first, held, lo, hi,
                                  0.25 * (o.time_limit - std::chrono::duration<double>(Clock::now() - t0).count()),
                                  o.coarse_iterations, kCoarseFactor, false);
        }
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
            s.coarse_iterations = coarse.iterations;
            s.coarse_seconds = coarse.seconds;
            s.piece_iterations = on_pieces.iterations;
            s.piece_seconds = piece_seconds;
            s.termination = sol.termination;
            s.converged = sol.converged;
        }
        if (best_cost <= enough) break;
    }
    if (best.empty()) throw std::runtime_error("identify: no start gave a usable fit (every simulation stopped?)");

    wide_steps(cost_ptrs, layout, held, lo, hi, o, t0, best, best_q0, best_cost, s);

    // The fit's verdict at the best start's optimum, then its hops.
    PathEnd better;
    AtFit at_fit;
    conclude(scene, layout, tracks, o, cost_ptrs, best, best_q0, s, better, at_fit);
    hops(scene, layout, tracks, o, cost_ptrs, held, lo, hi, t0, s, best, best_q0, better, at_fit);
    const auto cells_start = Clock::now();
    add_cells(layout, best, cell_spread(layout, o, cost_ptrs, best, best_q0, at_fit.J, at_fit.r0, at_fit.cov_internal), s);
    s.cells_seconds = std::chrono::duration<double>(Clock::now() - cells_start).count();
    if (o.envelope) {
        const auto envelope_start = Clock::now();
        long simulations = 0;
        add_envelope(envelope_sds(layout, o, cost_ptrs, best, best_q0, held, lo, hi, simulations), s);
        s.envelope_seconds = std::chrono::duration<double>(Clock::now() - envelope_start).count();
    }
    s.fitted = at(scene, layout, best);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

}   // namespace plate
