#include "plate/output.hpp"
#include "plate/progress.hpp"

#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdarg>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace plate {
namespace {

using nlohmann::json;

json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json vec(const Vec3& v, int n) {
    json a = json::array();
    for (int i = 0; i < n; ++i) a.push_back(num(v[i]));
    return a;
}

json stick_fractions(const std::array<double, 3>& f, int n) {
    json a = json::array();
    for (int i = 0; i < n; ++i) a.push_back(num(f[i]));
    return a;
}

json eig(const Eigen::Vector3cd& e, int n) {
    json a = json::array();
    for (int i = 0; i < n; ++i) a.push_back({num(e[i].real()), num(e[i].imag())});
    return a;
}

}   // namespace

json to_json(const Scene& sc, const Vec3& q, const LimitCycleSummary& lc) {
    const int d = sc.part.point ? 2 : 3;
    json j;
    j["scene"] = sc.name;
    j["at"] = vec(q, d);
    j["twist"] = vec(lc.twist, d);
    j["min_normal_force"] = num(lc.min_normal_force);
    j["converged"] = lc.converged;
    j["periods"] = lc.periods;
    j["residual"] = num(lc.residual);
    j["error_estimate"] = num(lc.error_estimate);
    j["contraction_per_period"] = num(lc.contraction);
    j["contact_lost"] = lc.contact_lost();
    // Stick-slip over the cycle's last period (modes.hpp).
    j["stick_fraction"] = stick_fractions(lc.stick_fraction, sc.part.contacts());
    json modes = json::array();
    if (lc.converged) {
        modes.push_back({{"t", 0.0}, {"mode", mode_name(lc.start_mode)}});
        for (const ModeEvent& e : lc.mode_events) modes.push_back({{"t", num(e.t)}, {"mode", mode_name(e.to)}});
    }
    j["mode_sequence"] = modes;
    j["stuck_all_period"] = lc.stuck_all_period();
    if (lc.stuck_all_period())
        j["stuck_note"] =
            "the part rides the plate all period long (static friction holds it): the asymptotic twist is exactly zero";
    j["stop"] = stop_name(lc.stop.reason);
    if (lc.stop.reason != StopReason::None) {
        j["stop_message"] = lc.stop.describe();
        j["stop_time"] = num(lc.stop.t);
        if (lc.stop.contact >= 0) j["stop_contact"] = lc.stop.contact + 1;
    }
    j["cycle_start_twist"] = vec(lc.qd_start, d);
    j["slip_reversals"] = lc.stats.slip_reversals;
    j["restarts"] = lc.restarts;
    if (!lc.note.empty()) j["note"] = lc.note;
    json ts = json::array();
    for (const auto& e : lc.transient_stops) ts.push_back(e.describe());
    j["transient_stops"] = ts;
    j["rhs_evaluations"] = lc.stats.rhs_evals;
    j["units"] = sc.part.point ? "m/s" : "m/s, m/s, rad/s";
    return j;
}

json to_json(const Scene& sc, const Field& f) {
    const int d = f.point_part ? 2 : 3;
    json j;
    j["scene"] = sc.name;
    j["kind"] = f.point_part ? "asymptotic velocity field" : "asymptotic twist field";
    j["grid"] = {{"nx", f.grid.nx},
                 {"ny", f.grid.ny},
                 {"ntheta", f.point_part ? 1 : f.grid.nth},
                 {"x", {f.grid.x0, f.grid.x1}},
                 {"y", {f.grid.y0, f.grid.y1}},
                 {"theta0", f.grid.th0}};
    j["seconds"] = f.seconds;
    j["threads"] = f.threads;
    j["rhs_evaluations"] = f.rhs_evals;
    json pts = json::array();
    for (const auto& p : f.points) {
        pts.push_back({{"at", vec(p.q, d)},
                       {"twist", vec(p.twist, d)},
                       {"converged", p.converged},
                       {"periods", p.periods},
                       {"residual", num(p.residual)},
                       {"min_normal_force", num(p.min_normal_force)},
                       {"stop", stop_name(p.stop)},
                       {"stick_fraction", stick_fractions(p.stick_fraction, d == 2 ? 1 : 3)}});
    }
    j["points"] = pts;
    j["units"] = {{"grid", {{"x", "m"}, {"y", "m"}, {"theta0", "rad"}}},
                  {"at", d == 2 ? json{"m", "m"} : json{"m", "m", "rad"}},
                  {"twist", d == 2 ? json{"m/s", "m/s"} : json{"m/s", "m/s", "rad/s"}},
                  {"residual", "1 (relative to v_ref)"},
                  {"min_normal_force", "N"},
                  {"stick_fraction", "period"},
                  {"seconds", "s (wall clock)"}};
    return j;
}

