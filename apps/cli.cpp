// plate: the command-line program (apps/main.cpp runs it). See `plate --help`.
// Exit codes: 0 success; 2 bad input (usage, scene file); 3 a simulation left the model's
// assumptions (contact lost, sticking, step collapse) -- its output up to that time is kept;
// 4 a design that failed verification (nothing written); 1 any other failure.
#include "cli.hpp"

#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/hierarchy.hpp"
#include "plate/output.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"
#include "report.hpp"
#include "theorem1.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct Io {
    std::ostream& out;
    std::ostream& err;
};

constexpr double kMaxRows = 1e7;   // rows of a trajectory CSV

// The folder with scenes/ (the report's inputs): an installed program's PREFIX/share/plate beside
// PREFIX/bin, else the source tree it was built from (relocatable: nothing else is compiled in).
std::string data_root() {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const std::filesystem::path share = exe.parent_path().parent_path() / "share" / "plate";
        if (std::filesystem::exists(share / "scenes", ec)) return share.string();
    }
    return PLATE_SOURCE_DIR;
}
constexpr long kCliCycleBudget = 2'000'000;   // right-hand sides per cycle (--max-rhs)

std::string fmt(double x) {
    std::ostringstream s;
    s.precision(3);
    s << x;
    return s.str();
}

const char* kUsage =
    "plate: sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch)\n"
    "\n"
    "usage: plate COMMAND SCENE [options]      plate COMMAND --help for its options; plate --version\n"
    "\n"
    "commands:\n"
    "  twist         asymptotic twist (36) at one configuration, as JSON\n"
    "  field         asymptotic twist field on a grid over (s_x, s_y, theta), JSON or CSV\n"
    "  fixed-points  zeros of the field, refined and classified (stable, unstable, saddle; lines)\n"
    "  simulate      U-dynamics, full-dynamics or field-integral-curve trajectory, CSV\n"
    "  random-scene  a seeded random part and plate motion (like Fig. 3), as a scene file\n"
    "  proofs        the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON\n"
    "  report        the verification report: DIR/index.html with SVG figures (gnuplot)\n"
    "  bench         the speed-accuracy study, written into the report in DIR (--full: the long campaign)\n"
    "  design        the plate motion that sends a (point) part where wanted: a sink or a transport, verified\n"
    "\n"
    "SCENE is a JSON scene file (see scenes/). Units are SI. Exit codes: 0 ok, 2 bad input,\n"
    "3 a simulation left the model (a normal force reached zero: the part would fly), 1 other failure.\n";

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Minimal option parser: --name values...; positional arguments in order.
struct Args {
    std::vector<std::string> pos;
    std::map<std::string, std::vector<std::string>> opt;
    bool help = false;

    Args(int argc, char** argv, const std::map<std::string, int>& arity) {
        for (int i = 0; i < argc; ++i) {
            std::string a = argv[i];
            if (a == "--help" || a == "-h") { help = true; continue; }
            if (a.rfind("--", 0) == 0) {
                auto it = arity.find(a);
                if (it == arity.end()) throw UsageError("unknown option " + a);
                if (opt.count(a)) throw UsageError("option " + a + " given twice");
                std::vector<std::string> vals;
                for (int k = 0; k < it->second; ++k) {
                    if (i + 1 >= argc) throw UsageError("option " + a + " expects " + std::to_string(it->second) + " value(s)");
                    vals.push_back(argv[++i]);
                }
                opt[a] = vals;
            } else {
                pos.push_back(a);
            }
        }
    }
    bool has(const std::string& k) const { return opt.count(k) > 0; }
    double num(const std::string& k, int i, double def) const {
        if (!has(k)) return def;
        return parse_num(k, opt.at(k)[i]);
    }
    static double parse_num(const std::string& k, const std::string& s) {
        char* end = nullptr;
        const double x = std::strtod(s.c_str(), &end);
        if (s.empty() || *end != '\0' || !std::isfinite(x))
            throw UsageError("option " + k + ": expected a finite number, got '" + s + "'");
        return x;
    }
    long integer(const std::string& k, long def, long lo, long hi) const {
        if (!has(k)) return def;
        const std::string& s = opt.at(k)[0];
        char* end = nullptr;
        const long x = std::strtol(s.c_str(), &end, 10);
        if (s.empty() || *end != '\0' || x < lo || x > hi)
            throw UsageError("option " + k + ": expected a whole number from " + std::to_string(lo) + " to " +
                             std::to_string(hi) + ", got '" + s + "'");
        return x;
    }
    std::string str(const std::string& k, const std::string& def) const { return has(k) ? opt.at(k)[0] : def; }
};

// The scene file; its warnings (scene_warnings: admissible, outside the intended regime) to err.
Scene scene_arg(const Args& a, Io& cio) {
    if (a.pos.size() != 1) throw UsageError("expected exactly one SCENE file");
    Scene sc = load_scene(a.pos[0]);
    for (const std::string& w : scene_warnings(sc)) cio.err << "warning: " << w << "\n";
    return sc;
}

