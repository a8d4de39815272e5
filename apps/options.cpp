// The shared layer of the plate command line: see options.hpp.
#include "options.hpp"

#include "plate/measured_cycle.hpp"

#include "plate/output.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

namespace plate::cli {

// ---- errors and values -------------------------------------------------------------------------

double parse_num(const std::string& k, const std::string& s) {
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(x))
        throw UsageError("option " + k + ": expected a finite number, got '" + s + "'");
    return x;
}

long parse_whole(const std::string& k, const std::string& s, long lo, long hi) {
    char* end = nullptr;
    long x = std::strtol(s.c_str(), &end, 10);
    if (!s.empty() && (*end == 'e' || *end == 'E')) {   // 2e7: a whole number in exponent form, as the help writes budgets
        const double d = std::strtod(s.c_str(), &end);
        const bool whole = *end == '\0' && std::isfinite(d) && d == std::floor(d) && std::abs(d) <= 9.007199254740992e15;
        x = whole ? static_cast<long>(d) : lo - 1;
    }
    if (s.empty() || *end != '\0' || x < lo || x > hi)
        throw UsageError("option " + k + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                         ", got '" + s + "'");
    return x;
}

std::string fmt(double x) {
    std::ostringstream s;
    s.precision(3);
    s << x;
    return s.str();
}

std::string data_root() {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const std::filesystem::path share = exe.parent_path().parent_path() / "share" / "plate";
        if (std::filesystem::exists(share / "scenes", ec)) return share.string();
    }
    return PLATE_SOURCE_DIR;
}

// ---- a command's options -----------------------------------------------------------------------

Options::Options(CLI::App& app, const std::string& name, const std::string& about, const std::string& footer)
    : cmd_(app.add_subcommand(name, about)) {
    cmd_->group("commands")->footer(footer);
}

bool Options::given() const { return cmd_->parsed(); }

void Options::reject(const std::vector<std::string>& leftovers) const {
    for (const std::string& s : leftovers) {
        char* end = nullptr;
        std::strtod(s.c_str(), &end);
        if (s.size() > 1 && s[0] == '-' && *end != '\0') throw UsageError("unknown option " + s);
    }
    if (leftovers.empty()) return;
    throw UsageError(takes_scene_ ? "expected exactly one " + file_name_ + " file"
                                  : cmd_->get_name() + " takes no SCENE argument");
}

void Options::scene_file(std::string& file, const std::string& name, const std::string& what) {
    takes_scene_ = true;
    file_name_ = name;
    cmd_->add_option(name, file, what)->required()->option_text(" ");
}

void Options::number(const std::string& name, double& x, const std::string& help, const char* def) {
    std::ostringstream value;
    value << x;
    add(name, "X", help + in_parentheses("", def ? def : value.str()),
        [name, &x](const std::string& s) { x = parse_num(name, s); });
}

void Options::numbers(const std::string& name, std::vector<double>& v, std::size_t lo, std::size_t hi, const std::string& names,
                      const std::string& help) {
    const std::string count = std::to_string(lo) + (lo < hi ? " or " + std::to_string(hi) : "");
    add(name, static_cast<int>(hi), names, help, [name, &v, lo, hi, count](const std::vector<std::string>& s) {
        if (s.size() < lo || s.size() > hi) throw UsageError(name + ": expected " + count + " numbers");
        v.clear();
        for (const std::string& x : s) v.push_back(parse_num(name, x));
    });
}

void Options::words(const std::string& name, std::vector<std::string>& v, std::size_t n, const std::string& names,
                    const std::string& help) {
    add(name, static_cast<int>(n), names, help, [name, &v, n](const std::vector<std::string>& s) {
        if (s.size() != n) throw UsageError("option " + name + " expects " + std::to_string(n) + " value(s)");
        v = s;
    });
}

void Options::words(const std::string& name, std::vector<std::string>& v, std::size_t lo, std::size_t hi,
                    const std::string& names, const std::string& help) {
    add(name, static_cast<int>(hi), names, help, [name, &v, lo, hi](const std::vector<std::string>& s) {
        if (s.size() < lo || s.size() > hi)
            throw UsageError("option " + name + " expects " + std::to_string(lo) + " to " + std::to_string(hi) + " values");
        v = s;
    });
}

void Options::text(const std::string& name, std::string& s, const std::string& value, const std::string& help) {
    add(name, value, help, [&s](const std::string& t) { s = t; });
}

void Options::flag(const std::string& name, bool& b, const std::string& help) {
    cmd_->add_flag_function(
            name,
            [this, name, &b](std::int64_t) {
                once(name);
                b = true;
            },
            help)
        ->disable_flag_override()
        ->trigger_on_parse();
}

namespace {

// Declares option `name` of `cmd`, taking 1 to max_values values of type T (std::string or a vector
// of them), each occurrence passed through `once` to `store` as it is parsed.
template <class T>
void add_option(CLI::App* cmd, const std::string& name, int max_values, const std::string& names, const std::string& help,
                std::function<void(const std::string&)> once, std::function<void(const T&)> store) {
    cmd->add_option_function<T>(
           name,
           [name, once, store](const T& v) {
               once(name);
               store(v);
           },
           help)
        ->expected(1, max_values)
        ->allow_extra_args(false)   // (a vector's default: eat every value that follows)
        ->option_text(names)
        ->type_name(names.substr(0, names.find(' ')))   // "--at: 1 required SX missing"
        ->trigger_on_parse();
}

}   // namespace

