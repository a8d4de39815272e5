// The shared layer of the plate command line: what more than one command (apps/commands/) uses.
// Read top to bottom: where a command writes (Io), its errors, the rules for values, the Options
// class every command's arguments derive from, the scene and configuration arguments, the options
// of the limit cycle and the grid, and the work budgets of a field under its MPI ranks.
// Nothing here writes help of its own but the per-option lines Options adds: every command's
// text lives in its file.
#pragma once

#include "plate/farm.hpp"
#include "plate/field.hpp"
#include "plate/scene_io.hpp"

#include <cstddef>
#include <functional>
#include <memory>
#include <ostream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace plate::cli {

// ---- where a command writes --------------------------------------------------------------------

// A command's output streams (run()'s `out` and `err`), and the MPI ranks of a command started under
// mpirun (plate field, fixed-points, design, proofs): held here so that it outlives an exception
// from the command, whose report run() coordinates.
struct Io {
    std::ostream& out;
    std::ostream& err;
    std::unique_ptr<sweep::Farm> farm;
};

// ---- errors and values -------------------------------------------------------------------------

// A bad command line: run() reports it with "(see plate COMMAND --help)" and exit code 2. (A bad
// input file is plate::InputError, scene_io.hpp: exit code 2, no pointer to the help.)
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Option k's value `s` as a finite number, all of the text ("nan", "inf", "1e999", "" and "3x" are
// refused with a UsageError naming k).
double parse_num(const std::string& k, const std::string& s);

// Option k's value `s` as a whole number from lo to hi, all of the text: base 10, or a whole number
// in exponent form (2e7, as the help writes budgets).
long parse_whole(const std::string& k, const std::string& s, long lo, long hi);

// x with three significant digits, for the numbers in messages (estimates, budgets, limits).
std::string fmt(double x);

// The folder with scenes/ (the report's inputs): an installed program's PREFIX/share/plate beside
// PREFIX/bin, else the source tree it was built from (relocatable: nothing else is compiled in).
std::string data_root();

// ---- a command's options -----------------------------------------------------------------------

// CLI11 splits the arguments into a command, its options and their values, finds unknown
// options and writes the help. The rules for values are ours, and every message names the option.
//
// The options of one command, declared on its CLI11 subcommand into the command's variables
// (which hold the defaults). Each option reaches its callback once per occurrence, as it is
// parsed (trigger_on_parse): a second occurrence is refused there (CLI11's Throw policy counts
// values, not occurrences, so `--at 0 0 --at 1` would pass as three numbers), and the text is
// converted by the rules above. A command's arguments derive from it (apps/commands/).
class Options {
public:
    // Adds the command `name` to `app`, with `about` its line in `plate --help` and `footer` the
    // text under its options in `plate NAME --help`.
    Options(CLI::App& app, const std::string& name, const std::string& about, const std::string& footer);
    Options(const Options&) = delete;   // the callbacks hold `this`
    Options& operator=(const Options&) = delete;
    virtual ~Options() = default;   // (held as Options by the command table, apps/commands/commands.hpp)

    // Whether this is the command run.
    bool given() const;
    // Whether option `name` was given.
    bool has(const std::string& name) const { return seen_.count(name) > 0; }

    // What CLI11 could not place (the app allows extras so that the messages are ours): an
    // unknown option, or an argument beyond SCENE. Throws a UsageError; returns if none.
    void reject(const std::vector<std::string>& leftovers) const;

    // The command's positional file argument, `name` in the help (SCENE, PART_SCENE, CAMPAIGN): required.
    // `what` says what the file is, in the help.
    void scene_file(std::string& file, const std::string& name = "SCENE",
                    const std::string& what = "the scene file (JSON, see scenes/)");
    // A finite number. The help shows the default: `def`, or else x's value; none if def is "".
    void number(const std::string& name, double& x, const std::string& help, const char* def = nullptr);
    // A whole number from lo to hi (int, long or std::uint64_t); the help shows the range and the
    // default: `def`, or else x's value.
    template <class Int>
    void whole(const std::string& name, Int& x, long lo, long hi, const std::string& help, const char* def = nullptr) {
        const std::string range = std::to_string(lo) + " to " + std::to_string(hi);
        add(name, "N", help + in_parentheses(range, def ? def : std::to_string(x)),
            [name, &x, lo, hi](const std::string& s) { x = static_cast<Int>(parse_whole(name, s, lo, hi)); });
    }
    // lo to hi numbers (`names` in the help); how many a part takes is checked where that is known (config_arg).
    void numbers(const std::string& name, std::vector<double>& v, std::size_t lo, std::size_t hi, const std::string& names,
                 const std::string& help);
    // Exactly n words.
    void words(const std::string& name, std::vector<std::string>& v, std::size_t n, const std::string& names,
               const std::string& help);
    // From lo to hi words.
    void words(const std::string& name, std::vector<std::string>& v, std::size_t lo, std::size_t hi, const std::string& names,
               const std::string& help);
    // One word of any text (`value` in the help: FILE, DIR, NAME, json|csv ...).
    void text(const std::string& name, std::string& s, const std::string& value, const std::string& help);
    // A flag: b becomes true when given.
    void flag(const std::string& name, bool& b, const std::string& help);
    // `old_name`, an old spelling of option `name` (declared before, as numbers or words): it does what
    // `name` does, is left out of the help and leaves a deprecation notice (notices()). Old spellings are
    // kept for one release (issue 54: one vocabulary). Giving both is giving `name` twice.
    void deprecated(const std::string& old_name, const std::string& name);
    // An option this command accepts for old scripts (one word, any value) but does not use: left out
    // of the help, it leaves a notice that it is not used and goes in the next release.
    void unused(const std::string& name);
    // The deprecation notices of the old spellings and unused options given, for the error stream.
    const std::vector<std::string>& notices() const { return notices_; }

private:
    // An option taking one value, passed to `store` as parsed.
    void add(const std::string& name, const std::string& names, const std::string& help,
             std::function<void(const std::string&)> store);
    // An option taking 1 to max_values values, passed to `store` together.
    void add(const std::string& name, int max_values, const std::string& names, const std::string& help,
             std::function<void(const std::vector<std::string>&)> store);
    // Refuses a second occurrence of option `name`.
    void once(const std::string& name);
    // " (RANGE; default DEF)", without what is empty.
    static std::string in_parentheses(const std::string& range, const std::string& def);

