// Campaigns (issue 20): a parameter study over one base scene -- the paper's Fig. 3 at scale.
// A campaign file names the base scene, the parameters to vary (fields of the scene addressed by
// JSON pointers: lists or ranges, Cartesian products or seeded random samples) and what to compute
// per case (the twist at configurations, a field summary, fixed points with their classification,
// a design). `run_sweep` computes every case once, appends each finished case durably to a journal
// (so a killed run loses only the cases in flight and the same command resumes it), and writes the
// table (CSV and JSON lines, one row per case, full precision) and a summary figure when every case
// is done. How the cases are shared out is a Farm's business (farm.hpp: threads, or MPI ranks).
//
// A campaign file:
//   { "name": "fig4_amp_phase",
//     "scene": "../scenes/fig4.json",                       // relative to the campaign file
//     "sampling": "grid" | {"random": N, "seed": S},
//     "parameters": [ {"name": "x_amp", "pointer": "/plate/harmonics/0/amp",
//                      "from": 5, "to": 30, "count": 20}      // a range, end points included
//                   | {"name": "mu", "pointer": "/part/friction", "values": [0.2, 0.3]} ],
//                                                           // random sampling: "from" and "to" only
//     "compute": { "twist_at": [[SX, SY, THETA], ...],      // point parts: [SX, SY]
//                  "field": {"grid": [NX, NY, NTH], "x": [MIN, MAX], "y": [MIN, MAX]},
//                  "fixed_points": true,                    // on the field's grid
//                  "design": {"target": ["sink", X, Y], "starts": 4, "evaluations": 200},  // any
//                           // KIND and numbers --target takes, judged by parse_design_target;
//                           // also "limits": [LIN, ANG], "corner_limits": [DISP, VEL], "plate_half_size":
//                           // [HX, HY] and "seed", as plate design's flags
//                  "cycle": {"tol": 1e-7, "rtol": 1e-8, "max_rhs": 2e6} } }
// A pointer addresses a number of the scene, or an array of numbers, every element of which takes
// the value (/part/friction: every contact's friction). Unknown or missing fields are errors naming
// the file and the field (InputError).
#pragma once

#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::sweep {

using Row = nlohmann::ordered_json;   // one case's results, in column order

struct Parameter {
    std::string name;
    std::string pointer;          // RFC 6901, into the scene file's JSON
    std::vector<double> values;   // grid sampling: the values, in order
    double from = 0, to = 0;      // random sampling: uniform on [from, to]
};

struct Campaign {
    std::string name;
    std::string source;    // the campaign file (for messages)
    nlohmann::json base;   // the base scene, as its file reads
    bool random = false;   // else the Cartesian grid, the first parameter slowest
    int samples = 0;       // random sampling: cases
    std::uint64_t seed = 1;
    std::vector<Parameter> parameters;
    // What each case computes.
    std::vector<Vec3> twist_at;
    bool field = false, fixed_points = false;
    GridSpec grid;
    LimitCycleOptions cycle;
    std::optional<DesignTarget> design;
    DesignOptions design_options;
    nlohmann::json file;   // the campaign, its scene inlined: what every rank computes from

    int cases() const;
};

// Reads a campaign file and its base scene; checks every field, every pointer (it must address a
// number of the base scene) and that the base scene is valid. Throws InputError.
Campaign load_campaign(const std::string& path);
// The same from Campaign::file (what rank 0 sends the others: no file is read).
Campaign campaign_from_json(const nlohmann::json& file, const std::string& source);
// A hash of everything that decides the results (the campaign with its scene): a journal written
// for one campaign is never resumed by another.
std::string fingerprint(const Campaign& c);

