// Campaigns (issue 20): the case values, the campaign file's checks, a case's row against the same
// computation done directly and against a threshold known in closed form, the journal's durability
// rules (torn lines, another campaign, a second writer), the table's text, the thread farm.
// The program's runs -- single-process against `mpirun -np 2`, killed and resumed -- are in
// tests/sweep/check_sweep.py.
#include "plate/farm.hpp"
#include "plate/sweep.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

using namespace plate;
using namespace plate::sweep;
namespace fs = std::filesystem;

namespace {

struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() / ("plate_sweep_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    static int& counter() {
        static int n = 0;
        return n;
    }
    std::string operator/(const std::string& f) const { return (path / f).string(); }
};

std::string write(const std::string& file, const std::string& text) {
    std::ofstream(file) << text;
    return file;
}

// A point part on a plate translating as A sin(wt) along x (A = 2 m/s^2): it stays stuck for ever
// exactly when A <= mu g, i.e. mu >= A / g = 0.2039.
const char* kShakenBlock = R"({"name": "shaken_block", "gravity": 9.81, "part": {"mass": 0.1, "friction": 0.3},
  "plate": {"period": 0.05, "harmonics": [{"axis": "x", "n": 1, "amp": 2, "phase": 0}]}})";

std::string block_campaign(const TempDir& d, const std::string& parameters, const std::string& extra = "") {
    write(d / "block.json", kShakenBlock);
    return write(d / "c.json", R"({"name": "block", "scene": "block.json", "parameters": )" + parameters +
                                   R"(, "compute": {"twist_at": [[0, 0]])" + extra + "}}");
}

std::string slurp(const std::string& f) {
    std::ifstream in(f);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}   // namespace

TEST_CASE("a grid campaign's cases: the first parameter slowest, ranges with their end points exact", "[sweep]") {
    TempDir d;
    const Campaign c =
        load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "from": 0.1, "to": 0.4, "count": 4},
               {"name": "A", "pointer": "/plate/harmonics/0/amp", "values": [1, 2, 3]}])"));
    REQUIRE(c.cases() == 12);
    CHECK(case_values(c, 0) == std::vector<double>{0.1, 1});
    CHECK(case_values(c, 1) == std::vector<double>{0.1, 2});
    CHECK(case_values(c, 3) == std::vector<double>{0.2, 1});
    CHECK(case_values(c, 11) == std::vector<double>{0.4, 3});   // (0.4 itself, not 0.1 + 3 * 0.1)
    const Scene sc = case_scene(c, 5);                          // mu 0.2, A 3
    CHECK(sc.part.mu[0] == 0.2);
    CHECK(sc.plate.harmonics.at(0).amp == 3);
}

TEST_CASE("random samples: in range, reproducible, a function of (seed, case) only", "[sweep]") {
    TempDir d;
    write(d / "block.json", kShakenBlock);
    auto campaign = [&](int seed) {
        return load_campaign(write(d / "r.json", R"({"name": "r", "scene": "block.json", "sampling": {"random": 500, "seed": )" +
                                                     std::to_string(seed) + R"(}, "parameters": [
              {"name": "mu", "pointer": "/part/friction", "from": 0.1, "to": 0.4},
              {"name": "A", "pointer": "/plate/harmonics/0/amp", "from": 1, "to": 3}], "compute": {"twist_at": [[0, 0]]}})"));
    };
    const Campaign a = campaign(7), b = campaign(7), other = campaign(8);
    REQUIRE(a.cases() == 500);
    double lo = 1, hi = 0, mean = 0;
    std::set<double> seen;
    for (int i = 499; i >= 0; --i) {   // (any order)
        const auto v = case_values(a, i);
        CHECK(v == case_values(b, i));
        CHECK(v != case_values(other, i));
        lo = std::min(lo, v[0]);
        hi = std::max(hi, v[0]);
        mean += v[0] / 500;
        seen.insert(v[0]);
        CHECK((v[1] >= 1 && v[1] <= 3));
    }
    CHECK(seen.size() == 500);
    CHECK((lo >= 0.1 && lo < 0.11 && hi <= 0.4 && hi > 0.39));
    CHECK(std::abs(mean - 0.25) < 4 * 0.0866 / std::sqrt(500.0));   // uniform: sd 0.3/sqrt(12); 4 sigma
}

