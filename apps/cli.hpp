// The plate command line as a function: `plate COMMAND ...` with argv[0] the program's name.
// Writes results to `out` (where a command writes to standard output) and messages to `err`;
// returns the exit code (0 ok, 2 bad input, 3 a simulation left the model, 4 a design failed
// its verification, 5 a proofs verdict failed, 1 other failure).
// apps/main.cpp runs it on std::cout and std::cerr; the fuzz target (tests/fuzz/) in-process.
#pragma once

#include <ostream>

namespace plate::cli {

int run(int argc, char** argv, std::ostream& out, std::ostream& err);

}   // namespace plate::cli