// Reads --NAME with 3 numbers (rigid) or 2 (point part; a third is rejected).
Vec3 config_arg(const Args& a, const std::string& k, const Scene& sc, bool required, const Vec3& def = Vec3::Zero()) {
    if (!a.has(k)) {
        if (required) throw UsageError("missing " + k + (sc.part.point ? " SX SY" : " SX SY THETA"));
        return def;
    }
    const auto& v = a.opt.at(k);
    Vec3 q = Vec3::Zero();
    const std::size_t need = sc.part.point ? 2 : 3;
    std::vector<std::string> vals = v;
    if (vals.size() != need) throw UsageError(k + ": expected " + std::to_string(need) + " numbers");
    for (std::size_t i = 0; i < need; ++i) q[i] = Args::parse_num(k, vals[i]);
    return q;
}

// Options taking 2 or 3 values depending on the part are parsed from the raw argv.
std::map<std::string, int> with_config(std::map<std::string, int> m, const std::vector<std::string>& keys, int n) {
    for (const auto& k : keys) m[k] = n;
    return m;
}

// For a point part, --at/--from take two values: peek at the scene before parsing.
int config_arity(int argc, char** argv) {
    for (int i = 0; i < argc; ++i) {
        std::string s = argv[i];
        if (s.rfind("--", 0) == 0 || s == "-h") continue;
        try {
            return load_scene(s).part.point ? 2 : 3;
        } catch (const InputError&) {
            throw;
        }
    }
    return 3;
}


LimitCycleOptions cycle_opts(const Args& a) {
    LimitCycleOptions o;
    o.tol = a.num("--tol", 0, o.tol);
    o.integration.rtol = a.num("--rtol", 0, o.integration.rtol);
    o.max_periods = static_cast<int>(a.integer("--max-periods", o.max_periods, 2, 100000));
    // The command line's budget per cycle is tighter than the library's (2e7, for tight references):
    // 2e6, about 0.3 s; the shipped scenes' field cycles take at most ~6e4 at the default tolerances.
    o.max_rhs_evaluations = a.integer("--max-rhs", kCliCycleBudget, 1000, 1'000'000'000'000L);
    if (a.has("--cycle-solver")) {
        try {
            o.solver = parse_cycle_solver(a.str("--cycle-solver", ""));
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--cycle-solver: ") + e.what());
        }
    }
    if (!(o.tol > 0) || !(o.integration.rtol > 0 && o.integration.rtol < 1e-2))
        throw UsageError("--tol must be > 0 and --rtol in (0, 1e-2)");
    return o;
}

const std::map<std::string, int> kCycleOpts = {{"--tol", 1}, {"--rtol", 1}, {"--max-periods", 1}, {"--cycle-solver", 1},
                                               {"--max-rhs", 1}};
const std::map<std::string, int> kGridOpts = {{"--grid", 1}, {"--nx", 1}, {"--ny", 1}, {"--ntheta", 1}, {"--x", 2},
                                              {"--y", 2}, {"--theta0", 1}, {"--threads", 1}};

std::map<std::string, int> merge(std::map<std::string, int> a, const std::map<std::string, int>& b) {
    a.insert(b.begin(), b.end());
    return a;
}

GridSpec grid_opts(const Args& a) {
    GridSpec g;
    const int n = static_cast<int>(a.integer("--grid", 7, 1, 201));
    g.nx = static_cast<int>(a.integer("--nx", n, 1, 201));
    g.ny = static_cast<int>(a.integer("--ny", n, 1, 201));
    g.nth = static_cast<int>(a.integer("--ntheta", n, 1, 720));
    g.x0 = a.num("--x", 0, g.x0);
    g.x1 = a.num("--x", 1, g.x1);
    g.y0 = a.num("--y", 0, g.y0);
    g.y1 = a.num("--y", 1, g.y1);
    g.th0 = a.num("--theta0", 0, g.th0);
    if (!(g.x1 >= g.x0) || !(g.y1 >= g.y0)) throw UsageError("--x and --y take MIN MAX with MIN <= MAX");
    return g;
}

int cmd_twist(int argc, char** argv, Io& cio) {
    const int d = config_arity(argc, argv);
    Args a(argc, argv, merge(with_config({}, {"--at", "--from"}, d), kCycleOpts));
    if (a.help) {
        cio.out << "usage: plate twist SCENE --at SX SY THETA [--from VX VY OMEGA] [--tol X] [--rtol X]\n"
                     "                   [--max-periods N]\n"
                     "Asymptotic twist (36) of the reduced U-dynamics limit cycle at (SX, SY, THETA), starting\n"
                     "from the part twist --from (default: at rest relative to the plate). Point parts: --at SX SY.\n"
                     "--tol: accepted distance to the cycle relative to the slip-speed scale (default 1e-7);\n"
                     "--rtol: integrator tolerance (default 1e-8); --max-periods (default 400); --max-rhs: the work\n"
                     "budget of the cycle in right-hand sides (default 2e6, about 0.3 s; then stop: step_limit).\n";
        return 0;
    }
    const Scene sc = scene_arg(a, cio);
    const Vec3 q = config_arg(a, "--at", sc, true);
    const Vec3 qd = config_arg(a, "--from", sc, false);
    const LimitCycleSummary lc = limit_cycle(sc, q, cycle_opts(a), qd);
    cio.out << to_json(sc, q, lc).dump(2) << std::endl;
    return 0;
}

