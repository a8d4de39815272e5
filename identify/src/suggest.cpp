// Which motion to film (suggest.hpp): candidate plate motions weighed by the information the planned
// tracks would carry, through the fit's own Jacobian and Schur complement (internal.hpp).
#include "plate/suggest.hpp"

#include "internal.hpp"

#include "plate/peaks.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"
#include "plate/tasks.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace plate {
namespace {

// The nominal part's mean static coefficient (its kinetic one where no static is given).
double mean_static(const Part& p) {
    const Vec3 mus = p.mu_static ? *p.mu_static : p.mu;
    return p.point ? mus[0] : mus.mean();
}

// The contacts' largest horizontal distance from the centre of mass [m] (a point part: 0).
double reach(const Part& p) {
    double r = 0;
    if (!p.point)
        for (const Vec3& c : p.c) r = std::max(r, std::hypot(c.x(), c.y()));
    return r;
}

// One set of the tracks' starts at rest: x, y in +-box, theta any; drawn in the same order for every
// candidate.
std::vector<Vec3> planned_starts(const SuggestOptions& o, std::uint64_t seed) {
    Rng rng(seed);
    std::vector<Vec3> q0;
    for (int k = 0; k < o.tracks; ++k) {
        const double x = rng.uniform(-o.start_box, o.start_box), y = rng.uniform(-o.start_box, o.start_box);
        q0.emplace_back(x, y, rng.uniform(-kPi, kPi));
    }
    return q0;
}

// One planned track at the nominal parameters: its residual rows (zero: no noise) and Jacobians.
struct PlannedTrack {
    bool ok = false;
    double held = 0;   // the contacts' mean time at zero slip [s]
    double time = 0;   // simulated: up to the last frame's state time [s]
    Eigen::MatrixXd Jx, Jq;
};

PlannedTrack plan_track(const Scene& s, const Camera& camera, const SuggestOptions& o, const identify_detail::Layout& layout,
                        const std::vector<double>& x, const Vec3& q0) {
    PlannedTrack p;
    Camera clean = camera;
    clean.noise_xy_mm = clean.noise_theta_mrad = clean.drop = 0;
    IntegrationOptions opt;
    opt.rtol = o.fit.rtol;
    Trajectory exact;
    Track tr = observe(s, clean, o.fit.level, q0, Vec3::Zero(), o.duration, opt, &exact);
    if (exact.stop.reason != StopReason::None || static_cast<int>(tr.t.size()) < kMinTrackFrames) return p;
    tr.camera = camera;   // the residuals' scale: the camera's noise sds
    tr.camera.drop = 0;
    const int nc = s.part.contacts();
    for (int i = 0; i < nc; ++i) p.held += exact.held_time[static_cast<std::size_t>(i)] / nc;
    p.time = exact.samples.empty() ? 0.0 : exact.samples.back().t;
    std::vector<double> q0v = {q0.x() * 1e3, q0.y() * 1e3, q0.z()};
    q0v.resize(s.part.point ? 2 : 3);
    Eigen::VectorXd r;
    p.ok = identify_detail::track_jacobian(s, layout, tr, 0, o.fit, x, q0v, r, p.Jx, p.Jq);
    return p;
}


}   // namespace

void SuggestOptions::validate() const {
    auto bad = [](const std::string& what) { throw std::invalid_argument("suggest: " + what); };
    fit.validate();
    if (!(lin_limit > 0 && lin_limit <= 1e4)) bad("lin_limit: in (0, 1e4] m/s^2");
    if (!(ang_limit > 0 && ang_limit <= 1e6)) bad("ang_limit: in (0, 1e6] rad/s^2");
    if (tracks < 1 || tracks > 1000) bad("tracks: from 1 to 1000");
    if (start_sets < 1 || start_sets > 100) bad("start_sets: from 1 to 100");
    if (!(duration > 0 && duration <= 1e4)) bad("duration: in (0, 1e4] s");
    if (!(start_box >= 0 && start_box <= 1)) bad("start_box: in [0, 1] m");
    if (levels.empty() || levels.size() > 100) bad("levels: from 1 to 100 of them");
    for (double l : levels)
        if (!(l > 0 && l <= 100)) bad("levels: each in (0, 100] (units of mu_s g)");
    if (period_factors.empty() || period_factors.size() > 100) bad("period_factors: from 1 to 100 of them");
    for (double f : period_factors)
        if (!(f >= 0.01 && f <= 100)) bad("period_factors: each in [0.01, 100] (units of the scene's period)");
}

