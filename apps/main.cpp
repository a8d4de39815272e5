// plate: the command-line program. See `plate --help` and apps/cli.hpp.
#include "cli.hpp"

#include <iostream>

int main(int argc, char** argv) { return plate::cli::run(argc, argv, std::cout, std::cerr); }