void Options::add(const std::string& name, const std::string& names, const std::string& help,
                  std::function<void(const std::string&)> store) {
    add_option<std::string>(
        cmd_, name, 1, names, help, [this](const std::string& n) { once(n); }, std::move(store));
}

void Options::add(const std::string& name, int max_values, const std::string& names, const std::string& help,
                  std::function<void(const std::vector<std::string>&)> store) {
    multi_[name] = Multi{max_values, names, store};
    add_option<std::vector<std::string>>(
        cmd_, name, max_values, names, help, [this](const std::string& n) { once(n); }, std::move(store));
}

void Options::unused(const std::string& name) {
    add(name, "X", "", [this, name](const std::string&) {
        notices_.push_back(name + " is not used by this command (accepted for old scripts; refused from the next release)");
    });
    cmd_->get_option(name)->group("");
}

void Options::deprecated(const std::string& old_name, const std::string& name) {
    const auto m = multi_.find(name);
    if (m == multi_.end()) throw std::logic_error("deprecated(" + old_name + ", " + name + "): no such option");
    old_names_[name] = old_name;
    const std::string notice = old_name + " is deprecated: use " + name + " (the old spelling goes in the next release)";
    add_option<std::vector<std::string>>(
        cmd_, old_name, m->second.max_values, m->second.names, "",
        [this, name, notice](const std::string&) {
            once(name);
            notices_.push_back(notice);
        },
        m->second.store);
    cmd_->get_option(old_name)->group("");   // (hidden from the help)
}

void Options::once(const std::string& name) {
    if (seen_.insert(name).second) return;
    const auto old = old_names_.find(name);
    throw UsageError("option " + name + " given twice" +
                     (old == old_names_.end() ? "" : " (" + old->second + " is its old spelling)"));
}

std::string Options::in_parentheses(const std::string& range, const std::string& def) {
    std::string s = range;
    if (!def.empty()) s += (s.empty() ? "default " : "; default ") + def;
    return s.empty() ? s : " (" + s + ")";
}

// ---- the scene and a configuration -------------------------------------------------------------

std::string input_text(const std::string& file, const std::string& what, Io& cio) {
    std::string text;
    if (!cio.farm || cio.farm->root()) {
        std::ifstream in(file, std::ios::binary);
        std::stringstream buf;
        buf << in.rdbuf();
        text = in ? "S" + buf.str() : "E";
    }
    if (cio.farm && cio.farm->ranks() > 1) cio.farm->broadcast(text);
    if (text.empty() || text[0] != 'S') throw InputError(file + ": cannot open " + what);
    return text.substr(1);
}

Scene scene_arg(const std::string& file, Io& cio) {
    const Scene sc = parse_scene(input_text(file, "scene file", cio), file);
    if (!cio.farm || cio.farm->root())
        for (const std::string& w : scene_warnings(sc)) cio.err << "warning: " << w << "\n";
    return sc;
}

void add_measured_options(Options& p, MeasuredArgs& m) {
    p.text("--measured", m.file, "CYCLE.csv", "the plate motion from one measured period (t,x,y,z,rx,ry,rz; with --harmonics)");
    p.whole("--harmonics", m.harmonics, 1, 10'000, "the measured cycle's harmonics kept, 1..N", "none: required with --measured");
}

Scene measured_arg(const Options& a, const MeasuredArgs& m, Scene sc, Io& cio) {
    if (a.has("--measured") != a.has("--harmonics")) throw UsageError("--measured FILE and --harmonics N go together");
    if (!a.has("--measured")) return sc;
    const MeasuredCycle cycle = parse_measured_cycle(input_text(m.file, "measured cycle", cio), m.file, m.harmonics);
    if (!cio.farm || cio.farm->root())
        for (const std::string& w : cycle.warnings) cio.err << "warning: " << m.file << ": " << w << "\n";
    return with_measured_plate(sc, cycle);
}

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

// ---- the limit cycle's and the grid's options --------------------------------------------------

void add_cycle_options(Options& p, CycleArgs& c) {
    p.number("--tol", c.o.tol, "accepted distance to the cycle, relative to the slip-speed scale");
    p.number("--rtol", c.o.integration.rtol, "integrator tolerance, in (0, 1e-2)");
    p.whole("--max-periods", c.o.max_periods, 2, 100000, "periods before the cycle counts as not converged");
    p.whole("--max-rhs", c.o.max_rhs_evaluations, 1000, 1'000'000'000'000L, "work budget of one cycle, right-hand sides");
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

// ---- work budgets and MPI ranks ----------------------------------------------------------------

long check_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& lo, long budget) {
    try {
        require_field_work(sc, g, lo, budget, "--max-work");
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    return budget;
}

void require_within_budget(const Field& f, long budget) {
    if (!f.budget_spent) return;
    int left = 0;
    for (const auto& p : f.points) left += p.stop == StopReason::StepLimit && p.rhs_evals == 0;
    throw std::runtime_error("the work budget of " + fmt(static_cast<double>(budget)) + " right-hand sides was spent with " +
                             std::to_string(left) + " of " + std::to_string(f.points.size()) +
                             " configurations not started (the up-front estimate was low): raise --max-work");
}

sweep::Farm* launched_farm(Io& cio, int threads) {
    if (!sweep::mpi_launched()) return nullptr;
    if (!sweep::mpi_built())
        throw UsageError(
            "started by an MPI launcher with several ranks, but this plate was built without MPI: "
            "every process would do the whole job (rebuild with libopenmpi-dev, or run it alone)");
    cio.farm = sweep::mpi_farm(threads);
    return cio.farm.get();
}

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

}   // namespace plate::cli