json to_json(const Scene& sc, const FixedPoints& fp) {
    const int d = sc.part.point ? 2 : 3;
    json j;
    j["scene"] = sc.name;
    json pts = json::array();
    for (const auto& p : fp.points)
        pts.push_back({{"at", vec(p.q, d)},
                       {"stability", stability_name(p.stability)},
                       {"eigenvalues", eig(p.eigenvalues, d)},
                       {"eigen_error", num(p.eigen_error)},
                       {"residual", num(p.residual)}});
    json lines = json::array();
    for (const auto& l : fp.lines) {
        json ps = json::array();
        for (const auto& q : l.points) ps.push_back(vec(q, d));
        lines.push_back({{"stability", stability_name(l.stability)},
                         {"direction", vec(l.direction, d)},
                         {"from", vec(l.points.front(), d)},
                         {"to", vec(l.points.back(), d)},
                         {"length", num(l.length)},
                         {"eigenvalues", eig(l.eigenvalues, d)},
                         {"eigen_error", num(l.eigen_error)},
                         {"points", ps}});
    }
    json regions = json::array();
    for (const auto& r : fp.stuck_regions) {
        json one = {{"x", {num(r.lo[0]), num(r.hi[0])}},
                    {"y", {num(r.lo[1]), num(r.hi[1])}},
                    {"grid_points", r.grid_points},
                    {"touches_edge", r.touches_edge}};
        if (d == 3) {
            one["theta"] = {num(r.lo[2]), num(r.hi[2])};
            one["all_theta"] = r.all_theta;
        }
        regions.push_back(one);
    }
    json rotating = json::array();
    for (const auto& r : fp.rotating)
        rotating.push_back({{"at", vec(r.q, 2)},
                            {"theta_section", num(r.q[2])},
                            {"rate", num(r.rate)},
                            {"period", num(r.period)},
                            {"stability", stability_name(r.stability)},
                            {"multipliers", eig(Eigen::Vector3cd(r.multipliers[0], r.multipliers[1], 0), 2)},
                            {"residual", num(r.residual)},
                            {"wobble", num(r.wobble)},
                            {"centre", {num(r.centre[0]), num(r.centre[1])}},
                            {"radius", num(r.radius)},
                            {"pivot", {num(r.pivot[0]), num(r.pivot[1])}}});
    j["points"] = pts;
    j["lines"] = lines;
    j["candidate_cells"] = fp.candidates;
    j["cells"] = fp.cells;
    j["undefined_cells"] = fp.undefined_cells;     // skipped: a corner has no cycle
    j["unsearched_cells"] = fp.unsearched_cells;   // left when the evaluation budget was spent
    j["stuck_cells"] = fp.stuck_cells;             // skipped: a corner is in a stuck region
    j["stuck_regions"] = regions;
    j["rotating_attractors"] = rotating;
    j["near_zero_cells"] = fp.near_zero_cells;   // no sign change at the corners, field near zero: searched
    j["near_zero_unsearched"] = fp.near_zero_unsearched;
    j["coarse_zeros"] = fp.coarse_zeros;           // zeros found only from such cells
    j["unresolved_cells"] = fp.unresolved_cells;   // candidates whose centre their corners do not predict
    j["grid_too_coarse"] = fp.suggested_grid > 0;
    if (fp.suggested_grid > 0) j["suggested_grid"] = fp.suggested_grid;
    j["summary"] = fixed_points_sentence(fp);
    j["field_evaluations"] = fp.evaluations;
    j["rhs_evaluations"] = fp.rhs_evaluations;
    j["units"] = {
        {"at", d == 2 ? json{"m", "m"} : json{"m", "m", "rad"}},
        {"eigenvalues", "1/s (real, imaginary)"},
        {"eigen_error", "1/s"},
        {"residual", "m/s (|xi_a|, the angular part times rho)"},
        {"length", "m (in s_x, s_y, rho theta)"},
        {"stuck_regions", "x, y: m; theta: rad"},
        {"rotating_attractors", "at, centre, pivot: m; theta_section: rad; rate: rad/s; period: s; residual, wobble, radius: m"}};
    return j;
}

std::string shortest(double x) {
    if (!std::isfinite(x)) return std::string();
    char buf[32];
#if defined(__EMSCRIPTEN__)
    // (Emscripten's libc++ has no floating-point to_chars: the fewest significant digits that read
    // back to x, which are to_chars' digits, in printf's %g form)
    for (int digits = 1;; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, x);
        if (digits >= 17 || std::strtod(buf, nullptr) == x) return std::string(buf);
    }
#else
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
#endif
}

void write_field_csv(std::ostream& out, const Field& f) {
    // An undefined twist (no cycle there: converged = 0, stop says why) is left empty, not "nan". The
    // residual is the cycle's last fixed-point step relative to v_ref (limit_cycle.hpp).
    if (f.point_part)
        out << "s_x [m],s_y [m],v_x [m/s],v_y [m/s],converged,periods,residual [1],min_normal_force [N],stop,"
               "stick_1 [period]\n";
    else
        out << "s_x [m],s_y [m],theta [rad],v_x [m/s],v_y [m/s],omega [rad/s],converged,periods,residual [1],"
               "min_normal_force [N],stop,stick_1 [period],stick_2 [period],stick_3 [period]\n";
    for (const auto& p : f.points) {
        out << shortest(p.q[0]) << ',' << shortest(p.q[1]) << ',';
        if (!f.point_part) out << shortest(p.q[2]) << ',';
        out << shortest(p.twist[0]) << ',' << shortest(p.twist[1]) << ',';
        if (!f.point_part) out << shortest(p.twist[2]) << ',';
        out << (p.converged ? 1 : 0) << ',' << p.periods << ',' << shortest(p.residual) << ',' << shortest(p.min_normal_force)
            << ',' << stop_name(p.stop);
        for (int i = 0; i < (f.point_part ? 1 : 3); ++i) out << ',' << shortest(p.stick_fraction[i]);
        out << '\n';
    }
}

