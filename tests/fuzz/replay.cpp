// Replays the fuzz corpus (tests/fuzz/corpus/: one input per file, see fuzz_one.hpp), then runs a
// bounded number of new mutants of it, seeded: a structure-aware mutator (the scene's JSON tree
// and the argument list, as a user would get them wrong: extreme and non-finite numbers, wrong
// types, missing and unknown fields, dropped and repeated options) plus raw byte edits. Any failed
// check aborts with the input (fuzz_one.cpp). Built in the plain and the sanitizer builds; ctest
// runs it (tests/CMakeLists.txt).
//   plate_fuzz_replay CORPUS_DIR [--mutants N] [--seed S] [--seconds HANG] [--save DIR]
// --save writes every mutant that ran (not skipped) with a new exit code or stderr first line to
// DIR, to grow the corpus.
#include "fuzz_one.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

struct Mutator {
    std::mt19937_64 rng;
    explicit Mutator(std::uint64_t seed) : rng(seed) {}
    std::size_t pick(std::size_t n) { return n ? std::uniform_int_distribution<std::size_t>(0, n - 1)(rng) : 0; }
    bool coin(double p) { return std::uniform_real_distribution<double>(0, 1)(rng) < p; }

    double special(double x) {
        const double v[] = {0.0,  -0.0,   1.0,    -1.0, 1e-300,  -1e-300,  1e300,     -1e300,       1.7e308, 4.9e-324, 1e9,
                            1e-9, x * 10, x / 10, -x,   x * 1e6, x * 1e-6, x + 1e-12, 2147483648.0, 3.0,     7.0,      0.5};
        return v[pick(sizeof v / sizeof *v)];
    }
    // All node pointers of a JSON tree (pre-order).
    void nodes(json& j, std::vector<json*>& out) {
        out.push_back(&j);
        if (j.is_object())
            for (auto& [k, v] : j.items()) nodes(v, out);
        else if (j.is_array())
            for (auto& v : j) nodes(v, out);
    }
    void mutate_json(json& doc) {
        std::vector<json*> all;
        nodes(doc, all);
        json& n = *all[pick(all.size())];
        switch (pick(9)) {
            case 0:
                if (n.is_number())
                    n = special(n.get<double>());
                else
                    n = special(1.0);
                break;
            case 1:
                n = "text";
                break;
            case 2:
                n = nullptr;
                break;
            case 3:
                n = json::array();
                break;
            case 4:
                n = json::object();
                break;
            case 5:   // drop a field or an entry
                if (n.is_object() && !n.empty()) {
                    auto it = n.begin();
                    std::advance(it, pick(n.size()));
                    n.erase(it);
                } else if (n.is_array() && !n.empty())
                    n.erase(n.begin() + static_cast<long>(pick(n.size())));
                break;
            case 6:   // an unknown field, or a repeated entry
                if (n.is_object())
                    n["extra"] = 1;
                else if (n.is_array() && !n.empty())
                    n.push_back(n[pick(n.size())]);
                break;
            case 7:   // an integer field gets a special value, saturated to long long's range: a cast of
                      // 1.7e308 to it is undefined behaviour (clang's UBSan, float-cast-overflow)
                if (n.is_number_integer()) {
                    const double v = special(n.get<double>());
                    constexpr double lim = 9.2e18;   // below 2^63
                    n = v >= lim ? LLONG_MAX : v <= -lim ? LLONG_MIN : static_cast<long long>(v);
                }
                break;
            case 8:   // (the two draws in order: operands of * are evaluated in no set order)
                if (n.is_number()) {
                    const double sign = coin(0.5) ? -1 : 1;
                    n = n.get<double>() * sign * std::pow(10.0, static_cast<int>(pick(13)) - 6);
                }
                break;
        }
    }
    void mutate_args(std::vector<std::string>& a) {
        static const std::vector<std::string> options = {
            "--at",     "--from",     "--start", "--twist",  "--tol",  "--rtol", "--max-periods", "--cycle-solver",
            "--grid",   "--nx",       "--ny",    "--ntheta", "--x",    "--y",    "--theta0",      "--threads",
            "--out",    "--dynamics", "--time",  "--dt",     "--seed", "--thin", "--point",       "--help",
            "--format", "--verify",   "--cold",  "field",    "full",   "u",      "auto",          "shooting",
            "anderson", "OUT",        "SCENE",   "-1",       "0",      "1e308",  "nan",           "inf",
            "-0",       "0x10",       "1e-320",  "2",        "3"};
        if (a.empty()) {
            a.push_back("twist");
            return;
        }
        const std::size_t i = pick(a.size());
        switch (pick(5)) {
            case 0: {
                char* end = nullptr;
                const double x = std::strtod(a[i].c_str(), &end);
                if (i > 0 && !a[i].empty() && *end == '\0') {
                    std::ostringstream s;
                    s.precision(17);
                    s << special(x);
                    a[i] = s.str();
                } else {
                    a[i] = options[pick(options.size())];
                }
                break;
            }
            case 1:
                if (i > 0) a.erase(a.begin() + static_cast<long>(i));
                break;
            case 2:
                a.insert(a.begin() + static_cast<long>(i), a[i]);
                break;
            case 3:
                a.insert(a.begin() + static_cast<long>(std::max<std::size_t>(i, 1)), options[pick(options.size())]);
                break;
            case 4:
                std::swap(a[i], a[pick(a.size())]);
                break;
        }
    }
    std::string mutate(const std::string& input) {
        const std::size_t nl = input.find('\n');
        std::string head = input.substr(0, nl), body = nl == std::string::npos ? "" : input.substr(nl + 1);
        const int rounds = 1 + static_cast<int>(pick(3));
        for (int r = 0; r < rounds; ++r) {
            const std::size_t what = pick(10);
            if (what < 5) {
                json doc = json::parse(body, nullptr, false);
                if (doc.is_discarded()) {
                    what == 0 ? void() : bytes(body);
                    continue;
                }
                mutate_json(doc);
                body = doc.dump(coin(0.5) ? 2 : -1);
            } else if (what < 8) {
                std::istringstream s(head);
                std::vector<std::string> a;
                for (std::string t; s >> t;) a.push_back(t);
                mutate_args(a);
                head.clear();
                for (const auto& t : a) head += (head.empty() ? "" : " ") + t;
            } else {
                bytes(body);
            }
        }
        return head + "\n" + body;
    }
    void bytes(std::string& s) {
        if (s.empty()) {
            s = "{";
            return;
        }
        const std::size_t i = pick(s.size());
        switch (pick(4)) {
            case 0:
                s[i] = static_cast<char>(pick(256));
                break;
            case 1:
                s.insert(i, 1, "{}[],:\"0e-.\\"[pick(13)]);
                break;
            case 2:
                s.erase(i, 1 + pick(8));
                break;
            case 3:
                s.resize(i);
                break;
        }
    }
};

}   // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: plate_fuzz_replay CORPUS_DIR [--mutants N] [--seed S] [--seconds HANG] [--save DIR]\n");
        return 2;
    }
    long mutants = 0;
    std::uint64_t seed = 1;
    std::string save;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        if (k == "--mutants")
            mutants = std::atol(argv[i + 1]);
        else if (k == "--seed")
            seed = std::strtoull(argv[i + 1], nullptr, 10);
        else if (k == "--save")
            save = argv[i + 1];
        else if (k == "--seconds")
            plate::fuzz::set_seconds_per_input(std::atoi(argv[i + 1]));
        else {
            std::fprintf(stderr, "unknown option %s\n", k.c_str());
            return 2;
        }
    }
    // Every file under CORPUS_DIR is replayed; the seeds at its top level (hand-written, valid
    // commands on the shipped scenes) are the mutants' parents. found/ holds what libFuzzer added
    // (mostly broken inputs that reach new code; as parents they would make nearly every mutant a
    // parse error).
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(argv[1]))
        if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) {
        std::fprintf(stderr, "%s: empty corpus\n", argv[1]);
        return 2;
    }
    std::vector<std::string> corpus, parents;
    for (const auto& f : files) {
        corpus.push_back(slurp(f));
        if (f.parent_path() == fs::path(argv[1])) parents.push_back(corpus.back());
    }
    if (parents.empty()) parents = corpus;
    std::map<int, long> codes;
    long skipped = 0;
    auto tally = [&](const plate::fuzz::Outcome& o) {
        if (o.verdict == plate::fuzz::Verdict::Skipped)
            ++skipped;
        else
            ++codes[o.code];
    };
    for (const auto& in : corpus) tally(plate::fuzz::run_one(in));
    std::printf("corpus: %zu inputs replayed\n", corpus.size());
    Mutator m(seed);
    std::map<std::string, int> seen;
    for (long n = 0; n < mutants; ++n) {
        const std::string in = m.mutate(parents[m.pick(parents.size())]);
        const plate::fuzz::Outcome o = plate::fuzz::run_one(in);
        tally(o);
        if (!save.empty() && o.verdict == plate::fuzz::Verdict::Ran && seen[std::to_string(o.code)]++ < 3) {
            fs::create_directories(save);
            std::ofstream(fs::path(save) / ("mutant-" + std::to_string(seed) + "-" + std::to_string(n)), std::ios::binary) << in;
        }
    }
    std::printf("mutants: %ld (seed %llu); skipped %ld (outside the work bounds)", mutants, static_cast<unsigned long long>(seed),
                skipped);
    for (const auto& [c, k] : codes) std::printf("; exit %d: %ld", c, k);
    std::printf("\nno crash, hang, unexplained failure, non-finite output or partial file\n");
    plate::fuzz::cleanup();
    return 0;
}