// Bounded work for a field (issue 18): five cycles from rest (the grid's centre and four spread
// configurations) run first; the field costs about their mean per configuration (measured on the
// shipped scenes' 9x9x9 fields: 0.2-3.4x of it; warm starts save, sticking cycles cost more), and a
// field estimated over the budget --max-work (right-hand sides, default 2e9: minutes on two cores)
// is refused with the estimate. The budget also holds while the field runs (require_within_budget).
long check_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& lo, const Args& a) {
    const long budget = a.integer("--max-work", 2'000'000'000L, 1000, 1'000'000'000'000'000L);
    const auto t0 = std::chrono::steady_clock::now();
    const double dth = 2 * kPi / 5;
    const Vec3 samples[] = {{(g.x0 + g.x1) / 2, (g.y0 + g.y1) / 2, g.th0},
                            {g.x0 + 0.25 * (g.x1 - g.x0), g.y0 + 0.25 * (g.y1 - g.y0), g.th0 + dth},
                            {g.x0 + 0.75 * (g.x1 - g.x0), g.y0 + 0.25 * (g.y1 - g.y0), g.th0 + 2 * dth},
                            {g.x0 + 0.25 * (g.x1 - g.x0), g.y0 + 0.75 * (g.y1 - g.y0), g.th0 + 3 * dth},
                            {g.x0 + 0.75 * (g.x1 - g.x0), g.y0 + 0.75 * (g.y1 - g.y0), g.th0 + 4 * dth}};
    double total = 0;
    for (const Vec3& q : samples) total += std::max<double>(limit_cycle(sc, q, lo).stats.rhs_evals, 1);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double per = total / 5, n = static_cast<double>(g.size());
    if (per * n > static_cast<double>(budget))
        throw UsageError("a " + std::to_string(g.nx) + "x" + std::to_string(g.ny) + "x" + std::to_string(g.nth) +
                         " grid would take about " + fmt(per * n) + " right-hand sides (" + fmt(per) +
                         " per configuration, the mean of five cycles run first: about " + fmt(secs / 5 * n) +
                         " s on one core here), above the budget of " + fmt(static_cast<double>(budget)) +
                         ": raise it with --max-work or use a coarser grid");
    return budget;
}

// A field whose budget ran out while it was computed (the estimate from one cycle was low): not a result.
void require_within_budget(const Field& f, long budget) {
    if (!f.budget_spent) return;
    int left = 0;
    for (const auto& p : f.points) left += p.stop == StopReason::StepLimit && p.rhs_evals == 0;
    throw std::runtime_error("the work budget of " + fmt(static_cast<double>(budget)) + " right-hand sides was spent with " +
                             std::to_string(left) + " of " + std::to_string(f.points.size()) +
                             " configurations not started (the up-front estimate was low): raise --max-work");
}

int cmd_field(int argc, char** argv, Io& cio) {
    Args a(argc, argv, merge(merge(kGridOpts, kCycleOpts), {{"--format", 1}, {"--out", 1}, {"--max-work", 1}}));
    if (a.help) {
        cio.out << "usage: plate field SCENE [--grid N] [--nx N] [--ny N] [--ntheta N] [--x MIN MAX]\n"
                     "                   [--y MIN MAX] [--theta0 T] [--format json|csv] [--out FILE]\n"
                     "                   [--threads N] [--tol X] [--rtol X] [--max-periods N]\n"
                     "Asymptotic twist field on a regular grid (default 7x7x7 over [-0.05,0.05]^2 m x [0, 2pi)),\n"
                     "theta covering a full turn. Point parts: asymptotic velocity field on (s_x, s_y).\n"
                     "Configurations run in parallel on all cores (--threads). Output to stdout or --out FILE.\n"
                     "--max-work N: the budget in right-hand sides (default 2e9); the work is estimated up front\n"
                     "from one cycle and a larger field is refused with the estimate (exit 2); a field that spends\n"
                     "it anyway stops there (exit 1, no output).\n";
        return 0;
    }
    const Scene sc = scene_arg(a, cio);
    const GridSpec g = grid_opts(a);
    const std::string format = a.str("--format", "json");
    if (format != "json" && format != "csv") throw UsageError("--format: expected json or csv");
    FieldOptions fo;
    fo.cycle = cycle_opts(a);
    fo.threads = static_cast<int>(a.integer("--threads", 0, 0, 256));
    fo.max_rhs_evaluations = check_field_work(sc, g, fo.cycle, a);
    ProgressPrinter prog{"field"};
    prog.to = &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    fo.progress = std::ref(prog);
    const Field f = compute_field(sc, g, fo);
    require_within_budget(f, fo.max_rhs_evaluations);
    write_file_atomic(a.str("--out", "-"), [&](std::ostream& out) {
        if (format == "csv") write_field_csv(out, f);
        else out << to_json(sc, f).dump(1) << "\n";
    }, cio.out);
    return 0;
}