void write_trajectory_csv(std::ostream& out, const Trajectory& tr, bool point_part) {
    // A quantity the dynamics does not define (the normal forces of a field integral curve) is left
    // empty, not "nan".
    if (point_part)
        out << "t [s],s_x [m],s_y [m],s_x_dot [m/s],s_y_dot [m/s],N1 [N],mode\n";
    else
        out << "t [s],s_x [m],s_y [m],theta [rad],s_x_dot [m/s],s_y_dot [m/s],theta_dot [rad/s],N1 [N],N2 [N],N3 [N],"
               "mode\n";
    for (const auto& s : tr.samples) {
        out << shortest(s.t) << ',' << shortest(s.q[0]) << ',' << shortest(s.q[1]) << ',';
        if (!point_part) out << shortest(s.q[2]) << ',';
        out << shortest(s.qd[0]) << ',' << shortest(s.qd[1]) << ',';
        if (!point_part)
            out << shortest(s.qd[2]) << ',' << shortest(s.n[0]) << ',' << shortest(s.n[1]) << ',' << shortest(s.n[2]);
        else
            out << shortest(s.n[0]);
        out << ',' << mode_name(s.mode) << '\n';
    }
}

std::string fnv1a_hex(const std::string& text) {
    std::uint64_t h = 1469598103934665603ULL;
    for (unsigned char ch : text) {
        h ^= ch;
        h *= 1099511628211ULL;
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

bool progress_wanted() {
    static const bool wanted = [] {
        if (const char* e = std::getenv("PLATE_PROGRESS")) return std::string(e) != "0";
        return ::isatty(2) == 1;
    }();
    return wanted;
}

void progress_line(const char* format, ...) {
    if (!progress_wanted()) return;
    va_list args;
    va_start(args, format);
    std::vfprintf(stderr, format, args);
    va_end(args);
}

void ProgressPrinter::operator()(int done, int total) {
    if (to == nullptr || (to == &std::cerr && !progress_wanted())) return;
    const auto now = std::chrono::steady_clock::now();
    const double el = std::chrono::duration<double>(now - start).count();
    if ((el > 1.5 && std::chrono::duration<double>(now - last).count() > every) || (shown && done == total)) {
        std::ostringstream s;
        s << what << ": " << done << "/" << total << " (" << std::fixed << std::setprecision(1) << el << " s";
        if (done > 0 && done < total) s << ", about " << seconds_left(done, total, el) << " s left";
        s << ")\n";
        *to << s.str() << std::flush;
        last = now;
        shown = true;
    }
}

std::string machine_description() {
    std::ifstream in("/proc/cpuinfo");
    std::string line, cpu = "unknown CPU";
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            cpu = line.substr(line.find(':') + 2);
            break;
        }
    return cpu + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

namespace {
// The temporary of the write in progress, for the interrupt handler (one at a time: the program's
// outputs are written from its main thread).
char g_tmp[4096];
volatile std::sig_atomic_t g_has_tmp = 0;

extern "C" void remove_tmp_and_die(int sig) {
    if (g_has_tmp) ::unlink(g_tmp);
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}
}   // namespace

void install_interrupt_cleanup() {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, remove_tmp_and_die);
}

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write, std::ostream& standard_output) {
    if (path == "-") {
        write(standard_output);
        standard_output.flush();
        return;
    }
    const std::string tmp = path + ".tmp";
    const bool tracked = tmp.size() < sizeof g_tmp;
    if (tracked) {
        std::memcpy(g_tmp, tmp.c_str(), tmp.size() + 1);
        g_has_tmp = 1;
    }
    struct Untrack {
        bool on;
        ~Untrack() {
            if (on) g_has_tmp = 0;
        }
    } untrack{tracked};
    try {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(path + ": cannot open for writing");
        write(out);
        out.close();
        if (!out) throw std::runtime_error(path + ": write failed");
        // Test hook (tests/test_cli.cpp, [atomic]): hold the complete temporary before the rename,
        // so that a test can interrupt the program exactly there.
        if (const char* pause = std::getenv("PLATE_TEST_PAUSE_BEFORE_RENAME")) {
            std::fprintf(stderr, "paused before rename: %s\n", path.c_str());
            std::fflush(stderr);
            std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(pause)));
        }
        if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error(path + ": cannot rename into place");
    } catch (...) {
        std::remove(tmp.c_str());
        throw;
    }
}

}   // namespace plate
