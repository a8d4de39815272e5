// plate: the command-line program (apps/main.cpp runs it). See `plate --help`.
// Exit codes: 0 success; 2 bad input (usage, scene file); 3 a simulation left the model's
// assumptions (contact lost, sticking, step collapse) -- its output up to that time is kept;
// 4 a design that failed verification (nothing written); 1 any other failure.
#include "cli.hpp"

#include "plate/design.hpp"
#include "plate/farm.hpp"
#include "plate/field.hpp"
#include "plate/hierarchy.hpp"
#include "plate/output.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"
#include "plate/sweep.hpp"
#include "report.hpp"
#include "theorem1.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <set>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace plate::cli {
namespace {

struct Io {
    std::ostream& out;
    std::ostream& err;
    // The MPI ranks of a command started under mpirun (plate field, fixed-points, design, proofs):
    // held here so that it outlives an exception from the command, whose report run() coordinates.
    std::unique_ptr<sweep::Farm> farm;
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

const char* kAbout = "plate: sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch)\n";
const char* kFooter =
    "plate COMMAND --help for its options; plate --version\n"
    "\n"
    "SCENE is a JSON scene file (see scenes/). Units are SI. Exit codes: 0 ok, 2 bad input,\n"
    "3 a simulation left the model (a normal force reached zero: the part would fly), 4 a design that\n"
    "failed its verification, 1 other failure.\n";

// ---- the command line ----------------------------------------------------------------------
// CLI11 splits the arguments into a command, its options and their values, finds unknown
// options and writes the help. The rules for values are ours, and every message names the option.

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A finite number, all of the text ("nan", "inf", "1e999", "" and "3x" are refused).
double parse_num(const std::string& k, const std::string& s) {
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(x))
        throw UsageError("option " + k + ": expected a finite number, got '" + s + "'");
    return x;
}

// A whole number from lo to hi, all of the text, base 10.
long parse_whole(const std::string& k, const std::string& s, long lo, long hi) {
    char* end = nullptr;
    const long x = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || x < lo || x > hi)
        throw UsageError("option " + k + ": expected a whole number from " + std::to_string(lo) + " to " +
                         std::to_string(hi) + ", got '" + s + "'");
    return x;
}

// The options of one command, declared on its CLI11 subcommand into the command's variables
// (which hold the defaults). Each option reaches its callback once per occurrence, as it is
// parsed (trigger_on_parse): a second occurrence is refused there (CLI11's Throw policy counts
// values, not occurrences, so `--at 0 0 --at 1` would pass as three numbers), and the text is
// converted by the rules above.
class Options {
public:
    Options(CLI::App* cmd, const std::string& footer) : cmd_(cmd) { cmd_->group("commands")->footer(footer); }
    Options(const Options&) = delete;   // the callbacks hold `this`
    Options& operator=(const Options&) = delete;

    bool given() const { return cmd_->parsed(); }   // this is the command run
    bool has(const std::string& name) const { return seen_.count(name) > 0; }

    // What CLI11 could not place (the app allows extras so that the messages are ours): an
    // unknown option, or an argument beyond SCENE.
    void reject(const std::vector<std::string>& leftovers) const {
        for (const std::string& s : leftovers) {
            char* end = nullptr;
            std::strtod(s.c_str(), &end);
            if (s.size() > 1 && s[0] == '-' && *end != '\0') throw UsageError("unknown option " + s);
        }
        if (leftovers.empty()) return;
        throw UsageError(takes_scene_ ? "expected exactly one SCENE file" : cmd_->get_name() + " takes no SCENE argument");
    }

    void scene_file(std::string& file, const std::string& name = "SCENE") {
        takes_scene_ = true;
        cmd_->add_option(name, file, "the scene file (JSON, see scenes/)")->required()->option_text(" ");
    }
    // The help shows the default: `def`, or else x's value; none if def is "".
    void number(const std::string& name, double& x, const std::string& help, const char* def = nullptr) {
        std::ostringstream value;
        value << x;
        add<std::string>(name, 1, "X", help + in_parentheses("", def ? def : value.str()),
                         [name, &x](const std::string& s) { x = parse_num(name, s); });
    }
    template <class Int>
    void whole(const std::string& name, Int& x, long lo, long hi, const std::string& help, const char* def = nullptr) {
        const std::string range = std::to_string(lo) + " to " + std::to_string(hi);
        add<std::string>(name, 1, "N", help + in_parentheses(range, def ? def : std::to_string(x)),
                         [name, &x, lo, hi](const std::string& s) {
                             x = static_cast<Int>(parse_whole(name, s, lo, hi));
                         });
    }
    // lo to hi numbers (`names` in the help); how many a part takes is checked where that is known (config_arg).
    void numbers(const std::string& name, std::vector<double>& v, std::size_t lo, std::size_t hi,
                 const std::string& names, const std::string& help) {
        const std::string count = std::to_string(lo) + (lo < hi ? " or " + std::to_string(hi) : "");
        add<std::vector<std::string>>(name, static_cast<int>(hi), names, help,
                                      [name, &v, lo, hi, count](const std::vector<std::string>& s) {
                                          if (s.size() < lo || s.size() > hi)
                                              throw UsageError(name + ": expected " + count + " numbers");
                                          v.clear();
                                          for (const std::string& x : s) v.push_back(parse_num(name, x));
                                      });
    }
    void words(const std::string& name, std::vector<std::string>& v, std::size_t n, const std::string& names,
               const std::string& help) {
        add<std::vector<std::string>>(name, static_cast<int>(n), names, help,
                                      [name, &v, n](const std::vector<std::string>& s) {
                                          if (s.size() != n)
                                              throw UsageError("option " + name + " expects " + std::to_string(n) +
                                                               " value(s)");
                                          v = s;
                                      });
    }
    // From lo to hi words.
    void words(const std::string& name, std::vector<std::string>& v, std::size_t lo, std::size_t hi, const std::string& names,
               const std::string& help) {
        add<std::vector<std::string>>(name, static_cast<int>(hi), names, help,
                                      [name, &v, lo, hi](const std::vector<std::string>& s) {
                                          if (s.size() < lo || s.size() > hi)
                                              throw UsageError("option " + name + " expects " + std::to_string(lo) +
                                                               " to " + std::to_string(hi) + " values");
                                          v = s;
                                      });
    }
    void text(const std::string& name, std::string& s, const std::string& value, const std::string& help) {
        add<std::string>(name, 1, value, help, [&s](const std::string& t) { s = t; });
    }
    void flag(const std::string& name, bool& b, const std::string& help) {
        cmd_->add_flag_function(name, [this, name, &b](std::int64_t) { once(name); b = true; }, help)
            ->disable_flag_override()
            ->trigger_on_parse();
    }

private:
    template <class T>
    void add(const std::string& name, int max_values, const std::string& names, const std::string& help,
             std::function<void(const T&)> store) {
        cmd_->add_option_function<T>(name, [this, name, store](const T& v) { once(name); store(v); }, help)
            ->expected(1, max_values)
            ->allow_extra_args(false)                   // (a vector's default: eat every value that follows)
            ->option_text(names)
            ->type_name(names.substr(0, names.find(' ')))   // "--at: 1 required SX missing"
            ->trigger_on_parse();
    }
    void once(const std::string& name) {
        if (!seen_.insert(name).second) throw UsageError("option " + name + " given twice");
    }
    // " (RANGE; default DEF)", without what is empty.
    static std::string in_parentheses(const std::string& range, const std::string& def) {
        std::string s = range;
        if (!def.empty()) s += (s.empty() ? "default " : "; default ") + def;
        return s.empty() ? s : " (" + s + ")";
    }

