// The peers study (issue 19): the same four questions to Bullet, ODE, MuJoCo and `plate`, against
// converged references, one run, one machine. Writes a JSON file that bench/peers/study.py charts
// into the report's speed-accuracy section (a benchmark, not a test).
//
//   bench_peers --out FILE [--quick] [--source DIR]
//
// (a) fig4's full-dynamics trajectory from rest at (0.04, -0.04, 1.0), 20 s (quick: 5 s): final
//     configuration error (relative to rho, rho, 1 rad) vs CPU time, engines over a ladder of steps,
//     plate's event-driven integrator over tolerances. Reference: plate at rtol 1e-12.
// (b) fig4's asymptotic twist at (0.02, -0.01, 0.5): an engine simulates k periods from rest and
//     averages over the next, (q((k+1)T) - q(kT)) / T; the part moves meanwhile, so this estimate has
//     a method error besides the step error, shown by plate's own full dynamics under the same
//     protocol. plate: the limit cycle over tolerances. Reference: the cycle at tol 1e-11.
// (c) fig4's 343-configuration field, each engine configuration estimated as in (b); plate's field
//     on one thread over tolerances. Error: the largest over the field.
// (d) fig6's sticking configurations (stick fraction > 0 in plate's field), as in (c).
#include "../machine.hpp"
#include "peers.hpp"

#include "plate/field.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "plate/study.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

using namespace plate;
using nlohmann::json;

