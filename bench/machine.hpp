// The machine a benchmark ran on, for its printout: the CPU's model name from /proc/cpuinfo.
#pragma once

#include <fstream>
#include <string>

namespace plate::bench {

inline std::string machine() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown CPU";
}

}   // namespace plate::bench