    CLI::App* cmd_;
    std::set<std::string> seen_;
    bool takes_scene_ = false;
};

// The scene file; its warnings (scene_warnings: admissible, outside the intended regime) to err.
// The scene of a command. Under mpirun (cio.farm) rank 0 reads the file and sends its text to every
// rank (the others may not see the file: nodes without a shared filesystem), so that every rank has
// the same scene or the same error, and only rank 0 prints warnings.
Scene scene_arg(const std::string& file, Io& cio) {
    if (!cio.farm || cio.farm->ranks() == 1) {
        Scene sc = load_scene(file);
        for (const std::string& w : scene_warnings(sc)) cio.err << "warning: " << w << "\n";
        return sc;
    }
    std::string text;
    if (cio.farm->root()) {
        std::ifstream in(file, std::ios::binary);
        std::stringstream buf;
        buf << in.rdbuf();
        text = in ? "S" + buf.str() : "E";
    }
    cio.farm->broadcast(text);
    if (text.empty() || text[0] != 'S') throw InputError(file + ": cannot open scene file");
    Scene sc = parse_scene(text.substr(1), file);
    if (cio.farm->root())
        for (const std::string& w : scene_warnings(sc)) cio.err << "warning: " << w << "\n";
    return sc;
}

// --NAME's numbers (`v`, given or not): 3 for a rigid part, 2 for a point part.
Vec3 config_arg(const Options& a, const std::string& k, const std::vector<double>& v, const Scene& sc, bool required) {
    if (!a.has(k)) {
        if (required) throw UsageError("missing " + k + (sc.part.point ? " SX SY" : " SX SY THETA"));
        return Vec3::Zero();
    }
    Vec3 q = Vec3::Zero();
    const std::size_t need = sc.part.point ? 2 : 3;
    if (v.size() != need) throw UsageError(k + ": expected " + std::to_string(need) + " numbers");
    for (std::size_t i = 0; i < need; ++i) q[i] = v[i];
    return q;
}

// ---- the limit cycle's and the grid's options (twist, field, fixed-points) ------------------

struct CycleArgs {
    LimitCycleOptions o = [] {
        LimitCycleOptions o;
        // The command line's budget per cycle is tighter than the library's (2e7, for tight references):
        // 2e6, about 0.3 s; the shipped scenes' field cycles take at most ~6e4 at the default tolerances.
        o.max_rhs_evaluations = kCliCycleBudget;
        return o;
    }();
    std::string solver;
};

void add_cycle_options(Options& p, CycleArgs& c) {
    p.number("--tol", c.o.tol, "accepted distance to the cycle, relative to the slip-speed scale");
    p.number("--rtol", c.o.integration.rtol, "integrator tolerance, in (0, 1e-2)");
    p.whole("--max-periods", c.o.max_periods, 2, 100000, "periods before the cycle counts as not converged");
    p.whole("--max-rhs", c.o.max_rhs_evaluations, 1000, 1'000'000'000'000L,
            "work budget of one cycle, right-hand sides");
    p.text("--cycle-solver", c.solver, "NAME", "period-by-period, anderson, newton or shooting (default shooting)");
}

LimitCycleOptions cycle_opts(const Options& a, const CycleArgs& c) {
    LimitCycleOptions o = c.o;
    if (a.has("--cycle-solver")) {
        try {
            o.solver = parse_cycle_solver(c.solver);
        } catch (const std::invalid_argument& e) {
            throw UsageError(std::string("--cycle-solver: ") + e.what());
        }
    }
    if (!(o.tol > 0) || !(o.integration.rtol > 0 && o.integration.rtol < 1e-2))
        throw UsageError("--tol must be > 0 and --rtol in (0, 1e-2)");
    return o;
}

struct GridArgs {
    int n = 7;
    GridSpec g;
    std::vector<double> x, y;
    int threads = 0;
};

void add_grid_options(Options& p, GridArgs& a) {
    p.whole("--grid", a.n, 1, 201, "grid points on each axis");
    p.whole("--nx", a.g.nx, 1, 201, "points along s_x", "--grid");
    p.whole("--ny", a.g.ny, 1, 201, "points along s_y", "--grid");
    p.whole("--ntheta", a.g.nth, 1, 720, "points along theta", "--grid");
    p.numbers("--x", a.x, 2, 2, "MIN MAX", "the range of s_x [m] (default -0.05 0.05)");
    p.numbers("--y", a.y, 2, 2, "MIN MAX", "the range of s_y [m] (default -0.05 0.05)");
    p.number("--theta0", a.g.th0, "the first theta of the full turn");
    p.whole("--threads", a.threads, 0, 256, "threads (0: all cores)");
}

GridSpec grid_opts(const Options& a, const GridArgs& ga) {
    GridSpec g = ga.g;
    if (!a.has("--nx")) g.nx = ga.n;
    if (!a.has("--ny")) g.ny = ga.n;
    if (!a.has("--ntheta")) g.nth = ga.n;
    if (a.has("--x")) {
        g.x0 = ga.x[0];
        g.x1 = ga.x[1];
    }
    if (a.has("--y")) {
        g.y0 = ga.y[0];
        g.y1 = ga.y[1];
    }
    if (!(g.x1 >= g.x0) || !(g.y1 >= g.y0)) throw UsageError("--x and --y take MIN MAX with MIN <= MAX");
    return g;
}

// ---- plate twist ---------------------------------------------------------------------------

struct TwistArgs : Options {
    std::string scene;
    std::vector<double> at, from;
    CycleArgs cycle;
    explicit TwistArgs(CLI::App* cmd)
        : Options(cmd, "Asymptotic twist (36) of the reduced U-dynamics limit cycle at (SX, SY, THETA), starting\n"
                       "from the part twist --from (default: at rest relative to the plate). Point parts: --at SX SY.\n"
                       "--tol: accepted distance to the cycle relative to the slip-speed scale (default 1e-7);\n"
                       "--rtol: integrator tolerance (default 1e-8); --max-periods (default 400); --max-rhs: the work\n"
                       "budget of the cycle in right-hand sides (default 2e6, about 0.3 s; then stop: step_limit).\n") {
        scene_file(scene);
        numbers("--at", at, 2, 3, "SX SY THETA", "the configuration (point parts: SX SY); required");
        numbers("--from", from, 2, 3, "VX VY OMEGA", "the part's twist relative to the plate at the start");
        add_cycle_options(*this, cycle);
    }
};

int cmd_twist(const TwistArgs& a, Io& cio) {
    const Scene sc = scene_arg(a.scene, cio);
    const Vec3 q = config_arg(a, "--at", a.at, sc, true);
    const Vec3 qd = config_arg(a, "--from", a.from, sc, false);
    const LimitCycleSummary lc = limit_cycle(sc, q, cycle_opts(a, a.cycle), qd);
    cio.out << to_json(sc, q, lc).dump(2) << std::endl;
    return 0;
}