std::vector<MotionCandidate> candidate_motions(const Scene& scene, const SuggestOptions& o) {
    o.validate();
    const double a_s = mean_static(scene.part) * scene.g, r = reach(scene.part);
    std::vector<MotionCandidate> out;
    const char* shapes[4] = {"x+2x", "x+2x+2y", "x+2x+rz", "x+2x+2y+rz"};
    for (double factor : o.period_factors)
        for (int k = 0; k < (r > 0 ? 4 : 2); ++k)
            for (double level : o.levels) {
                MotionCandidate c;
                std::ostringstream label;
                label << shapes[k] << " @ " << level << " mu_s g";
                if (factor != 1) label << ", T = " << factor * scene.plate.T << " s";
                c.label = label.str();
                c.motion.T = factor * scene.plate.T;
                c.motion.harmonics.push_back(Harmonic{Axis::x, 1, 1, 0});
                c.motion.harmonics.push_back(Harmonic{Axis::x, 2, 1.0 / 3, 0});
                if (k == 1 || k == 3) c.motion.harmonics.push_back(Harmonic{Axis::y, 2, 1.0 / 3, kPi / 2});
                const double A = level * a_s, scale = A / horizontal_peak(c.motion);
                for (Harmonic& h : c.motion.harmonics) h.amp *= scale;
                // yaw: the contacts' tangential acceleration from it half the drive's peak, a quarter period
                // after the drive
                if (k >= 2) c.motion.harmonics.push_back(Harmonic{Axis::rz, 1, 0.5 * A / r, kPi / 2});
                out.push_back(c);
            }
    return out;
}

void weigh_motion(const Scene& scene, const Camera& camera, const SuggestOptions& o, MotionCandidate& c) {
    using namespace identify_detail;
    const auto t0 = std::chrono::steady_clock::now();
    o.validate();
    camera.validate();
    const Layout layout(scene, o.fit.params);
    if (!(camera.noise_xy_mm > 0) || (!scene.part.point && !(camera.noise_theta_mrad > 0)))
        throw InputError(camera.source +
                         ": the camera has no noise: the information weighs each frame by the noise's sd (give it)");
    c.predicted.clear();   // (a candidate weighed again starts afresh)
    c.information.resize(0, 0);
    c.min_eigenvalue = c.stick_fraction = 0;
    c.worst_set = 0;
    c.set_min_eigenvalues.clear();
    c.simulated = false;
    c.peaks = axis_peaks(c.motion);
    c.within_limits = c.peaks.head<3>().maxCoeff() <= o.lin_limit && c.peaks.tail<3>().maxCoeff() <= o.ang_limit;
    if (!c.within_limits) return;
    Scene s = scene;
    s.plate = c.motion;
    const std::vector<double> x = layout.internal(layout.scene_values());
    const int sets = o.start_sets, nt = o.tracks, n = layout.size(), d = scene.part.point ? 2 : 3;
    std::vector<std::vector<Vec3>> q0;
    for (int k = 0; k < sets; ++k) q0.push_back(planned_starts(o, o.seed + static_cast<std::uint64_t>(k)));
    std::vector<PlannedTrack> planned(static_cast<std::size_t>(sets) * nt);
    thread_tasks(std::max(1, std::min(o.fit.threads, sets * nt)))(
        sets * nt,
        [&](int i) {
            planned[i] = plan_track(s, camera, o, layout, x, q0[i / nt][i % nt]);
            return std::string();
        },
        [](int, const std::string&) {});

    c.simulated = true;
    double held = 0, time = 0;
    for (const PlannedTrack& p : planned) {
        c.simulated = c.simulated && p.ok;
        held += p.held;
        time += p.time;
    }
    c.stick_fraction = time > 0 ? held / time : 0.0;
    if (!c.simulated) return;
    Eigen::MatrixXd worst;
    for (int k = 0; k < sets; ++k) {
        int rows = 0;
        for (int t = 0; t < nt; ++t) rows += static_cast<int>(planned[k * nt + t].Jx.rows());
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, n + d * nt);
        for (int t = 0, row = 0; t < nt; ++t) {
            const PlannedTrack& p = planned[k * nt + t];
            const int m = static_cast<int>(p.Jx.rows());
            J.block(row, 0, m, n) = p.Jx;
            J.block(row, n + d * t, m, d) = p.Jq;
            row += m;
        }
        const Eigen::MatrixXd info = scaled_information(layout, o.fit, J, d * nt);
        const double eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(info, Eigen::EigenvaluesOnly).eigenvalues()[0];
        c.set_min_eigenvalues.push_back(eig);
        if (k == 0 || eig < c.min_eigenvalue) {
            c.min_eigenvalue = eig;
            c.information = info;
            c.worst_set = k;
            worst = J;
        }
    }
    IdentifySummary judged;
    judge(layout, o.fit, x, worst, d * nt, judged);
    c.predicted = judged.params;
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