int cmd_fixed_points(int argc, char** argv, Io& cio) {
    Args a(argc, argv, merge(merge(kGridOpts, kCycleOpts), {{"--out", 1}, {"--max-work", 1}}));
    if (a.help) {
        cio.out << "usage: plate fixed-points SCENE [grid options as for field] [--out FILE]\n"
                     "Computes the field, finds cells where every component changes sign, refines the zeros\n"
                     "by Gauss-Newton, classifies them by the Jacobian's eigenvalues (stable, unstable, saddle)\n"
                     "and reports curves of zeros as lines. JSON to stdout or --out FILE. --max-work as for field;\n"
                     "the refinement's own budget is the smaller of it and 2e7 right-hand sides.\n";
        return 0;
    }
    const Scene sc = scene_arg(a, cio);
    FieldOptions fo;
    fo.cycle = cycle_opts(a);
    fo.threads = static_cast<int>(a.integer("--threads", 0, 0, 256));
    const GridSpec g = grid_opts(a);
    fo.max_rhs_evaluations = check_field_work(sc, g, fo.cycle, a);   // (the refinement has its own budget)
    ProgressPrinter prog{"field"};
    prog.to = &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    fo.progress = std::ref(prog);
    const Field f = compute_field(sc, g, fo);
    require_within_budget(f, fo.max_rhs_evaluations);
    FixedPointOptions fpo;
    fpo.cycle = fo.cycle;
    if (a.has("--max-work")) fpo.max_rhs_evaluations = std::min(fpo.max_rhs_evaluations, a.integer("--max-work", 0, 1000, 1'000'000'000'000'000L));
    const FixedPoints fp = find_fixed_points(sc, f, fpo);
    write_file_atomic(a.str("--out", "-"), [&](std::ostream& out) { out << to_json(sc, fp).dump(2) << "\n"; }, cio.out);
    return 0;
}

int cmd_simulate(int argc, char** argv, Io& cio) {
    const int d = config_arity(argc, argv);
    Args a(argc, argv, merge(with_config({{"--dynamics", 1}, {"--time", 1}, {"--sample", 1}, {"--out", 1},
                                          {"--rtol", 1}},
                                         {"--from", "--twist"}, d),
                             {{"--tol", 1}, {"--max-periods", 1}, {"--model-tol", 1}, {"--verify", 0}, {"--max-steps", 1}}));
    if (a.help) {
        cio.out << "usage: plate simulate SCENE --dynamics full|u|field|auto --from SX SY THETA --time T\n"
                     "                      [--twist VX VY OMEGA] [--sample DT] [--out FILE] [--rtol X]\n"
                     "Trajectory from configuration --from with part twist --twist relative to the plate\n"
                     "(default: at rest). full: full dynamics (31) with the plate on SO(3); u: U-dynamics (32);\n"
                     "field: integral curve of the asymptotic twist field (RK4, 0.05 s steps).\n"
                     "auto: the cheapest of point/thin/thick part x field/u/full dynamics whose final configuration\n"
                     "is predicted within --model-tol E (default 1e-2; of rho and radians) of the scene's part\n"
                     "under full dynamics, decided up front from a few limit cycles at --from and the scene's\n"
                     "dimensionless numbers (hierarchy.hpp); --verify also runs the full model and reports the\n"
                     "measured error. The choice and its estimates go to stderr.\n"
                     "CSV with header t,s_x,s_y,theta,s_x_dot,s_y_dot,theta_dot,N1,N2,N3 every --sample\n"
                     "seconds (default T/4 of the plate period... 0.0125 s for T = 0.05), and the contact mode on the\n"
                     "step that ended there (slide, pivot1-3, stuck: stick-slip is simulated through). Exit code 3\n"
                     "when a normal force reaches zero (the part would fly): the CSV then ends at that time.\n"
                     "--max-steps N: the work budget (integrator steps; for field, RK4 steps of the curve; default\n"
                     "2e7, field 1e4). The work is estimated up front from one plate period (or one RK4 step) and a\n"
                     "run that would exceed the budget is refused with the estimate (exit 2); at most 10^7 rows.\n";
        return 0;
    }
    const Scene sc = scene_arg(a, cio);
    std::string dyn = a.str("--dynamics", "");
    if (dyn != "full" && dyn != "u" && dyn != "field" && dyn != "auto")
        throw UsageError("--dynamics: expected full, u, field or auto");
    const Vec3 q0 = config_arg(a, "--from", sc, true);
    const Vec3 qd0 = config_arg(a, "--twist", sc, false);
    if (!a.has("--time")) throw UsageError("missing --time T");
    const double T = a.num("--time", 0, 0);
    const double dt = a.num("--sample", 0, sc.plate.T / 4);
    if (!(T > 0) || !(dt > 0)) throw UsageError("--time and --sample must be > 0");
    IntegrationOptions io;
    io.rtol = a.num("--rtol", 0, io.rtol);
    Trajectory tr;
    ProgressPrinter prog{"simulate"};
    prog.to = &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    Scene used = sc;
    bool verify_auto = false;
    if (dyn == "auto") {
        if (!qd0.isZero()) throw UsageError("--dynamics auto answers from rest: drop --twist");
        const double tol = a.num("--model-tol", 0, 1e-2);
        if (!(tol > 0)) throw UsageError("--model-tol must be > 0");
        const ModelEstimate est = estimate_model_errors(sc, q0, T);
        PartModel part;
        Dynamics d;
        const double predicted = a_priori_pick(sc, est, tol, part, d);
        Rung picked;
        picked.part = part;
        picked.dynamics = d;
        cio.err << "auto model, decided up front (tolerance " << tol << "): picked " << picked.name()
                  << " (predicted error " << predicted << ")\n  estimates: |xi| " << est.xi << "/s, point " << est.e_point
                  << ", thin " << est.e_thin << ", eps_U " << est.eps_U << ", transient offset " << est.offset
                  << ", growth " << est.growth() << (est.ok ? "" : " (" + est.note + ")") << "\n";
        used = simplified(sc, part);
        dyn = d == Dynamics::Full ? "full" : d == Dynamics::U ? "u" : "field";
        verify_auto = a.has("--verify") && picked.name() != Rung{}.name();
    } else if (a.has("--verify")) {
        throw UsageError("--verify goes with --dynamics auto");
    }
    const Scene& sc_run = used;
    // Bounded work (issue 18): rows, then the steps extrapolated from one period (one RK4 step of a
    // field curve) run first, against the budget.
    const double rows = std::ceil(T / dt) + 1;
    if (rows > kMaxRows)
        throw UsageError("--time / --sample give " + fmt(rows) + " rows, above the limit of " + fmt(kMaxRows) +
                         ": sample less often");
    const bool field_dyn = dyn == "field";
    const long budget = a.integer("--max-steps", field_dyn ? 10'000 : io.max_steps, 1, 1'000'000'000'000L);
    io.max_steps = budget;
    {
        const auto t0 = std::chrono::steady_clock::now();
        double steps = 0, pilot_steps = 0;
        std::string what;
        if (field_dyn) {
            // RK4 steps of 0.05 s, and at least one per sample.
            LimitCycleOptions lo;
            lo.tol = a.num("--tol", 0, lo.tol);
            const double h = std::min(0.05, dt), span = std::min(T, h);
            const Trajectory pilot = field_curve(sc_run, q0, span, span, lo);
            pilot_steps = 1;
            steps = std::ceil(T / h);
            what = fmt(steps) + " RK4 steps of the field curve (one per 0.05 s, and per --sample)";
        } else {
            // Up to five periods: a start from rest can stick through the first.
            const double Tp = sc_run.plate.T, span = std::min(T, 5 * Tp);
            const Trajectory pilot = simulate(sc_run, dyn == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, span, span, io);
            pilot_steps = std::max<double>(pilot.stats.steps, 1) * std::min(span, Tp) / span;   // per period
            steps = std::max(pilot_steps * T / std::min(span, Tp), rows);   // (every row ends a step)
            what = fmt(steps) + " integrator steps (" + fmt(T / Tp) + " plate periods at " + fmt(pilot_steps) +
                   " steps each)";
        }
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (steps > budget)
            throw UsageError("--time " + fmt(T) + " s would take about " + what + ", about " +
                             fmt(secs / pilot_steps * steps) + " s here, above the budget of " +
                             fmt(static_cast<double>(budget)) + " steps: raise it with --max-steps or shorten --time");
    }
    if (dyn == "field") {
        if (!qd0.isZero()) throw UsageError("--twist has no meaning for --dynamics field");
        LimitCycleOptions lo;
        lo.tol = a.num("--tol", 0, lo.tol);
        tr = field_curve(sc_run, q0, T, dt, lo);
    } else {
        tr = simulate(sc_run, dyn == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, T, dt, io);
    }
    if (verify_auto && tr.stop.reason == StopReason::None && !tr.samples.empty()) {
        const Trajectory ref = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), T, T, io);
        if (ref.stop.reason == StopReason::None && !ref.samples.empty()) {
            const Vec3 dq = tr.samples.back().q - ref.samples.back().q;
            cio.err << "  verified against the full model: measured error "
                      << std::max({std::abs(dq[0]) / sc.part.rho(), std::abs(dq[1]) / sc.part.rho(), std::abs(wrap_angle(dq[2]))})
                      << "\n";
        } else {
            cio.err << "  verify: the full model stopped: " << ref.stop.describe() << "\n";
        }
    }
    if (tr.stop.reason == StopReason::StepLimit)   // the estimate was low: a cut-off run is not a result
        throw std::runtime_error(a.pos[0] + ": stopped: " + tr.stop.describe() + " (the up-front estimate was low: raise --max-steps); nothing written");
    write_file_atomic(a.str("--out", "-"), [&](std::ostream& out) { write_trajectory_csv(out, tr, sc_run.part.point); }, cio.out);
    if (tr.stop.reason != StopReason::None) {
        cio.err << "plate simulate: " << a.pos[0] << ": stopped: " << tr.stop.describe() << std::endl;
        return tr.stop.reason == StopReason::ContactLost ? 3 : 1;
    }
    return 0;
}

int cmd_random_scene(int argc, char** argv, Io& cio) {
    Args a(argc, argv, {{"--seed", 1}, {"--thin", 0}, {"--point", 0}, {"--out", 1}});
    if (a.help) {
        cio.out << "usage: plate random-scene --seed N [--thin | --point] [--out FILE]\n"
                     "A random part (thick by default) and a random plate motion (harmonics 1-2 on every axis,\n"
                     "vertical acceleration kept below 0.6 g within 3 cm of the centre), reproducible by seed.\n";
        return 0;
    }
    if (!a.pos.empty()) throw UsageError("random-scene takes no SCENE argument");
    if (!a.has("--seed")) throw UsageError("missing --seed N");
    RandomSceneOptions ro;
    ro.thin = a.has("--thin");
    ro.point = a.has("--point");
    if (ro.thin && ro.point) throw UsageError("--thin and --point exclude each other");
    const Scene sc = random_scene(static_cast<std::uint64_t>(a.integer("--seed", 0, 0, 1L << 62)), ro);
    write_file_atomic(a.str("--out", "-"), [&](std::ostream& out) { out << scene_to_json(sc).dump(2) << "\n"; }, cio.out);
    return 0;
}

// The checks that tie Theorem 1's to the dynamics (statics, limit-surface wrench).
nlohmann::json tie_json(const proofs::DynamicsTie& t) {
    return {{"samples", t.samples}, {"worst_statics_over_mg", t.worst_statics}, {"worst_wrench_over_mg", t.worst_wrench},
            {"tolerance", proofs::kTieTolerance}, {"failure", t.failure}, {"passed", t.passed()}};
}

nlohmann::json contraction_json(const proofs::ContractionSummary& s) {
    nlohmann::json j;
    j["cases"] = s.cases;
    j["valid"] = s.valid;
    j["monotone"] = s.monotone;
    j["converged"] = s.converged;
    j["unique_cycle"] = s.unique;
    j["floquet_below_one"] = s.floquet_below_one;
    j["worst_increase_over_bound"] = s.worst_increase;
    j["worst_seed"] = s.worst_seed;
    j["median_rate_per_period"] = s.median_rate;
    j["max_rate_per_period"] = s.max_rate;
    j["max_floquet_radius"] = s.max_spectral_radius;
    j["counterexample_seeds"] = s.counterexamples;
    j["seconds"] = s.seconds;
    j["dynamics_tie"] = tie_json(s.tie);
    j["passed"] = s.passed();
    nlohmann::json invalid = nlohmann::json::object();
    for (const auto& c : s.details)
        if (!c.why_invalid.empty()) invalid[c.why_invalid] = invalid.value(c.why_invalid, 0) + 1;
    j["not_in_model"] = invalid;
    return j;
}

int cmd_proofs(int argc, char** argv, Io& cio) {
    Args a(argc, argv, {{"--thin", 1}, {"--thick", 1}, {"--surfaces", 1}, {"--seed", 1}, {"--threads", 1}, {"--out", 1}});
    if (a.help) {
        cio.out << "usage: plate proofs [--thin N] [--thick M] [--surfaces K] [--seed S] [--threads T] [--out FILE]\n"
                     "Numerical checks of Theorem 1 on seeded random parts and plate motions: Lyapunov contraction\n"
                     "of the relative twist against its integration-error bound, convergence, uniqueness of the\n"
                     "cycle from further initial twists, Floquet multipliers (N thin parts, default 10000; M thick\n"
                     "parts beyond the theorem, default 1000); limit surfaces of K thin parts (default 200); the\n"
                     "conditioning of A as a contact approaches the line of the other two (e/L = 1 ... 0).\n"
                     "JSON to stdout or --out FILE; exit code 0 even when a check fails.\n";
        return 0;
    }
    if (!a.pos.empty()) throw UsageError("proofs takes no SCENE argument");
    const auto seed = static_cast<std::uint64_t>(a.integer("--seed", 1, 0, 1L << 40));
    const int threads = static_cast<int>(a.integer("--threads", 0, 0, 256));
    nlohmann::json j;
    j["seed"] = seed;
    auto campaign = [&](bool thin, int n, std::uint64_t s0) {
        proofs::ContractionOptions o;
        o.cases = n;
        o.seed = s0;
        o.thin = thin;
        o.threads = threads;
        o.progress = ProgressPrinter{thin ? "proofs, thin parts" : "proofs, thick parts", 10.0};
        return contraction_json(proofs::check_contraction(o));
    };
    j["thin"] = campaign(true, static_cast<int>(a.integer("--thin", 10000, 0, 1000000)), seed);
    j["thick"] = campaign(false, static_cast<int>(a.integer("--thick", 1000, 0, 100000)), seed + 50'000'000);
    // Limit surfaces of random thin parts at random plate times.
    const proofs::LimitSurfaceCampaign ls =
        proofs::check_limit_surfaces(static_cast<int>(a.integer("--surfaces", 200, 0, 20000)), seed);
    j["limit_surfaces"] = {{"parts", ls.parts}, {"directions", 300}, {"convex_and_normal", ls.convex},
                           {"strictly_convex", ls.strict}, {"worst_max_work_violation", ls.worst_max_work},
                           {"worst_monotonicity_violation", ls.worst_monotonicity},
                           {"min_separation", ls.min_separation}, {"min_strict_margin", ls.min_strict_margin},
                           {"on_friction_set", ls.on_set}, {"worst_support_violation", ls.worst_support},
                           {"worst_outside_violation", ls.worst_outside},
                           {"dynamics_tie", tie_json(ls.tie)}, {"passed", ls.passed()}};
    // A's conditioning toward collinear contacts (dimensionless A, 20 sampled states per part).
    j["conditioning_of_A"] = nlohmann::json::array();
    for (const auto& cs : proofs::collinear_scenes({1.0, 0.1, 0.01, 0.001, 0.0})) {
        const proofs::Conditioning c = proofs::condition_of_A(cs.scene, 20, seed);
        j["conditioning_of_A"].push_back({{"e_over_L", cs.e_over_L}, {"max_condition", c.max_condition},
                                          {"min_singular_over_max", c.min_singular}});
    }
    write_file_atomic(a.str("--out", "-"), [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    return 0;
}

nlohmann::json complex_json(const std::complex<double>& z) { return {z.real(), z.imag()}; }

int cmd_design(int argc, char** argv, Io& cio) {
    Args a(argc, argv, {{"--target", 3}, {"--out", 1}, {"--limits", 2}, {"--period", 1}, {"--seed", 1},
                        {"--threads", 1}, {"--starts", 1}, {"--evaluations", 1}});
    if (a.help) {
        cio.out << "usage: plate design PART_SCENE --target KIND A B --out SCENE.json [--limits LIN ANG] [--period T]\n"
                     "                    [--seed S] [--threads K] [--starts N] [--evaluations M]\n"
                     "Designs a plate motion for the part of PART_SCENE (its plate block is ignored but for its period)\n"
                     "and verifies it before reporting. Targets (point parts in this version):\n"
                     "  sink X Y          (or fixed-point X Y) the unique stable fixed point of the velocity field at (X, Y)\n"
                     "  transport VX VY   a uniform velocity (VX, VY) [m/s] over the plate\n"
                     "--limits LIN ANG: the largest amplitude of each harmonic (default 20 m/s^2, 150 rad/s^2); g plus the\n"
                     "vertical acceleration stays above 0.2 g over the plate (a constraint). NLopt COBYLA from --starts\n"
                     "seeded feasible motions (default 16), --evaluations each (default 400). Verification: the field's\n"
                     "fixed points on a 7x7 grid and full dynamics from 20 seeded random starts. Writes the designed\n"
                     "scene to --out and a JSON summary to stdout; exit 4 (and no scene) if the design fails verification.\n";
        return 0;
    }
    const Scene part = scene_arg(a, cio);
    if (!a.has("--target")) throw UsageError("missing --target KIND A B");
    if (!a.has("--out")) throw UsageError("missing --out SCENE.json");
    const std::string kind = a.opt.at("--target")[0];
    DesignTarget t;
    const Vec2 ab(Args::parse_num("--target", a.opt.at("--target")[1]), Args::parse_num("--target", a.opt.at("--target")[2]));
    if (kind == "sink" || kind == "fixed-point") t.at = ab;
    else if (kind == "transport") {
        t.kind = DesignTargetKind::Transport;
        t.velocity = ab;
    } else {
        throw UsageError("--target: expected sink X Y, fixed-point X Y or transport VX VY, got '" + kind + "'");
    }
    DesignOptions o;
    o.lin_limit = a.num("--limits", 0, o.lin_limit);
    o.ang_limit = a.num("--limits", 1, o.ang_limit);
    if (!(o.lin_limit >= 0 && o.ang_limit >= 0 && o.lin_limit <= kMaxAmplitude && o.ang_limit <= kMaxAmplitude))
        throw UsageError("--limits: expected amplitudes from 0 to " + fmt(kMaxAmplitude));
    o.period = a.num("--period", 0, 0);
    if (a.has("--period") && !(o.period >= kPeriodRange[0] && o.period <= kPeriodRange[1]))
        throw UsageError("--period: expected " + fmt(kPeriodRange[0]) + " to " + fmt(kPeriodRange[1]) + " s");
    o.seed = static_cast<std::uint64_t>(a.integer("--seed", 1, 0, 1L << 40));
    o.threads = static_cast<int>(a.integer("--threads", 0, 0, 256));
    o.starts = static_cast<int>(a.integer("--starts", o.starts, 1, 10000));
    o.local_evaluations = static_cast<int>(a.integer("--evaluations", o.local_evaluations, 1, 1'000'000));
    DesignSummary d;
    try {
        d = design(part, t, o);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    const bool sink = t.kind == DesignTargetKind::Sink;
    nlohmann::json j;
    j["target"] = {{"kind", sink ? "sink" : "transport"}, {sink ? "at" : "velocity", {ab.x(), ab.y()}}};
    j["verified"] = d.verified;
    if (!d.verified) j["failure"] = d.failure;
    j["scene"] = a.str("--out", "");
    if (sink) {
        j["unique"] = d.unique;
        j["convergence_rate_per_s"] = d.rate;
        j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1]};
        j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]), complex_json(d.fixed_point_eigenvalues[1])};
        j["fixed_points_on_grid"] = fixed_points_sentence(d.fixed_points);
    } else {
        j["mean_velocity"] = {d.transport_mean.x(), d.transport_mean.y()};
        j["spread"] = d.transport_spread;
        j["tolerance"] = d.transport_tolerance;
    }
    nlohmann::json runs = nlohmann::json::array();
    for (const DesignStartRun& r : d.runs) {
        nlohmann::json x = {{"start", {r.x, r.y}}, {"seconds", r.seconds}, {"end_distance", r.end_distance}};
        if (!r.stop.empty()) x["stop"] = r.stop;
        runs.push_back(x);
    }
    j["full_dynamics_runs"] = runs;
    j["worst_end_distance"] = d.worst_end_distance;
    j["min_vertical_acceleration_margin_over_g"] = d.min_vertical_margin;
    j["limits"] = {o.lin_limit, o.ang_limit};
    j["evaluations"] = d.evaluations;
    j["limit_cycles"] = d.cycles;
    j["seconds"] = d.seconds;
    j["notes"] = d.notes;
    if (d.verified) {
        write_file_atomic(a.str("--out", ""), [&](std::ostream& out) { out << scene_to_json(d.scene).dump(2) << "\n"; });
        for (const std::string& w : scene_warnings(d.scene)) cio.err << "warning: designed scene: " << w << "\n";
    }
    cio.out << j.dump(2) << std::endl;
    if (!d.verified) {
        cio.err << "plate design: " << a.pos[0] << ": the design failed verification: " << d.failure << " (no scene written)"
                << std::endl;
        return 4;
    }
    return 0;
}