TEST_CASE("bad campaign files are refused with the file and the field named", "[sweep][input]") {
    TempDir d;
    write(d / "block.json", kShakenBlock);
    auto refused = [&](const std::string& text, const std::string& expected) {
        const std::string f = write(d / "bad.json", text);
        INFO(text);
        try {
            load_campaign(f);
            FAIL("accepted");
        } catch (const InputError& e) {
            INFO(e.what());
            CHECK(std::string(e.what()).find(f) == 0);
            CHECK(std::string(e.what()).find(expected) != std::string::npos);
        }
    };
    const std::string ok_params = R"("parameters": [{"name": "mu", "pointer": "/part/friction", "values": [0.2]}])";
    const std::string ok_compute = R"("compute": {"twist_at": [[0, 0]]})";
    refused(R"({"name": "x", "scene": "block.json", )" + ok_params + ", " + ok_compute + R"(, "color": 1})",
            "color: unknown field");
    refused(R"({"name": "x", "scene": "none.json", )" + ok_params + ", " + ok_compute + "}",
            "scene: " + (d / "none.json") + ": cannot open the scene file");
    refused(R"({"name": "x", "scene": "block.json", "parameters": [{"name": "m", "pointer": "/part/mass2", "values": [1]}], )" +
                ok_compute + "}",
            "parameters[0].pointer: '/part/mass2' addresses no number");
    refused(R"({"name": "x", "scene": "block.json", "parameters": [{"name": "m", "pointer": "part/mass", "values": [1]}], )" +
                ok_compute + "}",
            "is no JSON pointer");
    refused(
        R"({"name": "x", "scene": "block.json", "parameters": [{"name": "m", "pointer": "/part/mass", "from": 1, "to": 2, "count": 0}], )" +
            ok_compute + "}",
        "parameters[0].count: expected a whole number from 1");
    refused(R"({"name": "x", "scene": "block.json", )" + ok_params + R"(, "compute": {"fixed_points": true}})",
            "compute.fixed_points: needs compute.field");
    refused(R"({"name": "x", "scene": "block.json", )" + ok_params + R"(, "compute": {}})", "compute: nothing to compute");
    refused(R"({"name": "x", "scene": "block.json", )" + ok_params + R"(, "compute": {"twist_at": [[0, 0, 0]]}})",
            "compute.twist_at[0]: expected an array of 2 numbers");   // a point part: SX SY
    refused(R"({"name": "x", "scene": "block.json", "parameters": [{"name": "a", "pointer": "/part/mass", "values": [1]},
                {"name": "a", "pointer": "/part/friction", "values": [1]}], )" +
                ok_compute + "}",
            "parameters[1].name: 'a' named twice");
}

TEST_CASE("a design campaign takes plate design's corner limits and the plate's half size", "[sweep][input]") {
    TempDir d;
    write(d / "block.json", kShakenBlock);
    const auto campaign = [&](const std::string& design) {
        return write(d / "c.json", R"({"name": "x", "scene": "block.json", "parameters": [{"name": "mu", "pointer":
          "/part/friction", "values": [0.2]}], "compute": {"design": {"target": ["sink", 0.02, -0.01], )" +
                                       design + "}}}");
    };
    const Campaign c = load_campaign(campaign(R"("corner_limits": [0.0005, 0.07], "plate_half_size": [0.1, 0.08])"));
    CHECK(c.design_options.corner_displacement_limit == 0.0005);
    CHECK(c.design_options.corner_velocity_limit == 0.07);
    CHECK(c.design_options.plate_half_size == Vec2(0.1, 0.08));
    const Campaign plain = load_campaign(campaign(R"("seed": 3)"));
    CHECK(plain.design_options.corner_displacement_limit == 0);
    CHECK(plain.design_options.plate_half_size == Vec2::Zero());
    for (const auto& [bad, expected] : {std::pair<std::string, std::string>{R"("corner_limits": [-1, 0])", "corner_limits"},
                                        {R"("corner_limits": [0.001])", "compute.design.corner_limits"},
                                        {R"("plate_half_size": [0.1, 0])", "plate_half_size"}}) {
        INFO(bad);
        CHECK_THROWS_WITH(load_campaign(campaign(bad)), Catch::Contains(expected));
    }
}