namespace {

// CPU time of this thread since t0 (every system runs on one thread: plate's field too).
double since(double t0) { return peers::cpu_now() - t0; }

void say(const std::string& s) { std::cerr << "bench_peers: " << s << std::endl; }

std::string sci(double x) {   // 1e-05 -> "1e-05", 0.00025 -> "2.5e-04"
    char b[32];
    std::snprintf(b, sizeof b, "%.1e", x);
    std::string s = b;
    const auto dot = s.find(".0e");
    if (dot != std::string::npos) s.erase(dot, 2);
    return s;
}

json point(const std::string& system, const std::string& setting, double cpu, double error, const std::string& failure = "") {
    json p = {{"system", system}, {"setting", setting}, {"cpu", cpu}, {"error", error}};
    if (!failure.empty()) p["failure"] = failure;
    return p;
}

std::vector<double> flat(const std::vector<Vec3>& q) {
    std::vector<double> v;
    for (const Vec3& x : q) v.insert(v.end(), {x[0], x[1], x[2]});
    return v;
}

// The twist estimated from a run sampled every period: after k periods, averaged over the next.
Vec3 twist_after(const std::vector<Vec3>& q, int k, double T) { return (q[k + 1] - q[k]) / T; }

double twist_err(const Scene& sc, const Vec3& a, const Vec3& b) {
    return twist_error(sc, {a[0], a[1], a[2]}, {b[0], b[1], b[2]});
}

// plate's limit-cycle settings (cycle tol, rtol) for (b)-(d): rtol = tol / 10, and below 1e-3 a loose
// cycle tolerance on an rtol of 1e-4 (a coarser rtol makes the period map too noisy for the
// shooting's test: fig4's field at tol 1e-2, rtol 1e-3 took 0.34 s; at rtol 1e-4 its starts predicted
// from their neighbours take 1.05 periods each, largest error 2.9e-4 m/s).
const std::vector<std::pair<double, double>> kCycleSettings = {{1e-2, 1e-4}, {1e-3, 1e-4}, {1e-4, 1e-5}, {1e-5, 1e-6},
                                                               {1e-6, 1e-7}, {1e-7, 1e-8}, {1e-8, 1e-9}, {1e-9, 1e-10}};
std::string cycle_setting(double tol, double rtol) { return "tol " + sci(tol) + ", rtol " + sci(rtol); }

// (a) the trajectory.
void question_a(json& j, const Scene& fig4, const std::vector<peers::Engine>& engines, const std::vector<double>& dts,
                bool quick) {
    const Vec3 q0(0.04, -0.04, 1.0);
    const double dur = quick ? 5 : 20, dt_s = 0.05;
    say("(a) reference");
    IntegrationOptions io;
    io.rtol = 1e-12;
    const Trajectory ref = simulate(fig4, Dynamics::Full, q0, Vec3::Zero(), dur, dt_s, io);
    io.rtol = 1e-11;
    const Trajectory ref2 = simulate(fig4, Dynamics::Full, q0, Vec3::Zero(), dur, dt_s, io);
    auto qs = [](const Trajectory& tr) {
        std::vector<Vec3> q;
        for (const auto& s : tr.samples) q.push_back(s.q);
        return q;
    };
    const std::vector<double> R = flat(qs(ref));
    double fe = 0, me = 0;
    path_error(fig4, flat(qs(ref2)), R, fe, me);
    json pts = json::array();
    for (double rtol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
        io.rtol = rtol;
        const double t0 = peers::cpu_now();
        const Trajectory tr = simulate(fig4, Dynamics::Full, q0, Vec3::Zero(), dur, dt_s, io);
        const double cpu = since(t0);
        double f = 0, m = 0;
        path_error(fig4, flat(qs(tr)), R, f, m);
        pts.push_back(point("plate", "rtol " + sci(rtol), cpu, f, tr.stop.reason == StopReason::None ? "" : tr.stop.describe()));
    }
    // plate's stroboscopic averaging of the same full dynamics (simulate.hpp), over its macro tolerance.
    io.rtol = 1e-5;
    for (double mtol : {3e-2, 1e-2, 3e-3, 1e-3}) {
        AveragingOptions avg;
        avg.macro_tol = mtol;
        const double t0 = peers::cpu_now();
        const Trajectory tr = simulate_averaged(fig4, q0, Vec3::Zero(), dur, dt_s, io, avg);
        const double cpu = since(t0);
        double f = 0, m = 0;
        path_error(fig4, flat(qs(tr)), R, f, m);
        pts.push_back(point("plate", "averaged, macro tol " + sci(mtol) + ", rtol 1e-05", cpu, f,
                            tr.stop.reason == StopReason::None ? "" : tr.stop.describe()));
    }
    for (const auto& e : engines)
        for (double dt : dts) {
            peers::PeerOptions o;
            o.dt = dt;
            const peers::PeerRun r = e.run(fig4, q0, dur, dt_s, o);
            double f = INFINITY, m = INFINITY;
            if (r.failure.empty()) path_error(fig4, flat(r.q), R, f, m);
            pts.push_back(point(r.engine, "dt " + sci(dt), r.cpu_seconds, f, r.failure));
            pts.back()["max_lift"] = r.max_lift;
            say("(a) " + r.engine + " dt " + std::to_string(dt) + ": error " + std::to_string(f) + ", cpu " +
                std::to_string(r.cpu_seconds));
        }
    j["a"] = {{"question", "fig4: full dynamics from rest at (0.04, -0.04, 1.0) for " + std::to_string(static_cast<int>(dur)) +
                               " s, final configuration"},
              {"reference_error", fe},
              {"points", pts}};
}

// (b) one asymptotic twist.
void question_b(json& j, const Scene& fig4, const std::vector<peers::Engine>& engines, const std::vector<double>& dts) {
    const std::vector<int> ks = {2, 5, 10, 20};
    const Vec3 q0(0.02, -0.01, 0.5);
    const double T = fig4.plate.T;
    LimitCycleOptions tight;
    tight.tol = 1e-11;
    tight.integration.rtol = 1e-12;
    const LimitCycleSummary ref = limit_cycle(fig4, q0, tight);
    tight.tol = 1e-10;
    tight.integration.rtol = 1e-11;
    const double ref_err = twist_err(fig4, limit_cycle(fig4, q0, tight).twist, ref.twist);
    json pts = json::array();
    for (const auto& [tol, rtol] : kCycleSettings) {
        LimitCycleOptions o;
        o.tol = tol;
        o.integration.rtol = rtol;
        const double t0 = peers::cpu_now();
        const LimitCycleSummary lc = limit_cycle(fig4, q0, o);
        const double cpu = since(t0);
        pts.push_back(point("plate", cycle_setting(tol, rtol), cpu, twist_err(fig4, lc.twist, ref.twist),
                            lc.converged ? "" : "not converged"));
    }
    // The method error of the protocol itself: plate's full dynamics, k periods, then one averaged.
    IntegrationOptions io;
    io.rtol = 1e-11;
    const double t0 = peers::cpu_now();
    const Trajectory full = simulate(fig4, Dynamics::Full, q0, Vec3::Zero(), (ks.back() + 1) * T, T, io);
    const double cpu_full = since(t0);
    std::vector<Vec3> fq;
    for (const auto& s : full.samples) fq.push_back(s.q);
    json protocol = json::array();
    for (int k : ks)
        if (static_cast<int>(fq.size()) > k + 1)
            protocol.push_back(point("plate full dynamics, k periods", "k " + std::to_string(k),
                                     cpu_full * (k + 1) / (ks.back() + 1), twist_err(fig4, twist_after(fq, k, T), ref.twist)));
    for (const auto& e : engines)
        for (double dt : dts) {
            peers::PeerOptions o;
            o.dt = dt;
            const peers::PeerRun r = e.run(fig4, q0, (ks.back() + 1) * T, T, o);
            for (int k : ks) {
                const bool ok = r.failure.empty() && static_cast<int>(r.q.size()) > k + 1;
                pts.push_back(point(r.engine, "dt " + sci(dt) + ", k " + std::to_string(k),
                                    r.cpu_seconds * (k + 1) / (ks.back() + 1),
                                    ok ? twist_err(fig4, twist_after(r.q, k, T), ref.twist) : INFINITY, r.failure));
            }
            say("(b) " + r.engine + " dt " + std::to_string(dt));
        }
    j["b"] = {{"question", "fig4: the asymptotic twist at (0.02, -0.01, 0.5)"},
              {"reference_error", ref_err},
              {"twist", {ref.twist[0], ref.twist[1], ref.twist[2]}},
              {"protocol_error", protocol},
              {"points", pts}};
}

// (c), (d): fields (SC's 7 x 7 x 7 field, or only its sticking configurations), under key ID.
void field_question(json& j, const Scene& sc, const std::string& id, const std::string& question, bool sticking_only,
                    const std::vector<peers::Engine>& engines, bool quick) {
    GridSpec g;   // 7 x 7 x 7 over [-0.05, 0.05]^2 x [0, 2 pi)
    FieldOptions tight;
    tight.cycle.tol = 1e-10;
    tight.cycle.integration.rtol = 1e-11;
    say("(" + id + ") reference field");
    const Field ref = compute_field(sc, g, tight);
    FieldOptions tight2 = tight;   // (what the reference is worth: against one a decade looser)
    tight2.cycle.tol = 1e-9;
    tight2.cycle.integration.rtol = 1e-10;
    const double ref_err = field_max_error(sc, compute_field(sc, g, tight2), ref);
    std::vector<int> idx;
    for (int i = 0; i < g.size(); ++i) {
        const FieldPoint& p = ref.points[i];
        const bool sticks = p.stick_fraction[0] > 0 || p.stick_fraction[1] > 0 || p.stick_fraction[2] > 0;
        if (p.converged && (!sticking_only || sticks)) idx.push_back(i);
    }
    if (sticking_only && quick && idx.size() > 8) idx.resize(8);
    json pts = json::array();
    for (const auto& [tol, rtol] : kCycleSettings) {
        LimitCycleOptions o;
        o.tol = tol;
        o.integration.rtol = rtol;
        double err = 0, cpu = 0;
        if (!sticking_only) {
            FieldOptions fo;
            fo.cycle = o;
            fo.threads = 1;
            const double t0 = peers::cpu_now();
            const Field f = compute_field(sc, g, fo);
            cpu = since(t0);
            int missing = 0;
            err = field_max_error(sc, f, ref, &missing);
            if (missing > 0) {   // (a point without a cycle fails the setting, as it does an engine's)
                err = INFINITY;
                pts.push_back(point("plate", cycle_setting(tol, rtol), cpu, err,
                                    std::to_string(missing) + " configurations without a cycle"));
                continue;
            }
        }
        std::string failure;
        if (sticking_only) {
            const double t0 = peers::cpu_now();
            for (int i : idx) {
                const LimitCycleSummary lc = limit_cycle(sc, ref.points[i].q, o);
                err = std::max(err, lc.converged ? twist_err(sc, lc.twist, ref.points[i].twist) : INFINITY);
                if (!lc.converged) {
                    const Vec3& q = ref.points[i].q;
                    failure = "no cycle at (" + std::to_string(q[0]) + ", " + std::to_string(q[1]) + ", " + std::to_string(q[2]) +
                              "): " + (lc.stop.reason != StopReason::None ? lc.stop.describe() : "not converged");
                }
            }
            cpu = since(t0);
        }
        pts.push_back(point("plate", cycle_setting(tol, rtol), cpu, err, failure));
    }
    const std::vector<std::pair<double, int>> settings =
        quick ? std::vector<std::pair<double, int>>{{2.5e-4, 5}}
              : std::vector<std::pair<double, int>>{{5e-4, 5}, {2.5e-4, 5}, {1e-4, 10}};
    for (const auto& e : engines)
        for (const auto& [dt, k] : settings) {
            peers::PeerOptions o;
            o.dt = dt;
            double err = 0, cpu = 0;
            std::string failure, name = e.name;
            for (int i : idx) {
                const peers::PeerRun r = e.run(sc, ref.points[i].q, (k + 1) * sc.plate.T, sc.plate.T, o);
                name = r.engine;
                cpu += r.cpu_seconds;
                if (!r.failure.empty() || static_cast<int>(r.q.size()) <= k + 1) {
                    failure = r.failure;
                    err = INFINITY;
                    continue;
                }
                err = std::max(err, twist_err(sc, twist_after(r.q, k, sc.plate.T), ref.points[i].twist));
            }
            pts.push_back(point(name, "dt " + sci(dt) + ", k " + std::to_string(k), cpu, err, failure));
            say("(" + id + ") " + name + " dt " + std::to_string(dt) + " k " + std::to_string(k) + ": error " +
                std::to_string(err) + ", cpu " + std::to_string(cpu));
        }
    j[id] = {{"question", question}, {"configurations", idx.size()}, {"reference_error", ref_err}, {"points", pts}};
}

}   // namespace