// The output folder of report and bench, which take no SCENE.
std::string out_dir_arg(const Args& a, const std::string& cmd) {
    if (!a.pos.empty()) throw UsageError(cmd + " takes no SCENE argument");
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    return a.str("--out", "");
}

int cmd_report(int argc, char** argv, Io& cio) {
    Args a(argc, argv, {{"--out", 1}, {"--seed", 1}, {"--quick", 0}, {"--threads", 1}, {"--source", 1}});
    if (a.help) {
        cio.out << "usage: plate report --out DIR [--quick] [--seed S] [--threads T] [--source ROOT]\n"
                     "Writes DIR/index.html and its figures: the derivation and its findings, kernel equivalence,\n"
                     "Theorem 1 checks (10^4 thin, 10^3 thick parts; --quick: a few), limit surfaces, Fig. 3, and the\n"
                     "paper's fields with full-dynamics trajectories and fixed-point tables. ROOT: the project folder\n"
                     "(scenes/, reports/generated/), default the one this program was built from.\n";
        return 0;
    }
    report::ReportOptions o;
    o.out = out_dir_arg(a, "report");
    o.source_dir = a.str("--source", data_root());
    o.seed = static_cast<std::uint64_t>(a.integer("--seed", 1, 0, 1L << 40));
    o.quick = a.has("--quick");
    o.threads = static_cast<int>(a.integer("--threads", 0, 0, 256));
    report::write_report(o);
    cio.err << "report: " << o.out << "/index.html" << std::endl;
    return 0;
}