// The parameter values of case `index` (grid: mixed radix; random: a generator seeded by the
// campaign's seed and the index alone, so any rank computes any case's values).
std::vector<double> case_values(const Campaign& c, int index);
// The base scene with case `index`'s values put in (throws InputError when they make it invalid).
Scene case_scene(const Campaign& c, int index);
// Computes case `index`. Never throws: a case that fails (its values make the scene invalid, a
// cycle that does not converge, a design that fails verification) gets status "failed" and the
// reason, with whatever was computed. Single-threaded, so the row is the same on every rank.
Row run_case(const Campaign& c, int index);
// The table's columns, in order (run_case's keys; the JSON lines also carry "fixed_points").
std::vector<std::string> columns(const Campaign& c);
// A column's heading in table.csv: its name and unit, "stable_x [m]"; a parameter's unit is the scene
// field's it sets, "x_amp [as /plate/harmonics/0/amp]"; counts, flags and words have no unit.
std::string column_heading(const Campaign& c, const std::string& column);

// ---- the journal: finished cases, appended durably -------------------------------------------
// DIR/journal.jsonl: a header line (campaign name, fingerprint, cases), then one line per finished
// case {"case": i, "rank": r, "seconds": s, "row": {...}}, each written with one write(2) and
// fsync'd before the next case is counted as done. Opening it again keeps the complete lines and
// drops a torn last one (a kill during the write); a journal of another campaign is refused.
// DIR/journal.lock (flock) keeps a second run out of the same folder.
class Journal {
public:
    Journal(const std::string& dir, const Campaign& c);   // throws InputError
    ~Journal();
    Journal(const Journal&) = delete;
    Journal& operator=(const Journal&) = delete;

    struct Entry {
        int index = -1;
        int rank = 0;
        double seconds = 0;
        Row row;
    };
    const std::vector<Entry>& entries() const { return entries_; }   // in the order they finished
    bool done(int index) const { return index >= 0 && index < static_cast<int>(done_.size()) && done_[index]; }
    int resumed() const { return resumed_; }   // entries found when opened
    int dropped() const { return dropped_; }   // torn lines dropped when opened
    // `line` is the entry's JSON text (what a worker sent). Not thread-safe: one caller at a time.
    void append(const std::string& line);

private:
    void open(const std::string& dir, const Campaign& c);
    std::string path_;
    int fd_ = -1, lock_ = -1;
    std::vector<Entry> entries_;
    std::vector<char> done_;
    int resumed_ = 0, dropped_ = 0;
};
// The journal line of a finished case.
std::string journal_line(int index, int rank, double seconds, const Row& row);

// ---- the tables and the figure ----------------------------------------------------------------
// DIR/table.csv (header, one row per case in case order, numbers %.17g, missing values empty),
// DIR/table.jsonl, DIR/timing.csv (case, rank, seconds: not part of the result) and
// DIR/summary.svg; each written atomically. Requires every case in the journal.
void write_tables(const std::string& dir, const Campaign& c, const Journal& j);

// ---- running a campaign ------------------------------------------------------------------------
class Farm;   // farm.hpp

struct SweepOptions {
    std::string out;                                     // DIR
    std::function<void(int done, int total)> progress;   // serialised
};

struct SweepSummary {
    int cases = 0;
    int resumed = 0;           // found in the journal
    int computed = 0;          // in this run
    int failed = 0;            // rows with status "failed" (all cases)
    int torn = 0;              // torn journal lines dropped
    double seconds = 0;        // this run's wall time
    double busy_seconds = 0;   // sum of this run's case times
    int workers = 0;           // threads over all ranks
    std::string farm;          // how the cases were shared
};

// The command line's JSON summary of a campaign run (`plate sweep`; Python's sweep()): the counts,
// times [s], the farm and the tables written.
nlohmann::json sweep_summary_json(const std::string& campaign_file, const std::string& out, const SweepSummary& s);

// Collective over the farm. Rank 0 reads the campaign file, opens the journal under opt.out and
// sends the campaign to the other ranks (Farm::broadcast: they read no file); the cases not in the
// journal are computed on the farm, each appended to the journal as it finishes; rank 0 then
// writes the tables. Bad input (campaign, scene, a journal of another campaign, a folder in use)
// throws InputError on rank 0 and Reported on the others (rank 0 says what).
struct Reported : std::runtime_error {
    using std::runtime_error::runtime_error;
};
SweepSummary run_sweep(const std::string& campaign_file, const SweepOptions& opt, Farm& farm);

}   // namespace plate::sweep