int main(int argc, char** argv) {
    std::string out, source = PLATE_SOURCE_DIR;
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--out" && i + 1 < argc)
            out = argv[++i];
        else if (a == "--source" && i + 1 < argc)
            source = argv[++i];
        else if (a == "--quick")
            quick = true;
        else {
            std::cerr << "usage: bench_peers --out FILE [--quick] [--source DIR]\n";
            return 2;
        }
    }
    if (out.empty()) {
        std::cerr << "bench_peers: missing --out FILE\n";
        return 2;
    }
    const Scene fig4 = load_scene(source + "/scenes/fig4.json"), fig6 = load_scene(source + "/scenes/fig6.json");
    const std::vector<peers::Engine> engines = peers::engines();
    json j;
    j["machine"] = plate::bench::machine();
    j["quick"] = quick;
    j["engines"] = json::array();
    for (const auto& e : engines) {
        const peers::PeerRun r = e.run(fig4, Vec3::Zero(), 1e-3, 1e-3, peers::PeerOptions{});
        j["engines"].push_back({{"name", r.engine}, {"settings", r.settings}});
    }
    // (steps that divide the period: samples land on whole periods)
    const std::vector<double> dts =
        quick ? std::vector<double>{1e-3, 2.5e-4, 1e-4} : std::vector<double>{1e-3, 5e-4, 2.5e-4, 1e-4, 5e-5};

    question_a(j, fig4, engines, dts, quick);
    question_b(j, fig4, engines, dts);
    field_question(j, fig4, "c", "fig4: the 343-configuration field (7 x 7 x 7), largest twist error", false, engines, quick);
    field_question(j, fig6, "d",
                   "fig6: its sticking configurations (stick fraction > 0 in the 7 x 7 x 7 field), largest twist error", true,
                   engines, quick);

    std::ofstream f(out + ".tmp");
    f << j.dump(1) << "\n";
    f.close();
    if (!f || std::rename((out + ".tmp").c_str(), out.c_str()) != 0) {
        std::cerr << "bench_peers: cannot write " << out << "\n";
        return 1;
    }
    return 0;
}