    CLI::App* cmd_;
    std::set<std::string> seen_;
    // Each option taking several values: its most values, its `names` and its store (for deprecated()).
    struct Multi {
        int max_values;
        std::string names;
        std::function<void(const std::vector<std::string>&)> store;
    };
    std::map<std::string, Multi> multi_;
    std::map<std::string, std::string> old_names_;   // an option's deprecated spelling, for messages
    std::vector<std::string> notices_;
    bool takes_scene_ = false;
    std::string file_name_ = "SCENE";   // the positional file's name in the help and in messages
};

// ---- the scene and a configuration -------------------------------------------------------------

// The whole text of an input file (`what` names it in the error: "FILE: cannot open WHAT", an
// InputError). Under mpirun (cio.farm) rank 0 reads it and sends it to every rank (the others may not
// see the file: nodes without a shared filesystem), so every rank has the same text or the same error.
std::string input_text(const std::string& file, const std::string& what, Io& cio);

// The scene of a command; its warnings (scene_warnings: admissible, outside the intended regime) to
// err. Under mpirun (cio.farm) rank 0 reads the file and sends its text to every rank (the others may
// not see the file: nodes without a shared filesystem), so that every rank has the same scene or
// the same error, and only rank 0 prints warnings.
Scene scene_arg(const std::string& file, Io& cio);

// A measured cycle in place of the scene's plate motion (issue 51; measured_cycle.hpp): --measured
// CYCLE.csv --harmonics N, both or neither.
struct MeasuredArgs {
    std::string file;
    int harmonics = 0;
};
// Declares --measured and --harmonics on a command.
void add_measured_options(Options& p, MeasuredArgs& m);
// `sc` with its plate motion replaced by the measured cycle's harmonics 1..N when --measured is given
// (its warnings to err; read as the scene is under mpirun, by rank 0 and sent to every rank); else sc.
Scene measured_arg(const Options& a, const MeasuredArgs& m, Scene sc, Io& cio);

// --NAME's numbers (`v`, given or not, option k of `a`): 3 for a rigid part, 2 for a point part; zero
// when not given and not required.
Vec3 config_arg(const Options& a, const std::string& k, const std::vector<double>& v, const Scene& sc, bool required);

// ---- the limit cycle's and the grid's options (twist, field, fixed-points) ---------------------

// The command line's budget per cycle is tighter than the library's (2e7, for tight references):
// 2e6 right-hand sides (--max-rhs), about 0.3 s; the shipped scenes' field cycles take at most ~6e4
// at the default tolerances.
constexpr long kCliCycleBudget = 2'000'000;

// The limit cycle's options as given (--tol, --rtol, --max-periods, --max-rhs, --cycle-solver).
struct CycleArgs {
    LimitCycleOptions o = [] {
        LimitCycleOptions o;
        o.max_rhs_evaluations = kCliCycleBudget;
        return o;
    }();
    std::string solver;
};
// Declares the cycle's options on a command.
void add_cycle_options(Options& p, CycleArgs& c);
// The cycle's options, checked (UsageError: an unknown solver, --tol <= 0, --rtol outside (0, 1e-2)).
LimitCycleOptions cycle_opts(const Options& a, const CycleArgs& c);

// The grid's options as given (--grid, --nx, --ny, --ntheta, --x, --y, --theta0, --threads).
struct GridArgs {
    int n = 7;
    GridSpec g;
    std::vector<double> x, y;
    int threads = 0;
};
// Declares the grid's options on a command.
void add_grid_options(Options& p, GridArgs& a);
// The grid: --nx, --ny, --ntheta default to --grid; MIN <= MAX checked.
GridSpec grid_opts(const Options& a, const GridArgs& ga);

// ---- work budgets and MPI ranks (field, fixed-points, design, proofs) --------------------------

// The largest --max-work of a field.
constexpr long kMaxWorkLimit = 1'000'000'000'000'000L;

// Bounded work for a field: the library's estimate (field.hpp, require_field_work) against --max-work
// (default kDefaultFieldWork); a field estimated over it is refused with the estimate (UsageError).
// Returns the budget, which also holds while the field runs (require_within_budget).
long check_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& lo, long budget);

// A field whose budget ran out while it was computed (the estimate was low) is not a result: throws.
void require_within_budget(const Field& f, long budget);

// Under an MPI launcher with several ranks: the ranks (`threads` each), held in cio.farm; else null
// (one process). A plate built without MPI under such a launcher: a UsageError.
sweep::Farm* launched_farm(Io& cio, int threads);

// The field of `field` and `fixed-points`: its work estimated up front against `max_work`, progress
// on a terminal, and refused if the budget was spent anyway. Under mpirun (cio.farm) its planes are
// shared over the ranks and every rank returns the whole field, the same as one process computes.
Field bounded_field(const Scene& sc, const GridSpec& g, const LimitCycleOptions& cycle, int threads, long max_work, Io& cio);

}   // namespace plate::cli
