// Benchmark: stick-slip (issue 14). Not a test: nothing here passes or fails.
//   (1) fields in one run: fig6 (78 of 343 configurations stick), heave_yaw (every configuration
//       sticks) and the never-sticking fig4, wall time on 1 and all threads;
//   (1d) plate's side of the peers study's question (d): fig6's sticking configurations from rest;
//   (2) at equal accuracy, the event-driven engine against the regularised-friction method
//       (f = -mu N v / sqrt(|v|^2 + eps^2) integrated by GSL's bsimp, the stiff method that works
//       for it, see README): on a sample of fig6's sticking configurations, each method's error against
//       the regularised reference extrapolated to eps = 0, and its time; the regularised method at the
//       largest eps whose error stays below 1e-6 v_ref on the whole sample, against the engine.
// Ratios are measured in this run; absolute figures come with the machine.
#include "plate/dynamics.hpp"
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"
#include "plate/study.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <utility>
#include <vector>

using namespace plate;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
double thread_cpu_seconds() {   // (the peers study's clock: this thread's CPU time)
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

Scene scene(const std::string& name) { return load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

double distance(const Scene& sc, const Vec3& a, const Vec3& b) {
    const double v = sc.v_ref();
    return (a - b).cwiseQuotient(Vec3(v, v, v / sc.part.rho())).cwiseAbs().maxCoeff();
}

// (1) fields on 1 and all threads, and the goal for fig6's.
void fields_timing() {
    // Each field seven times (this machine's speed drifts by up to 30 % over seconds): the best and the
    // median wall time; the field itself is the same every time (and on any threads).
    std::printf("\n(1) fields, 7x7x7 (point parts 7x7), default options (rtol 1e-8, cycle tol 1e-7), seven runs each\n");
    double fig6_best = 0, fig6_median = 0;   // on all threads
    for (const char* name : {"fig6", "heave_yaw", "heave_yaw_point", "fig4"}) {
        const Scene sc = scene(name);
        for (int threads : {1, 0}) {
            FieldOptions opt;
            opt.threads = threads;
            Field f;
            std::vector<double> wall;
            for (int run = 0; run < 7; ++run) {
                f = compute_field(sc, GridSpec{}, opt);
                wall.push_back(f.seconds);
            }
            std::sort(wall.begin(), wall.end());
            if (threads == 0 && std::string(name) == "fig6") {
                fig6_best = wall.front();
                fig6_median = wall[3];
            }
            int converged = 0, sticking = 0;
            for (const auto& p : f.points) {
                converged += p.converged;
                sticking += *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0;
            }
            std::printf(
                "  %-16s %d thread(s): %.3f s wall (median %.3f), %.3g right-hand sides, %d/%zu defined, %d stick "
                "during their cycle\n",
                name, f.threads, wall.front(), wall[3], static_cast<double>(f.rhs_evals), converged, f.points.size(), sticking);
        }
    }

    std::printf(
        "  the goal, fig6's field in at most 0.1 s on this machine: %s at the best of seven runs (%.3f s), %s at "
        "the median (%.3f s)\n",
        fig6_best <= 0.1 ? "met" : "not met", fig6_best, fig6_median <= 0.1 ? "met" : "not met", fig6_median);
}

// (1b), (1c) where fig6's field goes: sticking against sliding configurations.
void fig6_costs() {
    std::printf(
        "\n(1b) where fig6's field goes (one thread): right-hand sides and periods, sticking against sliding\n"
        "     configurations (docs/decisions.md, Where fig6's field's work goes)\n");
    {
        FieldOptions opt;
        opt.threads = 1;
        const Field f = compute_field(scene("fig6"), GridSpec{}, opt);
        long rhs[2] = {0, 0};
        int n[2] = {0, 0}, periods[2] = {0, 0};
        for (const auto& p : f.points) {
            const int k = *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0;
            rhs[k] += p.rhs_evals;
            periods[k] += p.periods;
            ++n[k];
        }
        for (int k : {1, 0})
            std::printf(
                "  %-8s %3d configurations: %4.1f %% of the right-hand sides, %.1f periods each, %.0f right-hand sides "
                "a period\n",
                k ? "sticking" : "sliding", n[k], 100.0 * rhs[k] / f.rhs_evals, n[k] ? double(periods[k]) / n[k] : 0.0,
                periods[k] ? double(rhs[k]) / periods[k] : 0.0);

        // (1c) Why a sticking period costs more: of the accepted steps of each cycle's last period
        // (recorded), the slides whose smallest slip at the step's start is between 5e-5 and 1e-2
        // v_ref, and there the step relative to T |v| / v_ref. Where a slip is small the friction
        // direction relaxes at a rate ~ |a| / |v|, which bounds an explicit step: it grows with the slip.
        std::printf(
            "\n(1c) fig6's cycles, last period's accepted steps (every mode), and among them the slides whose\n"
            "     smallest slip s at the step's start is small\n");
        const Scene sc = scene("fig6");
        const double T = sc.plate.T, v = sc.v_ref();
        for (int k : {1, 0}) {
            long steps = 0, small = 0;
            std::vector<double> ratio;
            for (const auto& p : f.points) {
                if ((*std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0) != bool(k)) continue;
                LimitCycleOptions o;
                o.record = true;
                const LimitCycleSummary lc = limit_cycle(sc, p.q, o);
                if (!lc.converged || lc.path.empty()) continue;
                const double t_end = lc.path.back().t;
                for (std::size_t i = 1; i < lc.path.size(); ++i) {
                    const Sample& a = lc.path[i - 1];
                    if (a.t < t_end - T * (1 + 1e-12)) continue;
                    ++steps;
                    if (a.mode.kind != ModeKind::Slide || lc.path[i].mode.kind != ModeKind::Slide) continue;
                    std::array<Vec2, 3> slip;
                    slip_velocities(sc.part, p.q, a.qd, slip);
                    double s = slip[0].norm();
                    for (int c = 1; c < sc.part.contacts(); ++c) s = std::min(s, slip[c].norm());
                    if (s < 5e-5 * v || s > 1e-2 * v) continue;
                    ++small;
                    ratio.push_back((lc.path[i].t - a.t) / (T * s / v));
                }
            }
            std::sort(ratio.begin(), ratio.end());
            const auto pct = [&](double f) { return ratio.empty() ? 0.0 : ratio[std::size_t(f * (ratio.size() - 1))]; };
            std::printf(
                "  %-8s %5ld steps, %4.1f %% with 5e-5 <= s / v_ref <= 1e-2; there step / (T s / v_ref): "
                "median %.2f (10-90 %%: %.2f-%.2f)\n",
                k ? "sticking" : "sliding", steps, steps ? 100.0 * small / steps : 0.0, pct(0.5), pct(0.1), pct(0.9));
        }
    }
}

// (1d) plate's side of the peers study's question (d) (bench/peers/study.cpp): fig6's sticking
// configurations (stick fraction > 0 in the field at tol 1e-10, rtol 1e-11), each cycle from rest on
// one thread at the study's settings; its ratio is an engine's CPU time over the cheapest of these
// at least as accurate as the engine.
void peers_sticking() {
    std::printf(
        "\n(1d) fig6's sticking configurations, each cycle from rest (the peers study's question (d)): thread CPU\n"
        "     time, best of three, right-hand sides, periods and the largest twist error against the tight field\n");
    const Scene sc = scene("fig6");
    FieldOptions tight;
    tight.cycle.tol = 1e-10;
    tight.cycle.integration.rtol = 1e-11;
    const Field ref = compute_field(sc, GridSpec{}, tight);
    std::vector<int> idx;
    for (int i = 0; i < static_cast<int>(ref.points.size()); ++i) {
        const FieldPoint& p = ref.points[i];
        if (p.converged && *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0) idx.push_back(i);
    }
    for (const auto& [tol, rtol] :
         std::vector<std::pair<double, double>>{{1e-2, 1e-4}, {1e-4, 1e-5}, {1e-6, 1e-7}, {1e-7, 1e-8}}) {
        LimitCycleOptions o;
        o.tol = tol;
        o.integration.rtol = rtol;
        double best = 1e300, err = 0;
        long rhs = 0;
        int periods = 0, converged = 0;
        for (int run = 0; run < 3; ++run) {
            err = 0;
            rhs = 0;
            periods = 0;
            converged = 0;
            const double t0 = thread_cpu_seconds();
            for (int i : idx) {
                const LimitCycleSummary lc = limit_cycle(sc, ref.points[i].q, o);
                err = std::max(err, lc.converged ? distance(sc, lc.twist, ref.points[i].twist) : INFINITY);
                rhs += lc.stats.rhs_evals;
                periods += lc.periods;
                converged += lc.converged;
            }
            best = std::min(best, thread_cpu_seconds() - t0);
        }
        std::printf(
            "  tol %.0e, rtol %.0e: %zu configurations, %.4f s CPU (%.3f ms each), %ld right-hand sides, %.2f periods each, "
            "%d converged, largest error %.1e\n",
            tol, rtol, idx.size(), best, 1e3 * best / idx.size(), rhs, double(periods) / idx.size(), converged, err);
    }
}

// (2) the engine against the regularised-friction method at equal accuracy.
void against_regularised() {
    std::printf(
        "\n(2) fig6's sticking configurations, every 5th in grid order: error against the regularised\n"
        "    reference (eps -> 0), relative to v_ref, and time per configuration\n");
    const Scene sc = scene("fig6");
    const GridSpec grid;
    std::vector<Vec3> sample;
    int seen = 0;
    for (int idx = 0; idx < grid.size(); ++idx) {
        const int i = idx / (grid.ny * grid.nth), j = (idx / grid.nth) % grid.ny, k = idx % grid.nth;
        const Vec3 q = grid.at(i, j, k);
        const LimitCycleSummary lc = limit_cycle(sc, q);
        if (!lc.converged) continue;
        if (*std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end()) > 0 && seen++ % 5 == 0) sample.push_back(q);
    }
    std::vector<Vec3> ref(sample.size());
    double t_ref = 0;
    for (std::size_t n = 0; n < sample.size(); ++n) {
        const RegularisedReference r = regularised_reference(sc, sample[n]);
        ref[n] = r.twist;
        t_ref += r.seconds;
    }
    std::printf("  %zu configurations; the reference took %.2f s in all\n", sample.size(), t_ref);

    std::vector<double> err_engine, ms;
    const auto t0 = Clock::now();
    std::size_t at = 0;
    for (std::size_t n = 0; n < sample.size(); ++n) {
        const auto t1 = Clock::now();
        const LimitCycleSummary lc = limit_cycle(sc, sample[n]);
        ms.push_back(1e3 * since(t1));
        err_engine.push_back(distance(sc, lc.twist, ref[n]));
        if (err_engine.back() >= err_engine[at]) at = n;
    }
    const double t_engine = since(t0);
    std::printf(
        "  engine (events, rtol 1e-8):   %8.2f ms per configuration (slowest %.1f ms), largest error %.1e at "
        "(%.4f, %.4f, %.3f)\n",
        1e3 * t_engine / sample.size(), *std::max_element(ms.begin(), ms.end()), err_engine[at], sample[at][0], sample[at][1],
        sample[at][2]);
    std::sort(err_engine.begin(), err_engine.end());
    std::sort(ms.begin(), ms.end());
    std::printf("                                 median %.2f ms; error median %.1e, second largest %.1e\n", ms[ms.size() / 2],
                err_engine[err_engine.size() / 2], err_engine[err_engine.size() - 2]);

    double chosen_time = 0, chosen_eps = 0;
    for (double eps : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
        Solver s;
        s.method = Method::GslBsimp;
        s.law = FrictionLaw::Sqrt;
        s.law_eps = eps;
        double t = 0, worst = 0;
        bool ok = true;
        std::vector<double> errs, rms;
        std::size_t at = 0;
        for (std::size_t n = 0; n < sample.size(); ++n) {
            const RunResult r = twist_run(sc, sample[n], s, 1e-10, 1e-8, 200'000'000);
            t += r.seconds;
            rms.push_back(1e3 * r.seconds);
            ok = ok && r.ok;
            if (!r.ok) continue;
            errs.push_back(distance(sc, Vec3(r.value[0], r.value[1], r.value[2]), ref[n]));
            if (errs.back() > worst) {
                worst = errs.back();
                at = n;
            }
        }
        std::sort(errs.begin(), errs.end());
        std::sort(rms.begin(), rms.end());
        std::printf(
            "  regularised eps %.0e v_ref:   %8.2f ms per configuration (median %.2f), error median %.1e, largest %.1e at "
            "(%.4f, %.4f, %.3f)%s\n",
            eps, 1e3 * t / sample.size(), rms[rms.size() / 2], errs.empty() ? 0.0 : errs[errs.size() / 2], worst, sample[at][0],
            sample[at][1], sample[at][2], ok ? "" : " (some runs failed)");
        std::printf("                                 %.0fx the engine's time in all, %.0fx at the median\n", t / t_engine,
                    rms[rms.size() / 2] / ms[ms.size() / 2]);
        if (ok && worst <= 1e-6 && chosen_eps == 0) {
            chosen_eps = eps;
            chosen_time = t;
        }
    }
    if (chosen_eps > 0)
        std::printf(
            "  at 1e-6 v_ref: the regularised method needs eps = %.0e v_ref and is %.1fx slower than the "
            "engine (largest engine error %.1e)\n",
            chosen_eps, chosen_time / t_engine, err_engine.back());
    else
        std::printf("  no eps tried reaches 1e-6 v_ref on the whole sample\n");
}

}   // namespace

int main() {
    std::printf("machine: %s\n", machine_description().c_str());

    fields_timing();
    fig6_costs();
    peers_sticking();
    against_regularised();
    return 0;
}
