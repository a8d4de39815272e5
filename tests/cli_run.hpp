// Running the plate program from a test: its exit code and output, in a folder of the test
// process's own (tests/test_cli*.cpp).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

struct Run {
    int code;
    std::string out, err;
};

// A folder of this test process's own, removed when the process ends (ctest runs each test case
// as a process: without it, every run left one behind in /tmp).
struct OwnTmpDir {
    fs::path p;
    ~OwnTmpDir() {
        std::error_code ec;
        fs::remove_all(p, ec);
    }
};
fs::path tmpdir() {
    static const OwnTmpDir d{[] {
        fs::path p = fs::temp_directory_path() / ("plate_cli_" + std::to_string(::getpid()));
        fs::create_directories(p);
        return p;
    }()};
    return d.p;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

Run run(const std::string& args) {
    const fs::path o = tmpdir() / "stdout", e = tmpdir() / "stderr";
    const std::string cmd = std::string(PLATE_EXE) + " " + args + " > " + o.string() + " 2> " + e.string();
    const int st = std::system(cmd.c_str());
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(o), slurp(e)};
}

const std::string kScenes = PLATE_SOURCE_DIR "/scenes/";

}   // namespace