SuggestSummary suggest_motion(const Scene& scene, const Camera& camera, const SuggestOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    SuggestSummary s;
    s.candidates = candidate_motions(scene, o);
    for (int k = 0; k < static_cast<int>(s.candidates.size()); ++k) {
        MotionCandidate& c = s.candidates[k];
        weigh_motion(scene, camera, o, c);
        if (c.within_limits && c.simulated && (s.best < 0 || c.min_eigenvalue > s.candidates[s.best].min_eigenvalue)) s.best = k;
    }
    s.suggested = scene;
    if (s.best >= 0) {
        s.suggested.plate = s.candidates[s.best].motion;
        s.suggested.name = scene.name + "_suggested";
    }
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

nlohmann::json suggest_json(const SuggestSummary& s, const SuggestOptions& o) {
    using json = nlohmann::json;
    const auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    json cands = json::array();
    for (const MotionCandidate& c : s.candidates) {
        json h = json::array();
        for (const Harmonic& m : c.motion.harmonics)
            h.push_back({{"axis", axis_name(m.axis)}, {"n", m.n}, {"amp", m.amp}, {"phase", m.phase}});
        json peaks = json::object();
        for (int a = 0; a < 6; ++a) peaks[axis_name(static_cast<Axis>(a))] = c.peaks[a];
        json j{{"label", c.label}, {"harmonics", h}, {"peaks", peaks}, {"within_limits", c.within_limits}};
        if (c.within_limits) {
            j["simulated"] = c.simulated;
            j["stick_fraction"] = c.stick_fraction;
            j["min_eigenvalue"] = c.min_eigenvalue;
            j["worst_set"] = c.worst_set;
            j["set_min_eigenvalues"] = c.set_min_eigenvalues;
            json pred = json::array();
            for (const FittedParameter& p : c.predicted)
                pred.push_back({{"name", p.name}, {"unit", p.unit}, {"nominal", p.estimate}, {"sd", num(p.sd)}});
            j["predicted"] = pred;
            j["seconds"] = c.seconds;
        }
        cands.push_back(j);
    }
    json out{{"params", o.fit.params},
             {"limits", {{"lin_m_s2", o.lin_limit}, {"ang_rad_s2", o.ang_limit}}},
             {"tracks_planned", o.tracks},
             {"duration_s", o.duration},
             {"seed", o.seed},
             {"start_sets", o.start_sets},
             {"period_factors", o.period_factors},
             {"criterion", "largest smallest eigenvalue of the range-scaled information (E-optimal), of the worst set of starts"},
             {"candidates", cands},
             {"seconds", s.seconds}};
    out["best"] = s.best >= 0 ? json(s.candidates[s.best].label) : json(nullptr);
    if (s.best >= 0) out["suggested_scene"] = scene_to_json(s.suggested);
    return out;
}

}   // namespace plate
