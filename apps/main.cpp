// plate: the command-line program. See `plate --help` and apps/cli.hpp.
#include "cli.hpp"

#include "plate/output.hpp"

#include <iostream>

int main(int argc, char** argv) {
    plate::install_interrupt_cleanup();
    return plate::cli::run(argc, argv, std::cout, std::cerr);
}
