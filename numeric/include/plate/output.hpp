// Writing results: JSON for summaries, CSV for tables. Files are written atomically
// (to a temporary beside the target, renamed on success), so a failure leaves no partial file.
#pragma once

#include "plate/field.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <functional>
#include <iostream>
#include <ostream>
#include <string>

namespace plate {

nlohmann::json to_json(const Scene& scene, const Vec3& q, const LimitCycleSummary& lc);
nlohmann::json to_json(const Scene& scene, const Field& field);
nlohmann::json to_json(const Scene& scene, const FixedPoints& fp);
// The CSV tables state each column's unit in its header, "name [unit]" (a column without brackets is
// a count, a flag or a name; [1] a ratio), and write numbers by `shortest` below; an undefined value is empty.
void write_field_csv(std::ostream& out, const Field& field);
void write_trajectory_csv(std::ostream& out, const Trajectory& tr, bool point_part);

// x in the shortest decimal form that reads back to the same double (std::to_chars: 0.2, not
// 0.20000000000000001); "" when x is not finite. Every text table writes its numbers with it.
std::string shortest(double x);

// A text's FNV-1a 64-bit hash as 16 lowercase hex digits: a fingerprint of a canonical text (a
// campaign file, a scene), the same on every platform.
std::string fnv1a_hex(const std::string& text);

// Progress on stderr for long runs: silent for the first 1.5 s, then a line at most every
// `every` seconds, and the final count if anything was shown.
// Progress lines go to stderr only when it is a terminal (a person watching); in pipes, logs and
// CI they would be noise. PLATE_PROGRESS=1 forces them, =0 silences them.
bool progress_wanted();
// A progress line (printf-style) on stderr when progress_wanted().
void progress_line(const char* format, ...) __attribute__((format(printf, 1, 2)));

struct ProgressPrinter {
    std::string what;
    double every = 1.0;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last = start;
    bool shown = false;
    std::ostream* to = &std::cerr;   // nullptr: silent
    void operator()(int done, int total);
};

// The CPU model and hardware thread count, for benchmarks and reports.
std::string machine_description();

// Calls write(stream) on a temporary file and renames it to `path`; on any exception the
// temporary is removed and the exception rethrown. path "-" writes to `standard_output`.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write,
                       std::ostream& standard_output = std::cout);
// For programs (apps/main.cpp), not libraries: on SIGINT, SIGTERM or SIGHUP remove the temporary of
// a write_file_atomic in progress, then die of the signal. (SIGKILL leaves the temporary, under its
// .tmp name: nothing that looks complete.)
void install_interrupt_cleanup();

}   // namespace plate