int cmd_bench(int argc, char** argv, Io& cio) {
    Args a(argc, argv, {{"--out", 1}, {"--full", 0}, {"--source", 1}});
    if (a.help) {
        cio.out << "usage: plate bench --out DIR [--full] [--source ROOT]\n"
                     "The speed-accuracy study: work-precision charts (every method and friction treatment on (a) an\n"
                     "asymptotic twist of fig4, (b) fig4's 20 s full-dynamics trajectory, (c) a near-sticking twist of\n"
                     "fig6) against reference solutions; the limit-cycle solvers on fig4's field against period-by-\n"
                     "period RK4; failure maps; the model hierarchy. Writes the charts into DIR and the section into\n"
                     "DIR/index.html (the report's page if `plate report --out DIR` wrote one). Quick by default\n"
                     "(minutes); --full sweeps more settings.\n";
        return 0;
    }
    report::SpeedOptions o;
    o.out = out_dir_arg(a, "bench");
    o.source_dir = a.str("--source", data_root());
    o.full = a.has("--full");
    report::write_speed_study(o);
    cio.err << "bench: " << o.out << "/index.html" << std::endl;
    return 0;
}

}  // namespace

int run(int argc, char** argv, std::ostream& out, std::ostream& err) {
    Io cio{out, err};
    if (argc >= 2 && !std::strcmp(argv[1], "--version")) {
        cio.out << "plate " << PLATE_VERSION << " (scenes and report inputs: " << data_root() << ")\n";
        return 0;
    }
    if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
        cio.out << kUsage;
        return argc < 2 ? 2 : 0;
    }
    const std::string cmd = argv[1];
    try {
        if (cmd == "twist") return cmd_twist(argc - 2, argv + 2, cio);
        if (cmd == "field") return cmd_field(argc - 2, argv + 2, cio);
        if (cmd == "fixed-points") return cmd_fixed_points(argc - 2, argv + 2, cio);
        if (cmd == "simulate") return cmd_simulate(argc - 2, argv + 2, cio);
        if (cmd == "random-scene") return cmd_random_scene(argc - 2, argv + 2, cio);
        if (cmd == "proofs") return cmd_proofs(argc - 2, argv + 2, cio);
        if (cmd == "report") return cmd_report(argc - 2, argv + 2, cio);
        if (cmd == "bench") return cmd_bench(argc - 2, argv + 2, cio);
        if (cmd == "design") return cmd_design(argc - 2, argv + 2, cio);
        cio.err << "plate: unknown command '" << cmd << "'\n" << kUsage;
        return 2;
    } catch (const InputError& e) {
        cio.err << "plate " << cmd << ": " << e.what() << std::endl;
        return 2;
    } catch (const UsageError& e) {
        cio.err << "plate " << cmd << ": " << e.what() << " (see plate " << cmd << " --help)" << std::endl;
        return 2;
    } catch (const std::exception& e) {
        cio.err << "plate " << cmd << ": error: " << e.what() << std::endl;
        return 1;
    }
}

}  // namespace plate::cli