TEST_CASE("a case's row is the direct computation's, and the stick threshold mu = A/g is where the closed form puts it",
          "[sweep]") {
    TempDir d;
    // A / g = 0.20387: 0.19 and 0.2 slide part of each period, 0.21 and 0.3 stick for ever.
    const Campaign c =
        load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "values": [0.19, 0.2, 0.21, 0.3]}])"));
    for (int i = 0; i < c.cases(); ++i) {
        const Row row = run_case(c, i);
        const double mu = case_values(c, i)[0];
        INFO("mu " << mu << ": " << row.dump());
        CHECK(row["status"] == "ok");
        // The same cycle computed directly, from a scene built by hand: the same bits.
        Scene sc = load_scene(write(d / "direct.json", kShakenBlock));
        sc.part.mu.fill(mu);
        const LimitCycleSummary lc = limit_cycle(sc, Vec3::Zero(), c.cycle);
        CHECK(row["twist0_vx"].get<double>() == lc.twist[0]);
        CHECK(row["twist0_stick"].get<double>() == lc.stick_fraction[0]);
        if (mu * 9.81 >= 2) {
            CHECK(row["twist0_stick"].get<double>() == 1);
            CHECK(row["twist0_vx"].get<double>() == 0);   // stuck: exactly zero
        } else {
            CHECK(row["twist0_stick"].get<double>() < 1);
            // A sine has no preferred direction: zero mean velocity, to the cycle's tolerance.
            CHECK(std::abs(row["twist0_vx"].get<double>()) < 1e-6 * sc.v_ref());
        }
    }
}

TEST_CASE("a case whose values make the scene invalid gets a failed row with the reason, the others go on", "[sweep]") {
    TempDir d;
    const Campaign c =
        load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "values": [0.3, -0.1]}])"));
    const Row good = run_case(c, 0), bad = run_case(c, 1);
    CHECK(good["status"] == "ok");
    CHECK(bad["status"] == "failed");
    INFO(bad.dump());
    CHECK(bad["reason"].get<std::string>().find("block case 1") != std::string::npos);
    CHECK(bad["reason"].get<std::string>().find("friction") != std::string::npos);
    CHECK(bad["twist0_vx"].is_null());
    // Every row has every column, in order.
    std::vector<std::string> keys;
    for (const auto& [k, v] : bad.items()) keys.push_back(k);
    CHECK(keys == columns(c));
}

TEST_CASE("the journal: entries survive, a torn last line is cut, a damaged one or another campaign's journal is refused",
          "[sweep][journal]") {
    TempDir d;
    const Campaign c =
        load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "values": [0.1, 0.2, 0.3]}])"));
    const std::string dir = d / "out";
    std::string line1;
    {
        Journal j(dir, c);
        CHECK(j.resumed() == 0);
        line1 = journal_line(1, 0, 0.5, run_case(c, 1));
        j.append(line1);
        // A second writer is kept out while this one holds the folder.
        CHECK_THROWS_WITH(Journal(dir, c), Catch::Contains("another plate sweep is writing this folder"));
    }
    const std::string path = dir + "/journal.jsonl";
    const std::string complete = slurp(path);
    {   // a kill in the middle of a write: half a line, no newline
        std::ofstream(path, std::ios::app) << journal_line(2, 0, 0.1, run_case(c, 2)).substr(0, 40);
        Journal j(dir, c);
        CHECK(j.resumed() == 1);
        CHECK(j.dropped() == 1);
        CHECK(j.done(1));
        CHECK_FALSE(j.done(2));
        CHECK(j.entries()[0].row.dump() == Row::parse(line1)["row"].dump());
    }
    CHECK(slurp(path) == complete);   // cut back to the last complete line
    {                                 // a damaged line before the end is not a torn write: refused, not silently dropped
        std::ofstream(path, std::ios::app) << "{not json\n" << line1 << "\n";
        CHECK_THROWS_WITH(Journal(dir, c), Catch::Contains("journal.jsonl:3: not a journal line"));
        std::ofstream(path) << complete;
    }
    {   // another campaign (a different parameter list) may not resume this journal
        const Campaign other =
            load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "values": [0.1, 0.2, 0.35]}])"));
        CHECK(fingerprint(other) != fingerprint(c));
        CHECK_THROWS_WITH(Journal(dir, other), Catch::Contains("the journal of another campaign"));
    }
}

