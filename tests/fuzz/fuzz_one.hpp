// The fuzz target (issue 18): one input is a command line and a scene file, run through the plate
// command line in-process (plate::cli::run), and checked for what must never happen:
//   - a crash or a sanitizer report (the build's sanitizers abort);
//   - a hang (no result within kSecondsPerInput: SIGALRM aborts with the input);
//   - an exit code other than 0, 1, 2, 3; a failure whose stderr does not end with the program's
//     message ("plate COMMAND: ...");
//   - NaN or Inf in the output of a run that exited 0 (CSV text; in JSON, where NaN is written as null,
//     a null in a converged twist), or a random scene that does not read back;
//   - an output file left after bad input (exit 2), or a temporary (.tmp) left after any run.
// Input: the first line holds the arguments (`field SCENE --grid 2 --out OUT`); SCENE and OUT
// stand for files the harness provides; the rest of the input is the scene file's bytes.
// Work is bounded so that a run takes milliseconds, not minutes, through the program's own budgets:
// grids at most 3 per axis (2 if none is given), at most 40 periods and 3e5 right-hand sides per
// cycle, 3e6 per field or fixed-point search, 10^5 steps and 0.5 s of simulated time per
// trajectory, 2 threads (inputs asking for more are skipped). report, bench and proofs read no scene and run for minutes by
// design; their options go through the same parser as the commands fuzzed here, so they are left out. Arguments with a
// '/' are skipped (a mutant must not write outside the harness's folder).
#pragma once

#include <string>

namespace plate::fuzz {

enum class Verdict { Skipped, Ran };

struct Outcome {
    Verdict verdict = Verdict::Skipped;
    int code = -1;
};

// Runs one input; aborts (after printing why, and the input) if a check fails.
Outcome run_one(const std::string& input);
// Removes the harness's folder (its scene and output files).
void cleanup();

// A hang: no result within this many seconds. The default is for an ASan build on a busy machine;
// the release replay uses 10 (the slowest corpus input takes 0.2 s there).
constexpr int kSecondsPerInput = 60;
void set_seconds_per_input(int seconds);

}   // namespace plate::fuzz
