#include "fuzz_one.hpp"

#include "cli.hpp"

#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <set>
#include <sstream>
#include <unistd.h>
#include <vector>

namespace plate::fuzz {
namespace {

namespace fs = std::filesystem;

const std::string* g_input = nullptr;   // for the messages of a failed check (and the alarm)
int seconds_per_input = kSecondsPerInput;

[[noreturn]] void fail(const std::string& why, const std::string& detail) {
    std::fprintf(stderr, "\nfuzz check failed: %s\n%s\n--- input ---\n%s\n--- end ---\n", why.c_str(), detail.c_str(),
                 g_input ? g_input->c_str() : "");
    std::abort();
}

extern "C" void on_alarm(int) {
    static const char msg[] = "\nfuzz check failed: hang (no result within the time limit); the input follows\n";
    ssize_t w = ::write(2, msg, sizeof msg - 1);
    if (g_input) w = ::write(2, g_input->data(), g_input->size());
    (void)w;
    std::abort();
}

const fs::path& workdir() {
    static const fs::path d = [] {
        fs::path p = fs::temp_directory_path() / ("plate_fuzz_" + std::to_string(::getpid()));
        fs::create_directories(p);
        std::signal(SIGALRM, on_alarm);
        return p;
    }();
    return d;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

bool number(const std::string& s, double& x) {
    char* end = nullptr;
    x = std::strtod(s.c_str(), &end);
    return !s.empty() && *end == '\0';
}

}   // namespace

Outcome run_one(const std::string& input) {
    Outcome o;
    g_input = &input;
    const std::size_t nl = input.find('\n');
    std::istringstream line(input.substr(0, nl));
    const std::string scene_text = nl == std::string::npos ? std::string() : input.substr(nl + 1);
    std::vector<std::string> args;
    for (std::string t; line >> t;) args.push_back(t);
    static const std::set<std::string> commands = {"twist", "field", "fixed-points", "simulate", "random-scene"};
    if (args.empty() || !commands.count(args[0]) || args.size() > 40) return o;
    const fs::path scene = workdir() / "scene.json", out = workdir() / "out";
    bool help = false, has_grid = false, has_periods = false, has_rhs = false, has_work = false, has_steps = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        std::string& a = args[i];
        if (a.find('/') != std::string::npos) return o;
        // Files are written only where the harness says: --out OUT or standard output.
        if (i > 0 && args[i - 1] == "--out" && a != "OUT" && a != "-") return o;
        if (a == "--out" && i + 1 == args.size()) return o;
        if (a == "SCENE") a = scene.string();
        if (a == "OUT") a = out.string();
        help |= a == "--help" || a == "-h";
        has_grid |= a == "--grid";
        has_periods |= a == "--max-periods";
        has_rhs |= a == "--max-rhs";
        has_work |= a == "--max-work";
        has_steps |= a == "--max-steps";
        if (i == 0) continue;
        double x = 0;
        const std::string& k = args[i - 1];
        if (!number(a, x)) continue;
        if ((k == "--grid" || k == "--nx" || k == "--ny" || k == "--ntheta") && x > 3) return o;
        if (k == "--max-periods" && x > 40) return o;
        if ((k == "--max-rhs" && x > 3e5) || (k == "--max-work" && x > 3e6) || (k == "--max-steps" && x > 1e5)) return o;
        if (k == "--time" && x > 0.5) return o;
        if (k == "--threads" && (x > 2 || x == 0)) return o;
    }
    if ((args[0] == "field" || args[0] == "fixed-points") && !has_grid) args.insert(args.begin() + 1, {"--grid", "2"});
    const bool cycles = args[0] == "twist" || args[0] == "field" || args[0] == "fixed-points";
    if (cycles && !has_periods) args.insert(args.begin() + 1, {"--max-periods", "40"});
    if (cycles && !has_rhs) args.insert(args.begin() + 1, {"--max-rhs", "300000"});
    if ((args[0] == "field" || args[0] == "fixed-points") && !has_work) args.insert(args.begin() + 1, {"--max-work", "3000000"});
    if (args[0] == "simulate" && !has_steps) args.insert(args.begin() + 1, {"--max-steps", "100000"});
    for (const fs::path& p : {scene, out, fs::path(out.string() + ".tmp")}) fs::remove(p);
    std::ofstream(scene, std::ios::binary) << scene_text;

    std::vector<std::string> argv_s = {"plate"};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    std::ostringstream so, se;
    ::alarm(static_cast<unsigned>(seconds_per_input));
    o.code = cli::run(static_cast<int>(argv_s.size()), argv.data(), so, se);
    ::alarm(0);
    o.verdict = Verdict::Ran;

    const std::string err = se.str();
    std::string detail = "exit " + std::to_string(o.code) + "; stderr:\n" + err;
    if (o.code < 0 || o.code > 3) fail("exit code outside 0-3", detail);
    // A failure ends with the program's own message (warnings may come before it).
    const std::size_t last = err.find_last_of('\n', err.size() >= 2 ? err.size() - 2 : 0);
    const std::string last_line = err.substr(last == std::string::npos ? 0 : last + 1);
    if (o.code != 0 && last_line.rfind("plate ", 0) != 0) fail("a failure without the program's message", detail);
    if (fs::exists(out.string() + ".tmp")) fail("a temporary output left behind", detail);
    if (o.code == 2 && fs::exists(out)) fail("an output file left after bad input", detail);
    if (o.code == 0 && !help) {
        // "nan", "inf" or "infinity" as a word, any case
        auto nonfinite_word = [](const std::string& t) {
            std::size_t i = 0;
            while (i < t.size()) {
                if (!std::isalpha(static_cast<unsigned char>(t[i])) && t[i] != '_') {
                    ++i;
                    continue;
                }
                std::size_t j = i;
                while (j < t.size() && (std::isalpha(static_cast<unsigned char>(t[j])) || t[j] == '_')) ++j;
                std::string w = t.substr(i, j - i);
                for (char& c : w) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
                if (w == "nan" || w == "inf" || w == "infinity") return true;
                i = j;
            }
            return false;
        };
        const std::string file = fs::exists(out) ? slurp(out) : std::string(), printed = so.str();
        for (const std::string* text : {&printed, &file})
            if (nonfinite_word(*text))
                fail("NaN or Inf in the output of a run that exited 0", detail + "\noutput:\n" + text->substr(0, 2000));
        for (const std::string* text : {&printed, &file}) {
            if (text->empty() || ((*text)[0] != '{' && (*text)[0] != '[')) continue;
            const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
            if (j.is_discarded()) fail("malformed JSON output", detail);
            // JSON writes NaN as null: a defined result must have no null in it.
            auto defined_twist = [&](const nlohmann::json& x) {
                if (x.contains("converged") && x["converged"] == true && x.contains("twist"))
                    for (const auto& v : x["twist"])
                        if (!v.is_number()) fail("a converged twist with a non-finite component (null)", detail);
            };
            if (j.is_object()) {
                defined_twist(j);
                if (j.contains("points"))
                    for (const auto& p : j["points"]) defined_twist(p);
                if (args[0] == "random-scene") {
                    try {
                        parse_scene(*text, "random-scene output");
                    } catch (const std::exception& e) {
                        fail("random-scene wrote a scene it cannot read back", detail + "\n" + e.what());
                    }
                }
            }
        }
    }
    g_input = nullptr;
    return o;
}

void set_seconds_per_input(int s) { seconds_per_input = s; }

void cleanup() {
    std::error_code ec;
    fs::remove_all(workdir(), ec);
}

}   // namespace plate::fuzz