// Bounded work for a field (issue 18): five cycles from rest (the grid's centre and four spread
// configurations) run first; the field costs about their mean per configuration (measured on the
// shipped scenes' 9x9x9 fields: 0.2-3.4x of it; warm starts save, sticking cycles cost more), and a
// field estimated over the budget --max-work (right-hand sides, default 2e9: minutes on two cores)
// is refused with the estimate. The budget also holds while the field runs (require_within_budget).
long check_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& lo, long budget) {
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


// ---- plate field, plate fixed-points ---------------------------------------------------------

// The field of `field` and `fixed-points`: its work estimated up front against `max_work`, progress
// on a terminal, and refused if the budget was spent anyway.
// The field within its work budget; under mpirun (cio.farm) its planes are shared over the ranks and
// Under an MPI launcher with several ranks: the ranks (threads each), else null (one process).
sweep::Farm* launched_farm(Io& cio, int threads) {
    if (!sweep::mpi_launched()) return nullptr;
    if (!sweep::mpi_built())
        throw UsageError("started by an MPI launcher with several ranks, but this plate was built without MPI: "
                         "every process would do the whole job (rebuild with libopenmpi-dev, or run it alone)");
    cio.farm = sweep::mpi_farm(threads);
    return cio.farm.get();
}

// every rank returns the whole field, the same as one process computes.
Field bounded_field(const Scene& sc, const GridSpec& g, const LimitCycleOptions& cycle, int threads, long max_work, Io& cio) {
    FieldOptions fo;
    fo.cycle = cycle;
    fo.threads = threads;
    if (cio.farm) fo.tasks = sweep::farm_tasks(*cio.farm);
    fo.max_rhs_evaluations = check_field_work(sc, g, fo.cycle, max_work);
    ProgressPrinter prog{"field"};
    prog.to = &cio.err == &std::cerr && progress_wanted() && (!cio.farm || cio.farm->root()) ? &cio.err : nullptr;
    fo.progress = std::ref(prog);
    Field f = compute_field(sc, g, fo);
    require_within_budget(f, fo.max_rhs_evaluations);
    return f;
}

constexpr long kMaxWorkLimit = 1'000'000'000'000'000L;

struct FieldArgs : Options {
    std::string scene, format = "json", out = "-";
    GridArgs grid;
    CycleArgs cycle;
    long max_work = 2'000'000'000L;
    explicit FieldArgs(CLI::App* cmd)
        : Options(cmd, "Asymptotic twist field on a regular grid (default 7x7x7 over [-0.05,0.05]^2 m x [0, 2pi)),\n"
                       "theta covering a full turn. Point parts: asymptotic velocity field on (s_x, s_y).\n"
                       "Configurations run in parallel on all cores (--threads). Output to stdout or --out FILE.\n"
                       "--max-work N: the budget in right-hand sides (default 2e9); the work is estimated up front\n"
                       "from one cycle and a larger field is refused with the estimate (exit 2); a field that spends\n"
                       "it anyway stops there (exit 1, no output).\n") {
        scene_file(scene);
        add_grid_options(*this, grid);
        text("--format", format, "json|csv", "the output's format (default json)");
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--max-work", max_work, 1000, kMaxWorkLimit, "work budget of the field, right-hand sides");
        add_cycle_options(*this, cycle);
    }
};

int cmd_field(const FieldArgs& a, Io& cio) {
    launched_farm(cio, a.grid.threads);
    const Scene sc = scene_arg(a.scene, cio);
    const GridSpec g = grid_opts(a, a.grid);
    const std::string format = a.format;
    if (format != "json" && format != "csv") throw UsageError("--format: expected json or csv");
    const Field f = bounded_field(sc, g, cycle_opts(a, a.cycle), a.grid.threads, a.max_work, cio);
    if (cio.farm && !cio.farm->root()) return 0;   // (rank 0 writes)
    write_file_atomic(a.out, [&](std::ostream& out) {
        if (format == "csv") {
            write_field_csv(out, f);
        } else {
            nlohmann::json j = to_json(sc, f);
            if (cio.farm) j["mpi"] = cio.farm->describe();
            out << j.dump(1) << "\n";
        }
    }, cio.out);
    return 0;
}

struct FixedPointsArgs : Options {
    std::string scene, out = "-";
    GridArgs grid;
    CycleArgs cycle;
    long max_work = 2'000'000'000L;
    explicit FixedPointsArgs(CLI::App* cmd)
        : Options(cmd, "Computes the field, finds cells where every component changes sign, refines the zeros\n"
                       "by Gauss-Newton, classifies them by the Jacobian's eigenvalues (stable, unstable, saddle)\n"
                       "and reports curves of zeros as lines. JSON to stdout or --out FILE. --max-work as for field;\n"
                       "the refinement's own budget is the smaller of it and 2e7 right-hand sides.\n") {
        scene_file(scene);
        add_grid_options(*this, grid);
        text("--out", out, "FILE", "the output file (default: standard output)");
        whole("--max-work", max_work, 1000, kMaxWorkLimit, "work budget of the field, right-hand sides");
        add_cycle_options(*this, cycle);
    }
};

int cmd_fixed_points(const FixedPointsArgs& a, Io& cio) {
    launched_farm(cio, a.grid.threads);
    const Scene sc = scene_arg(a.scene, cio);
    const LimitCycleOptions cycle = cycle_opts(a, a.cycle);
    const GridSpec g = grid_opts(a, a.grid);
    const Field f = bounded_field(sc, g, cycle, a.grid.threads, a.max_work, cio);
    if (cio.farm && !cio.farm->root()) return 0;   // (rank 0 refines the zeros and writes)
    FixedPointOptions fpo;   // (the refinement has its own budget)
    fpo.cycle = cycle;
    if (a.has("--max-work")) fpo.max_rhs_evaluations = std::min(fpo.max_rhs_evaluations, a.max_work);
    const FixedPoints fp = find_fixed_points(sc, f, fpo);
    write_file_atomic(a.out, [&](std::ostream& out) { out << to_json(sc, fp).dump(2) << "\n"; }, cio.out);
    return 0;
}

// ---- plate simulate ------------------------------------------------------------------------

struct SimulateArgs : Options {
    std::string scene, dynamics, out = "-";
    std::vector<double> from, twist;
    double time = 0, sample = 0, model_tol = 1e-2;
    double rtol = IntegrationOptions{}.rtol, tol = LimitCycleOptions{}.tol;
    std::string max_periods;   // (accepted as always, any value: no simulation reads it)
    long max_steps = 0;
    bool verify = false;
    explicit SimulateArgs(CLI::App* cmd)
        : Options(cmd, "Trajectory from configuration --from with part twist --twist relative to the plate\n"
                       "(default: at rest). full: full dynamics (31) with the plate on SO(3); u: U-dynamics (32);\n"
                       "field: integral curve of the asymptotic twist field (RK4, 0.05 s steps). averaged: stroboscopic\n"
                       "averaging of the full dynamics (macro steps of many periods, each slope from a burst of the full\n"
                       "dynamics; coning included; rows after the first five periods interpolated, their twist and\n"
                       "normal forces nan).\n"
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
                       "run that would exceed the budget is refused with the estimate (exit 2); at most 10^7 rows.\n") {
        scene_file(scene);
        text("--dynamics", dynamics, "full|u|field|averaged|auto", "the model; required");
        numbers("--from", from, 2, 3, "SX SY THETA", "the start (point parts: SX SY); required");
        number("--time", time, "the duration T [s]; required", "");
        numbers("--twist", twist, 2, 3, "VX VY OMEGA", "the part's twist relative to the plate at the start");
        number("--sample", sample, "seconds between rows", "a quarter of the plate's period");
        text("--out", out, "FILE", "the CSV file (default: standard output)");
        number("--rtol", rtol, "integrator tolerance");
        number("--tol", tol, "limit-cycle tolerance of the field curve");
        text("--max-periods", max_periods, "N", "(not used by simulate)");
        number("--model-tol", model_tol, "auto: the error allowed");
        flag("--verify", verify, "auto: also run the full model and report the measured error");
        whole("--max-steps", max_steps, 1, 1'000'000'000'000L, "work budget, integrator steps", "2e7, field 1e4");
    }
};

int cmd_simulate(const SimulateArgs& a, Io& cio) {
    const Scene sc = scene_arg(a.scene, cio);
    std::string dyn = a.dynamics;
    if (dyn != "full" && dyn != "u" && dyn != "field" && dyn != "averaged" && dyn != "auto")
        throw UsageError("--dynamics: expected full, u, field, averaged or auto");
    const Vec3 q0 = config_arg(a, "--from", a.from, sc, true);
    const Vec3 qd0 = config_arg(a, "--twist", a.twist, sc, false);
    if (!a.has("--time")) throw UsageError("missing --time T");
    const double T = a.time;
    const double dt = a.has("--sample") ? a.sample : sc.plate.T / 4;
    if (!(T > 0) || !(dt > 0)) throw UsageError("--time and --sample must be > 0");
    IntegrationOptions io;
    io.rtol = a.rtol;
    Trajectory tr;
    ProgressPrinter prog{"simulate"};
    prog.to = &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    Scene used = sc;
    bool verify_auto = false;
    if (dyn == "auto") {
        if (!qd0.isZero()) throw UsageError("--dynamics auto answers from rest: drop --twist");
        const double tol = a.model_tol;
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
        verify_auto = a.verify && picked.name() != Rung{}.name();
    } else if (a.verify) {
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
    const long budget = a.has("--max-steps") ? a.max_steps : field_dyn ? 10'000 : io.max_steps;
    io.max_steps = budget;
    {
        const auto t0 = std::chrono::steady_clock::now();
        double steps = 0, pilot_steps = 0;
        std::string what;
        if (field_dyn) {
            // RK4 steps of 0.05 s, and at least one per sample.
            LimitCycleOptions lo;
            lo.tol = a.tol;
            const double h = std::min(0.05, dt), span = std::min(T, h);
            const Trajectory pilot = field_curve(sc_run, q0, span, span, lo);
            pilot_steps = 1;
            steps = std::ceil(T / h);
            what = fmt(steps) + " RK4 steps of the field curve (one per 0.05 s, and per --sample)";
        } else {
            // Up to five periods: a start from rest can stick through the first.
            const double Tp = sc_run.plate.T, span = std::min(T, 5 * Tp);
            // (averaged: its bursts are full dynamics; the estimate is the direct run's, an upper bound)
            const Trajectory pilot = simulate(sc_run, dyn == "u" ? Dynamics::U : Dynamics::Full, q0, qd0, span, span, io);
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
        lo.tol = a.tol;
        tr = field_curve(sc_run, q0, T, dt, lo);
    } else if (dyn == "averaged") {
        tr = simulate_averaged(sc_run, q0, qd0, T, dt, io);
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
        throw std::runtime_error(a.scene + ": stopped: " + tr.stop.describe() + " (the up-front estimate was low: raise --max-steps); nothing written");
    write_file_atomic(a.out, [&](std::ostream& out) { write_trajectory_csv(out, tr, sc_run.part.point); }, cio.out);
    if (tr.stop.reason != StopReason::None) {
        cio.err << "plate simulate: " << a.scene << ": stopped: " << tr.stop.describe() << std::endl;
        return tr.stop.reason == StopReason::ContactLost ? 3 : 1;
    }
    return 0;
}

// ---- plate random-scene --------------------------------------------------------------------

struct RandomSceneArgs : Options {
    std::uint64_t seed = 0;
    bool thin = false, point = false;
    std::string out = "-";
    explicit RandomSceneArgs(CLI::App* cmd)
        : Options(cmd, "A random part (thick by default) and a random plate motion (harmonics 1-2 on every axis,\n"
                       "vertical acceleration kept below 0.6 g within 3 cm of the centre), reproducible by seed.\n") {
        whole("--seed", seed, 0, 1L << 62, "the seed; required", "");
        flag("--thin", thin, "a thin part (contacts in the plane of the centre of mass: Theorem 1)");
        flag("--point", point, "a point part");
        text("--out", out, "FILE", "the scene file (default: standard output)");
    }
};

int cmd_random_scene(const RandomSceneArgs& a, Io& cio) {
    if (!a.has("--seed")) throw UsageError("missing --seed N");
    RandomSceneOptions ro;
    ro.thin = a.thin;
    ro.point = a.point;
    if (ro.thin && ro.point) throw UsageError("--thin and --point exclude each other");
    const Scene sc = random_scene(a.seed, ro);
    write_file_atomic(a.out, [&](std::ostream& out) { out << scene_to_json(sc).dump(2) << "\n"; }, cio.out);
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

// ---- plate proofs --------------------------------------------------------------------------

struct ProofsArgs : Options {
    int thin = 10000, thick = 1000, surfaces = 200, threads = 0;
    std::uint64_t seed = 1;
    std::string out = "-";
    explicit ProofsArgs(CLI::App* cmd)
        : Options(cmd, "Numerical checks of Theorem 1 on seeded random parts and plate motions: Lyapunov contraction\n"
                       "of the relative twist against its integration-error bound, convergence, uniqueness of the\n"
                       "cycle from further initial twists, Floquet multipliers (N thin parts, default 10000; M thick\n"
                       "parts beyond the theorem, default 1000); limit surfaces of K thin parts (default 200); the\n"
                       "conditioning of A as a contact approaches the line of the other two (e/L = 1 ... 0).\n"
                       "JSON to stdout or --out FILE; exit code 0 even when a check fails.\n") {
        whole("--thin", thin, 0, 1000000, "thin parts");
        whole("--thick", thick, 0, 100000, "thick parts");
        whole("--surfaces", surfaces, 0, 20000, "limit surfaces");
        whole("--seed", seed, 0, 1L << 40, "the first seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        text("--out", out, "FILE", "the JSON file (default: standard output)");
    }
};

// A contraction case as the MPI ranks send it: what summarize_contraction reads, doubles exact
// (nlohmann writes 17 digits; NaN and infinities as text).
nlohmann::json exact(double x) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    return x;
}
double exact(const nlohmann::json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string s = j.get<std::string>();
    return s == "nan" ? std::nan("") : s == "inf" ? HUGE_VAL : -HUGE_VAL;
}
std::string case_text(const proofs::ContractionCase& c) {
    return nlohmann::json{{"seed", c.seed}, {"valid", c.valid}, {"why_invalid", c.why_invalid},
                          {"monotone", c.monotone}, {"converged", c.converged}, {"unique", c.unique},
                          {"spectral_radius", exact(c.spectral_radius)}, {"worst_increase", exact(c.worst_increase)},
                          {"rate", exact(c.rate)}, {"tie_samples", c.tie.samples}, {"tie_statics", exact(c.tie.worst_statics)},
                          {"tie_wrench", exact(c.tie.worst_wrench)}, {"tie_failure", c.tie.failure}}
        .dump();
}
proofs::ContractionCase case_from_text(const std::string& text) {
    const nlohmann::json j = nlohmann::json::parse(text);
    proofs::ContractionCase c;
    c.seed = j["seed"].get<std::uint64_t>();
    c.valid = j["valid"].get<bool>();
    c.why_invalid = j["why_invalid"].get<std::string>();
    c.monotone = j["monotone"].get<bool>();
    c.converged = j["converged"].get<bool>();
    c.unique = j["unique"].get<bool>();
    c.spectral_radius = exact(j["spectral_radius"]);
    c.worst_increase = exact(j["worst_increase"]);
    c.rate = exact(j["rate"]);
    c.tie.samples = j["tie_samples"].get<int>();
    c.tie.worst_statics = exact(j["tie_statics"]);
    c.tie.worst_wrench = exact(j["tie_wrench"]);
    c.tie.failure = j["tie_failure"].get<std::string>();
    return c;
}

int cmd_proofs(const ProofsArgs& a, Io& cio) {
    const std::uint64_t seed = a.seed;
    const int threads = a.threads;
    // Under mpirun the contraction cases (the bulk of the work) are shared over the ranks, one at a
    // time; the summary is the single-process one to the bit (but for its wall time). Rank 0 alone
    // checks the limit surfaces and A and writes the output.
    sweep::Farm* const farm = launched_farm(cio, threads);
    const bool root = !farm || farm->root();
    nlohmann::json j;
    j["seed"] = seed;
    auto campaign = [&](bool thin, int n, std::uint64_t s0) {
        proofs::ContractionOptions o;
        o.cases = n;
        o.seed = s0;
        o.thin = thin;
        o.threads = threads;
        ProgressPrinter prog{thin ? "proofs, thin parts" : "proofs, thick parts", 10.0};
        if (!root) prog.to = nullptr;
        o.progress = prog;
        if (!farm) return contraction_json(proofs::check_contraction(o));
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<proofs::ContractionCase> cases(static_cast<std::size_t>(n));
        std::vector<int> todo;
        for (int k = 0; root && k < n; ++k) todo.push_back(k);
        int done = 0;
        farm->run(todo, [&](int k) { return case_text(proofs::contraction_random_case(o, k)); },
                  [&](int k, const std::string& text) {
                      cases[static_cast<std::size_t>(k)] = case_from_text(text);
                      prog(++done, n);
                  });
        if (!root) return nlohmann::json();
        return contraction_json(proofs::summarize_contraction(
            o, std::move(cases), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
    };
    j["thin"] = campaign(true, a.thin, seed);
    j["thick"] = campaign(false, a.thick, seed + 50'000'000);
    if (!root) return 0;
    if (farm) j["mpi"] = farm->describe();
    // Limit surfaces of random thin parts at random plate times.
    const proofs::LimitSurfaceCampaign ls =
        proofs::check_limit_surfaces(a.surfaces, seed);
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
    write_file_atomic(a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    return 0;
}

// ---- plate design --------------------------------------------------------------------------

nlohmann::json complex_json(const std::complex<double>& z) { return {z.real(), z.imag()}; }

struct DesignArgs : Options {
    std::string scene, out;
    std::vector<std::string> target;
    std::vector<double> limits;
    double period = 0, hold = DesignOptions{}.hold, max_coning = DesignOptions{}.max_coning;
    std::uint64_t seed = 1;
    int threads = 0, starts = DesignOptions{}.starts, evaluations = DesignOptions{}.local_evaluations, harmonics = 0;
    std::string axes;
    explicit DesignArgs(CLI::App* cmd)
        : Options(cmd, "Designs a plate motion for the part of PART_SCENE (its plate block is ignored but for its period)\n"
                       "and verifies it before reporting. Targets:\n"
                       "  sink X Y          point part: the unique stable fixed point of the velocity field at (X, Y);\n"
                       "                    rigid part: its position ends at (X, Y) whatever its orientation (left free)\n"
                       "  fixed-point X Y THETA  rigid part: (X, Y, THETA) the unique stable fixed point of the twist field\n"
                       "                    (or, where that is out of reach, the target's basin share and the competing\n"
                       "                    fixed points); point part: fixed-point X Y = sink X Y\n"
                       "  orient THETA      rigid part: every start ends at orientation THETA (position free; a part\n"
                       "                    whose contacts' friction differs: by a plate that only translates)\n"
                       "  line-sink X Y PHI point part: every start ends on the line through (X, Y) along PHI [rad]\n"
                       "  transport VX VY   a uniform velocity (VX, VY) [m/s] over the plate (a rigid part: one friction\n"
                       "                    coefficient; OMEGA, a turn, is refused: see the README)\n"
                       "--limits LIN ANG: the largest amplitude of each harmonic (default 20 m/s^2, 150 rad/s^2); g plus the\n"
                       "vertical acceleration stays above 0.2 g over the plate (a constraint). NLopt COBYLA from --starts\n"
                       "seeded feasible motions (default 4 for sinks and line sinks, 16 otherwise),\n"
                       "--evaluations each (default 400). Verification: the field's fixed points on a 7x7 grid and full\n"
                       "dynamics from 20 seeded random starts; sinks and fixed points also hold: released at rest at the\n"
                       "target, the part is still within 5 mm after --hold seconds (default 120; coning, rx and ry out of\n"
                       "phase, turns the field about the plate's centre, so it limits the coning). --axes and --harmonics\n"
                       "narrow each target's motion family (sinks x, y, rx, ry at n = 1, 3; line sinks y, rx at n = 1;\n"
                       "transport and orienters x, y, z at n = 1, 2; rigid fixed points all six at n = 1, 2): the other\n"
                       "harmonics stay zero. Writes the designed\n"
                       "scene to --out and a JSON summary to stdout; exit 4 (and no scene) if the design fails verification.\n") {
        scene_file(scene, "PART_SCENE");
        words("--target", target, 2, 4, "KIND ...",
              "sink X Y, fixed-point X Y [THETA], orient THETA, line-sink X Y PHI or transport VX VY [OMEGA]; required");
        text("--out", out, "SCENE.json", "the designed scene; required");
        numbers("--limits", limits, 2, 2, "LIN ANG", "the largest harmonic amplitudes (default 20 m/s^2, 150 rad/s^2)");
        number("--period", period, "the plate's period [s]", "the part scene's");
        whole("--seed", seed, 0, 1L << 40, "the seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        whole("--starts", starts, 1, 10000, "seeded starts of the search");
        whole("--evaluations", evaluations, 1, 1'000'000, "evaluations per start");
        number("--hold", hold, "seconds a part released at the target must stay within 5 mm (0: not checked)", "120");
        number("--max-coning", max_coning, "a sink's largest coning rate [rad/s] (negative: from the hold)", "from the hold");
        text("--axes", axes, "x,y,z,rx,ry,rz", "the axes the motion may use (default: the target's own)");
        whole("--harmonics", harmonics, 1, 64, "the highest harmonic n the motion may use (default: the target's own)");
    }
};

int cmd_design(const DesignArgs& a, Io& cio) {
    launched_farm(cio, a.threads);
    const Scene part = scene_arg(a.scene, cio);
    if (!a.has("--target")) throw UsageError("missing --target KIND A B");
    if (!a.has("--out")) throw UsageError("missing --out SCENE.json");
    const std::string kind = a.target[0];
    DesignTarget t;
    std::vector<double> v;
    for (std::size_t i = 1; i < a.target.size(); ++i) v.push_back(parse_num("--target", a.target[i]));
    const std::size_t want = kind == "orient" ? 1 : (kind == "fixed-point" && !part.part.point) || kind == "line-sink" ? 3 : 2;
    const std::string usage = "expected sink X Y, fixed-point X Y (point part) or X Y THETA (rigid part), orient THETA, "
                              "line-sink X Y PHI or transport VX VY [OMEGA]";
    if (v.size() != want && !(kind == "transport" && v.size() == 3)) throw UsageError("--target " + kind + ": " + usage);
    if (kind == "sink" || kind == "fixed-point") {
        t.kind = kind == "sink" ? DesignTargetKind::Sink : DesignTargetKind::FixedPoint;
        t.at = Vec2(v[0], v[1]);
        if (v.size() == 3) t.theta = v[2];
    } else if (kind == "orient") {
        t.kind = DesignTargetKind::Orient;
        t.theta = v[0];
    } else if (kind == "line-sink") {
        t.kind = DesignTargetKind::LineSink;
        t.at = Vec2(v[0], v[1]);
        t.theta = v[2];
    } else if (kind == "transport") {
        t.kind = DesignTargetKind::Transport;
        t.velocity = Vec2(v[0], v[1]);
        if (v.size() == 3) t.omega = v[2];
    } else {
        throw UsageError("--target: " + usage + ", got '" + kind + "'");
    }
    DesignOptions o;
    if (a.has("--limits")) {
        o.lin_limit = a.limits[0];
        o.ang_limit = a.limits[1];
    }
    if (!(o.lin_limit >= 0 && o.ang_limit >= 0 && o.lin_limit <= kMaxAmplitude && o.ang_limit <= kMaxAmplitude))
        throw UsageError("--limits: expected amplitudes from 0 to " + fmt(kMaxAmplitude));
    o.period = a.period;
    if (a.has("--period") && !(o.period >= kPeriodRange[0] && o.period <= kPeriodRange[1]))
        throw UsageError("--period: expected " + fmt(kPeriodRange[0]) + " to " + fmt(kPeriodRange[1]) + " s");
    if (!(a.hold >= 0 && a.hold <= 3600)) throw UsageError("--hold: expected 0 to 3600 s");
    o.hold = a.hold;
    o.max_coning = a.max_coning;   // (any finite number: negative asks for the hold's limit)
    o.seed = a.seed;
    o.threads = a.threads;
    o.starts = a.starts;
    o.local_evaluations = a.evaluations;
    if (a.has("--harmonics")) o.max_harmonic = a.harmonics;
    if (a.has("--axes")) {
        std::istringstream in(a.axes);
        std::string name;
        while (std::getline(in, name, ',')) {
            bool found = false;
            for (int k = 0; k < 6; ++k)
                if (name == axis_name(static_cast<Axis>(k))) {
                    o.axes.push_back(static_cast<Axis>(k));
                    found = true;
                }
            if (!found) throw UsageError("--axes: expected a comma-separated list of x, y, z, rx, ry, rz, got '" + name + "'");
        }
        if (o.axes.empty()) throw UsageError("--axes: expected at least one of x, y, z, rx, ry, rz");
    }
    // Under mpirun the starts, the verification field's planes and the verification runs are shared
    // over the ranks; every rank follows the same path, rank 0 writes.
    if (cio.farm) o.tasks = sweep::farm_tasks(*cio.farm);
    DesignSummary d;
    try {
        d = design(part, t, o);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    if (cio.farm && !cio.farm->root()) return d.verified ? 0 : 4;
    const bool transport = t.kind == DesignTargetKind::Transport, rigid = !part.part.point;
    nlohmann::json j;
    j["target"] = {{"kind", kind}};
    if (transport) j["target"]["velocity"] = {t.velocity.x(), t.velocity.y()};
    else if (t.kind != DesignTargetKind::Orient) j["target"]["at"] = {t.at.x(), t.at.y()};
    if (rigid) j["target"]["theta"] = t.theta;
    if (t.kind == DesignTargetKind::LineSink) j["target"]["direction"] = t.theta;
    if (!o.axes.empty()) {   // (the search's freedom, where narrowed)
        j["axes"] = nlohmann::json::array();
        for (Axis ax : o.axes) j["axes"].push_back(axis_name(ax));
    }
    if (o.max_harmonic > 0) j["max_harmonic"] = o.max_harmonic;
    j["verified"] = d.verified;
    if (!d.verified) j["failure"] = d.failure;
    j["scene"] = a.out;
    const bool line = t.kind == DesignTargetKind::LineSink, rigid_sink = rigid && t.kind == DesignTargetKind::Sink;
    if (!transport) {
        // (a line sink has a line of fixed points, not one: there the flag says the line attracts with no
        // drift along it; a rigid sink's, that the position's field vanishes at the target at every
        // orientation of the grid -- the design's Newton checks, not a search of the grid for other zeros)
        j[line ? "line_attracts" : rigid_sink ? "position_zero_at_target_for_every_orientation" : "unique"] = d.unique;
        j["convergence_rate_per_s"] = d.rate;
        if (t.kind == DesignTargetKind::LineSink)   // (the grid's largest speed along the line, and its bound)
            j["speed_along_line"] = {{"largest_on_grid", d.transport_spread}, {"tolerance", d.transport_tolerance}};
        if (t.kind == DesignTargetKind::Orient) {
            // (position free: the orientation, and the velocity the part travels at there)
            j["orientation"] = d.fixed_point[2];
            j["velocity_at_orientation"] = {d.transport_mean.x(), d.transport_mean.y()};
        }
        if (rigid && t.kind == DesignTargetKind::Sink) {
            // (the orientation is free: where the position's field vanishes at each orientation)
            nlohmann::json pulls = nlohmann::json::array();
            for (const auto& p : d.pulls)
                pulls.push_back({{"theta", p.theta}, {"position_zero", {p.zero.x(), p.zero.y()}},
                                 {"eigenvalues", {complex_json(p.eigenvalues[0]), complex_json(p.eigenvalues[1])}}});
            j["position_pull_per_orientation"] = pulls;
        } else if (rigid) {
            j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1], d.fixed_point[2]};
            j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]),
                                            complex_json(d.fixed_point_eigenvalues[1]),
                                            complex_json(d.fixed_point_eigenvalues[2])};
            j["basin_share"] = d.basin_share;
            if (d.basin_share_bound < 1) j["basin_share_bound"] = d.basin_share_bound;
            nlohmann::json comp = nlohmann::json::array();
            for (const auto& c : d.competitors)
                comp.push_back({{"at", {c.point.q[0], c.point.q[1], c.point.q[2]}},
                                {"eigenvalues", {complex_json(c.point.eigenvalues[0]), complex_json(c.point.eigenvalues[1]),
                                                 complex_json(c.point.eigenvalues[2])}},
                                {"basin_share", c.basin_share}});
            j["competing_fixed_points"] = comp;
        } else if (!line) {
            j["fixed_point"] = {d.fixed_point[0], d.fixed_point[1]};
            j["fixed_point_eigenvalues"] = {complex_json(d.fixed_point_eigenvalues[0]), complex_json(d.fixed_point_eigenvalues[1])};
        }
        if (!rigid_sink) j["fixed_points_on_grid"] = fixed_points_sentence(d.fixed_points);   // (no grid search for those)
    } else {
        j["mean_velocity"] = {d.transport_mean.x(), d.transport_mean.y()};
        if (rigid) j["largest_turn_rate"] = d.transport_turn;   // (theta' on the grid, rad/s)
        j["spread"] = d.transport_spread;
        j["tolerance"] = d.transport_tolerance;
    }
    nlohmann::json runs = nlohmann::json::array();
    for (const DesignStartRun& r : d.runs) {
        nlohmann::json x = {{"start", rigid ? nlohmann::json{r.x, r.y, r.theta} : nlohmann::json{r.x, r.y}},
                            {"end", rigid ? nlohmann::json{r.end[0], r.end[1], r.end[2]} : nlohmann::json{r.end[0], r.end[1]}},
                            {"seconds", r.seconds}, {"end_distance", r.end_distance}};
        if (r.from > 0) {   // (transport: judged over [from, seconds])
            x["from"] = r.from;
            x["at_from"] = nlohmann::json{r.at_from[0], r.at_from[1]};
        }
        if (!r.stop.empty()) x["stop"] = r.stop;
        runs.push_back(x);
    }
    j["full_dynamics_runs"] = runs;
    j["worst_end_distance"] = d.worst_end_distance;
    if (d.held.seconds > 0) {   // (sinks and fixed points)
        const DesignStartRun& h = d.held;
        nlohmann::json x = {{"seconds", h.seconds}, {"end_distance", h.end_distance},
                            {"end", rigid ? nlohmann::json{h.end[0], h.end[1], h.end[2]} : nlohmann::json{h.end[0], h.end[1]}}};
        if (!h.stop.empty()) x["stop"] = h.stop;
        j["hold"] = x;
    }
    j["coning_rate"] = d.coning;
    j["min_vertical_acceleration_margin_over_g"] = d.min_vertical_margin;
    j["limits"] = {o.lin_limit, o.ang_limit};
    j["starts"] = d.starts;
    j["evaluations"] = d.evaluations;
    j["limit_cycles"] = d.cycles;
    j["seconds"] = d.seconds;
    j["notes"] = d.notes;
    if (d.verified) {
        write_file_atomic(a.out, [&](std::ostream& out) { out << scene_to_json(d.scene).dump(2) << "\n"; });
        for (const std::string& w : scene_warnings(d.scene)) cio.err << "warning: designed scene: " << w << "\n";
    }
    cio.out << j.dump(2) << std::endl;
    if (!d.verified) {
        cio.err << "plate design: " << a.scene << ": the design failed verification: " << d.failure << " (no scene written)"
                << std::endl;
        return 4;
    }
    if (rigid && t.kind == DesignTargetKind::FixedPoint && !d.unique) {   // (verified, but say it plainly)
        cio.err << "plate design: " << a.scene << ": not unique: the target holds " << d.basin_share
                << " of the random starts";
        for (const auto& c : d.competitors)
            cio.err << "; a stable fixed point at (" << c.point.q[0] << ", " << c.point.q[1] << ", " << c.point.q[2]
                    << ") holds " << c.basin_share;
        cio.err << std::endl;
    }
    return 0;
}


// ---- plate sweep ---------------------------------------------------------------------------

struct SweepArgs : Options {
    std::string campaign, out;
    int threads = 0;
    explicit SweepArgs(CLI::App* cmd)
        : Options(cmd, "Runs a campaign (see campaigns/ and sweep/include/plate/sweep.hpp): one case per parameter\n"
                       "value set, each computing what the campaign asks (twists, a field summary, fixed points,\n"
                       "a design). Every finished case is appended to DIR/journal.jsonl and fsync'd: a killed run\n"
                       "loses only the cases in flight, and the same command resumes it. When every case is done:\n"
                       "DIR/table.csv and DIR/table.jsonl (one row per case, full precision; a failed case has\n"
                       "status failed and its reason), DIR/timing.csv and DIR/summary.svg. Under `mpirun -np N` the\n"
                       "cases are shared over the ranks (one at a time, as workers free up), --threads each; the\n"
                       "table is the same, bit for bit. A JSON summary goes to stdout.\n") {
        scene_file(campaign, "CAMPAIGN");
        text("--out", out, "DIR", "the campaign's folder; required");
        whole("--threads", threads, 0, 256, "threads (per MPI rank; 0: the cores over the node's ranks)");
    }
};

int cmd_sweep(const SweepArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    std::unique_ptr<sweep::Farm> farm;
    if (sweep::mpi_launched()) {
        if (!sweep::mpi_built())
            throw UsageError("started by an MPI launcher with several ranks, but this plate was built without MPI: "
                             "every process would run the whole campaign (rebuild with libopenmpi-dev, or run it alone)");
        farm = sweep::mpi_farm(a.threads);
    } else {
        farm = sweep::thread_farm(a.threads);
    }
    sweep::SweepOptions o;
    o.out = a.out;
    ProgressPrinter prog{"sweep"};
    prog.to = farm->root() && &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    o.progress = std::ref(prog);
    sweep::SweepSummary s;
    try {
        s = sweep::run_sweep(a.campaign, o, *farm);
    } catch (const sweep::Reported&) {   // bad input, which rank 0 reports; every rank returns 2, rank 0
        farm->barrier();                  // first (the launcher ends the job at the first failed rank)
        return 2;
    } catch (const InputError& e) {
        cio.err << "plate sweep: " << e.what() << std::endl;
        farm->barrier();
        return 2;
    } catch (const std::exception& e) {
        cio.err << "plate sweep: error on rank " << farm->rank() << ": " << e.what() << std::endl;
        farm->abort(1);
        return 1;
    }
    if (!farm->root()) return 0;
    nlohmann::json j = {{"campaign", a.campaign},
                        {"out", a.out},
                        {"cases", s.cases},
                        {"resumed", s.resumed},
                        {"computed", s.computed},
                        {"failed", s.failed},
                        {"torn_journal_lines_dropped", s.torn},
                        {"seconds", s.seconds},
                        {"busy_seconds", s.busy_seconds},
                        {"workers", s.workers},
                        {"farm", s.farm},
                        {"load_balance_efficiency", s.computed && s.seconds > 0 ? s.busy_seconds / (s.seconds * s.workers) : 0.0},
                        {"tables", {a.out + "/table.csv", a.out + "/table.jsonl"}}};
    cio.out << j.dump(2) << std::endl;
    return 0;
}

// ---- plate report, plate bench -------------------------------------------------------------

struct ReportArgs : Options {
    std::string out, source;
    std::uint64_t seed = 1;
    int threads = 0;
    bool quick = false;
    std::vector<std::string> sections;
    explicit ReportArgs(CLI::App* cmd)
        : Options(cmd, "Writes DIR/index.html and its figures: the derivation and its findings, kernel equivalence,\n"
                       "Theorem 1 checks (10^4 thin, 10^3 thick parts; --quick: a few), limit surfaces, Fig. 3, and the\n"
                       "paper's fields with full-dynamics trajectories and fixed-point tables. ROOT: the project folder\n"
                       "(scenes/, reports/generated/), default the one this program was built from. --sections\n"
                       "computes only the named ones (derivation kernels proofs fig3 fields design orient fixed-point;\n"
                       "the page names those left out).\n") {
        text("--out", out, "DIR", "the report's folder; required");
        flag("--quick", quick, "small campaigns and grids");
        words("--sections", sections, 1, 8, "NAME ...", "only these sections (default all)");
        whole("--seed", seed, 0, 1L << 40, "the seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        text("--source", source, "ROOT", "the project folder");
    }
};

int cmd_report(const ReportArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    report::ReportOptions o;
    o.out = a.out;
    o.source_dir = a.has("--source") ? a.source : data_root();
    o.seed = a.seed;
    o.quick = a.quick;
    o.threads = a.threads;
    try {
        report::check_sections(a.sections);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--sections: ") + e.what());
    }
    o.sections = a.sections;
    report::write_report(o);
    cio.err << "report: " << o.out << "/index.html" << std::endl;
    return 0;
}

struct BenchArgs : Options {
    std::string out, source;
    bool full = false, peers = false;
    explicit BenchArgs(CLI::App* cmd)
        : Options(cmd, "The speed-accuracy study: work-precision charts (every method and friction treatment on (a) an\n"
                       "asymptotic twist of fig4, (b) fig4's 20 s full-dynamics trajectory, (c) a near-sticking twist of\n"
                       "fig6) against reference solutions; the limit-cycle solvers on fig4's field against period-by-\n"
                       "period RK4; failure maps; the model hierarchy. Writes the charts into DIR and the section into\n"
                       "DIR/index.html (the report's page if `plate report --out DIR` wrote one). Quick by default\n"
                       "(minutes); --full sweeps more settings. --peers: instead, Bullet, ODE and MuJoCo beside plate on\n"
                       "the same questions (the engines found at build time; quick unless --full).\n") {
        text("--out", out, "DIR", "the report's folder; required");
        flag("--full", full, "the long campaign");
        flag("--peers", peers, "instead: Bullet, ODE and MuJoCo beside plate (bench/peers/study.py, the engines this build found)");
        text("--source", source, "ROOT", "the project folder (default: the one this program was built from)");
    }
};

int cmd_bench(const BenchArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    if (a.peers) {
        // The peers study runs the engines' program built beside this one (bench/peers), charted by
        // its script: both live in the build tree, so an installed plate has no peers.
        std::error_code ec;
        const std::filesystem::path dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
        const std::string source = a.has("--source") ? a.source : std::string(PLATE_SOURCE_DIR);
        if (ec || !std::filesystem::exists(dir / "bench_peers"))
            throw UsageError("--peers: no bench_peers beside this plate (no peer engine was found when it was built: "
                             "install libbullet-dev, libode-dev or libmujoco-dev and rebuild)");
        auto quote = [](const std::string& x) {   // for the shell, quotes and all
            std::string q = "'";
            for (char ch : x) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
            return q + "'";
        };
        const std::string cmd = "/usr/bin/python3 " + quote(source + "/bench/peers/study.py") + " --out " + quote(a.out) +
                                " --build " + quote(dir.string()) + (a.full ? "" : " --quick");
        const int rc = std::system(cmd.c_str());
        if (rc != 0) throw std::runtime_error("the peers study failed (" + cmd + ")");
        cio.err << "bench: " << a.out << "/index.html (peers)" << std::endl;
        return 0;
    }
    report::SpeedOptions o;
    o.out = a.out;
    o.source_dir = a.has("--source") ? a.source : data_root();
    o.full = a.full;
    report::write_speed_study(o);
    cio.err << "bench: " << o.out << "/index.html" << std::endl;
    return 0;
}

}  // namespace

int run(int argc, char** argv, std::ostream& out, std::ostream& err) {
    Io cio{out, err, nullptr};
    CLI::App app{kAbout, "plate"};
    app.get_formatter()->label("Usage", "usage");   // (as before: the help says "usage: plate ...")
    app.get_formatter()->label("SUBCOMMAND", "COMMAND");
    app.footer(kFooter);
    app.set_version_flag("--version", [] {
        return "plate " PLATE_VERSION " (scenes and report inputs: " + data_root() + ")";
    });
    app.require_subcommand(1);
    app.allow_extras();   // (and so every command) what is left over is judged by Options::reject
    auto command = [&app](const char* name, const char* about) { return app.add_subcommand(name, about); };
    TwistArgs twist(command("twist", "asymptotic twist (36) at one configuration, as JSON"));
    FieldArgs field(command("field", "asymptotic twist field on a grid over (s_x, s_y, theta), JSON or CSV"));
    FixedPointsArgs fixed_points(
        command("fixed-points", "zeros of the field, refined and classified (stable, unstable, saddle; lines)"));
    SimulateArgs simulate(command("simulate", "U-dynamics, full-dynamics or field-integral-curve trajectory, CSV"));
    RandomSceneArgs random_scene(
        command("random-scene", "a seeded random part and plate motion (like Fig. 3), as a scene file"));
    ProofsArgs proofs(
        command("proofs", "the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON"));
    ReportArgs report(command("report", "the verification report: DIR/index.html with SVG figures (gnuplot)"));
    BenchArgs bench(
        command("bench", "the speed-accuracy study, written into the report in DIR (--full: the long campaign)"));
    DesignArgs design(
        command("design", "the plate motion that sends a part where wanted: a sink, fixed point, orientation or transport, verified"));
    SweepArgs sweep_cmd(command("sweep", "a campaign over parameters (resumable; shared over mpirun ranks), a table per case"));
    const std::pair<const Options*, std::function<int()>> commands[] = {
        {&twist, [&] { return cmd_twist(twist, cio); }},
        {&field, [&] { return cmd_field(field, cio); }},
        {&fixed_points, [&] { return cmd_fixed_points(fixed_points, cio); }},
        {&simulate, [&] { return cmd_simulate(simulate, cio); }},
        {&random_scene, [&] { return cmd_random_scene(random_scene, cio); }},
        {&proofs, [&] { return cmd_proofs(proofs, cio); }},
        {&report, [&] { return cmd_report(report, cio); }},
        {&bench, [&] { return cmd_bench(bench, cio); }},
        {&design, [&] { return cmd_design(design, cio); }},
        {&sweep_cmd, [&] { return cmd_sweep(sweep_cmd, cio); }},
    };

    if (argc < 2) {
        cio.out << app.help();
        return 2;
    }
    const std::string cmd = argv[1];
    const bool known = !app.get_subcommands([&](const CLI::App* c) { return c->get_name() == cmd; }).empty();
    if (!known && cmd != "--help" && cmd != "-h" && cmd != "--version") {
        cio.err << "plate: unknown command '" << cmd << "'\n" << app.help();
        return 2;
    }
    // An error's exit code (2: bad input or usage, 1: anything else), reported on stderr if `print`.
    auto fail = [&](const std::exception_ptr& ep, bool print) -> int {
        std::ostringstream msg;
        int code = 1;
        try {
            std::rethrow_exception(ep);
        } catch (const CLI::ParseError& e) {
            if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success))   // --help, --version
                return app.exit(e, cio.out, cio.err);
            msg << e.what() << " (see plate " << cmd << " --help)";
            code = 2;
        } catch (const InputError& e) {
            msg << e.what();
            code = 2;
        } catch (const UsageError& e) {
            msg << e.what() << " (see plate " << cmd << " --help)";
            code = 2;
        } catch (const std::exception& e) {
            msg << "error: " << e.what();
        }
        if (print) cio.err << "plate " << cmd << ": " << msg.str() << std::endl;
        return code;
    };
    try {
        app.parse(argc, argv);
        for (const auto& [options, run_command] : commands) {
            if (!options->given()) continue;
            options->reject(app.remaining(true));
            return run_command();
        }
        return 0;   // (not reached: a command is required)
    } catch (...) {
        const std::exception_ptr ep = std::current_exception();
        // (an error before the command joined its ranks, e.g. in its scene, meets every rank alike:
        // they join now to report it once)
        if (!cio.farm && sweep::mpi_launched() && sweep::mpi_built() && fail(ep, false) == 2) cio.farm = sweep::mpi_farm(1);
        if (!cio.farm || cio.farm->ranks() == 1) return fail(ep, true);
        // Under mpirun every rank meets the same bad input: rank 0 reports it, and every rank waits
        // for that before returning 2 (the launcher ends the job at the first rank that fails). Any
        // other error is one rank's: it says which, and ends every rank.
        if (fail(ep, false) == 2) {
            if (cio.farm->root()) fail(ep, true);
            cio.farm->barrier();
            return 2;
        }
        try {
            std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            cio.err << "plate " << cmd << ": error on rank " << cio.farm->rank() << ": " << e.what() << std::endl;
        } catch (...) {
            cio.err << "plate " << cmd << ": error on rank " << cio.farm->rank() << std::endl;
        }
        cio.farm->abort(1);
        return 1;
    }
}

}  // namespace plate::cli
