// The text tables' notation (issue 54, point 6): numbers in the shortest form that reads back to the
// same double, and every column's unit in its heading.
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

using namespace plate;

namespace {

std::vector<std::string> cells(const std::string& line) {
    std::vector<std::string> c;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, ',');) c.push_back(x);
    return c;
}

}   // namespace

TEST_CASE("numbers are written in the shortest form that reads back to the same double", "[output]") {
    // Known shortest forms (the decimal literal's nearest double prints as the literal; 0.1 + 0.2 is not
    // 0.3 and needs all 17 digits), the extremes of the double range, and no value for what is not finite.
    CHECK(shortest(0.2) == "0.2");
    CHECK(shortest(0.1 + 0.2) == "0.30000000000000004");
    CHECK(shortest(-0.015) == "-0.015");
    CHECK(shortest(20) == "20");
    CHECK(shortest(1e-7) == "1e-07");
    CHECK(shortest(std::numeric_limits<double>::denorm_min()) == "5e-324");
    CHECK(shortest(std::numeric_limits<double>::max()) == "1.7976931348623157e+308");
    CHECK(shortest(std::nan("")).empty());
    CHECK(shortest(-std::numeric_limits<double>::infinity()).empty());
    // Random bit patterns: each reads back to itself, and one digit fewer (the shortest form rounded
    // to one significant digit less) does not, so no shorter form exists.
    std::mt19937_64 rng(54);
    int checked = 0;
    while (checked < 20000) {
        const std::uint64_t bits = rng();
        double x;
        std::memcpy(&x, &bits, sizeof x);
        if (!std::isfinite(x)) continue;
        const std::string s = shortest(x);
        REQUIRE(std::strtod(s.c_str(), nullptr) == x);
        // Its significant digits: the mantissa's without the sign, the point, and leading or (in a
        // fixed form of a large number) trailing zeros.
        std::string digits_of;
        for (char ch : s.substr(0, s.find('e')))
            if (std::isdigit(static_cast<unsigned char>(ch))) digits_of += ch;
        digits_of.erase(0, digits_of.find_first_not_of('0'));
        digits_of.erase(digits_of.find_last_not_of('0') + 1);
        const int digits = static_cast<int>(digits_of.size());
        // (A large whole number in fixed form, "1451498526278341120", is as short in characters as its
        // shortest digits padded with zeros, and std::to_chars then writes the nearer digits: not counted.)
        const bool padded_whole = s.find_first_of(".e") == std::string::npos && s.size() > 15;
        if (digits > 1 && !padded_whole) {
            char fewer[40];
            std::snprintf(fewer, sizeof fewer, "%.*e", digits - 2, x);
            CHECK(std::strtod(fewer, nullptr) != x);
        }
        ++checked;
    }
}

TEST_CASE("a field's CSV states every column's unit and its numbers are the JSON's doubles", "[output]") {
    const Scene sc = plate_tests::scene("fig4");
    GridSpec g;
    g.nx = g.ny = g.nth = 2;
    const Field f = compute_field(sc, g);
    std::ostringstream csv;
    write_field_csv(csv, f);
    std::istringstream in(csv.str());
    std::string heading;
    std::getline(in, heading);
    CHECK(heading ==
          "s_x [m],s_y [m],theta [rad],v_x [m/s],v_y [m/s],omega [rad/s],converged,periods,residual [1],"
          "min_normal_force [N],stop,stick_1 [period],stick_2 [period],stick_3 [period]");
    const nlohmann::json j = to_json(sc, f);
    CHECK(j["units"]["twist"] == nlohmann::json({"m/s", "m/s", "rad/s"}));
    std::size_t k = 0;
    for (std::string line; std::getline(in, line); ++k) {
        REQUIRE(k < f.points.size());
        const auto c = cells(line);
        REQUIRE(c.size() == 14);
        for (int i = 0; i < 3; ++i) {
            CHECK(std::strtod(c[static_cast<std::size_t>(i)].c_str(), nullptr) == j["points"][k]["at"][i].get<double>());
            CHECK(std::strtod(c[static_cast<std::size_t>(3 + i)].c_str(), nullptr) == f.points[k].twist[i]);
            CHECK(c[static_cast<std::size_t>(3 + i)] == shortest(f.points[k].twist[i]));
        }
    }
    CHECK(k == f.points.size());
}

TEST_CASE("a trajectory's CSV states every column's unit", "[output]") {
    Trajectory tr;
    Sample s;
    s.t = 0.1;
    s.q = Vec3(0.02, -0.01, 0.5);
    s.qd = Vec3(0.001, 0, -0.2);
    s.n = Vec3(1.5, 2, 2.5);
    tr.samples.push_back(s);
    std::ostringstream rigid, point;
    write_trajectory_csv(rigid, tr, false);
    write_trajectory_csv(point, tr, true);
    CHECK(rigid.str() ==
          "t [s],s_x [m],s_y [m],theta [rad],s_x_dot [m/s],s_y_dot [m/s],theta_dot [rad/s],N1 [N],N2 [N],N3 [N],mode\n"
          "0.1,0.02,-0.01,0.5,0.001,0,-0.2,1.5,2,2.5," +
              mode_name(s.mode) + "\n");
    CHECK(point.str().rfind("t [s],s_x [m],s_y [m],s_x_dot [m/s],s_y_dot [m/s],N1 [N],mode\n0.1,0.02,-0.01,0.001,0,1.5,", 0) ==
          0);
}