TEST_CASE("the table: full precision, missing values empty, text quoted, written only when every case is done",
          "[sweep][journal]") {
    TempDir d;
    const Campaign c = load_campaign(block_campaign(d, R"([{"name": "mu", "pointer": "/part/friction", "values": [0.1, -1]}])"));
    const std::string dir = d / "out";
    Journal j(dir, c);
    j.append(journal_line(1, 0, 0.1, run_case(c, 1)));
    CHECK_THROWS_AS(write_tables(dir, c, j), std::logic_error);
    CHECK_FALSE(fs::exists(dir + "/table.csv"));
    const Row row0 = run_case(c, 0);
    j.append(journal_line(0, 0, 0.1, row0));
    write_tables(dir, c, j);
    std::ifstream in(dir + "/table.csv");
    std::string header, r0, r1;
    std::getline(in, header);
    std::getline(in, r0);
    std::getline(in, r1);
    // Each heading with its unit; the parameter's is the scene field's it sets.
    CHECK(header.rfind("case,mu [as /part/friction],status,reason,note,rhs_evaluations,twist0_vx [m/s],twist0_vy [m/s],"
                       "twist0_stick [period]",
                       0) == 0);
    // Row 0's speed reads back to the same double.
    std::vector<std::string> cells;
    std::stringstream s(r0);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    REQUIRE(cells.size() >= 9);
    CHECK(std::stod(cells[6]) == row0["twist0_vx"].get<double>());
    // Row 1 failed: its reason (with commas and quotes) is one quoted cell, its numbers empty.
    CHECK(r1.rfind("1,-1,failed,\"", 0) == 0);
    CHECK(r1.find(",,,") != std::string::npos);
    CHECK(slurp(dir + "/table.jsonl").find("\"case\":1") != std::string::npos);
    CHECK(slurp(dir + "/summary.svg").find("<svg") == 0);
}

TEST_CASE("the thread farm runs every task once and reports them one at a time", "[sweep]") {
    auto farm = thread_farm(3);
    std::vector<int> todo;
    for (int i = 0; i < 200; ++i) todo.push_back(3 * i);
    std::vector<int> count(600, 0);
    std::atomic<int> inside{0};
    int overlaps = 0;
    farm->run(
        todo, [](int i) { return std::to_string(i * i); },
        [&](int i, const std::string& r) {
            if (++inside > 1) ++overlaps;
            CHECK(r == std::to_string(i * i));
            ++count[static_cast<std::size_t>(i)];
            std::this_thread::yield();
            --inside;
        });
    CHECK(overlaps == 0);
    for (int i = 0; i < 600; ++i) CHECK(count[static_cast<std::size_t>(i)] == (i % 3 == 0 ? 1 : 0));
    // A done() that throws (a journal that cannot be written) stops the farm and reaches the caller.
    CHECK_THROWS_WITH(farm->run(
                          todo, [](int i) { return std::to_string(i); },
                          [](int i, const std::string&) {
                              if (i == 30) throw std::runtime_error("disk full");
                          }),
                      "disk full");
}

// farm_tasks on a rank other than 0 computes nothing itself in this fake: every result reaches it
// through rank 0's broadcast, which it must cut back into the same texts (empty ones, colons and
// line breaks included), in task order.
TEST_CASE("farm_tasks: a rank other than 0 gets every task's text from the broadcast, exactly", "[sweep][tasks]") {
    struct OtherRank : sweep::Farm {
        int rank() const override { return 1; }
        int ranks() const override { return 2; }
        int workers() const override { return 1; }
        std::string describe() const override { return "fake rank 1"; }
        void broadcast(std::string& text) override { text = "3:a:b0:7:x\ny 1:2"; }
        void run(const std::vector<int>& todo, const std::function<std::string(int)>&,
                 const std::function<void(int, const std::string&)>&) override {
            REQUIRE(todo.empty());   // (rank 0 alone hands out tasks)
        }
    } farm;
    std::vector<std::string> got(3, "unset");
    std::vector<int> order;
    sweep::farm_tasks(farm)(
        3,
        [](int) -> std::string {
            FAIL("rank 1 ran a task itself");
            return "";
        },
        [&](int i, const std::string& t) {
            got[static_cast<std::size_t>(i)] = t;
            order.push_back(i);
        });
    CHECK(got == std::vector<std::string>{"a:b", "", "x\ny 1:2"});
    CHECK(order == std::vector<int>{0, 1, 2});
}
