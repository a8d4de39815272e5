// Reading a JSON input (a scene, an uncertainty spec): every complaint names the file and the field
// and says what was expected, as an InputError.
#pragma once

#include "plate/model.hpp"
#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace plate::detail {

using nlohmann::json;

struct Reader {
    std::string source;

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw InputError(source + ": " + printable(field) + ": " + what);
    }
    // A field name as typed, control characters escaped (a message stays on one line).
    static std::string printable(const std::string& s) {
        std::string o;
        for (unsigned char c : s) {
            if (c == '\n')
                o += "\\n";
            else if (c == '\t')
                o += "\\t";
            else if (c < 0x20 || c == 0x7f) {
                static const char* hex = "0123456789abcdef";
                o += "\\x";
                o += hex[c >> 4];
                o += hex[c & 15];
            } else {
                o += static_cast<char>(c);
            }
        }
        return o;
    }

    void only_keys(const json& obj, const std::string& field, const std::set<std::string>& allowed,
                   const std::set<std::string>& required) const {
        if (!obj.is_object()) fail(field.empty() ? "(top level)" : field, "expected an object");
        for (auto it = obj.begin(); it != obj.end(); ++it)
            if (!allowed.count(it.key())) fail(join(field, it.key()), "unknown field (allowed: " + list(allowed) + ")");
        for (const auto& k : required)
            if (!obj.contains(k)) fail(join(field, k), "missing required field");
    }

    static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }
    static std::string list(const std::set<std::string>& s) {
        std::string out;
        for (const auto& k : s) out += (out.empty() ? "" : ", ") + k;
        return out;
    }

    double number(const json& v, const std::string& field) const {
        if (!v.is_number()) fail(field, "expected a number, got " + std::string(v.type_name()));
        const double x = v.get<double>();
        if (!std::isfinite(x)) fail(field, "expected a finite number");
        return x;
    }

    double positive(const json& v, const std::string& field) const {
        const double x = number(v, field);
        if (!(x > 0)) fail(field, "expected a positive number, got " + fmt(x));
        return x;
    }

    Vec3 vec3(const json& v, const std::string& field) const {
        if (!v.is_array() || v.size() != 3)
            fail(field, "expected an array of 3 numbers" +
                            (v.is_array() ? ", got " + std::to_string(v.size()) + " entries" : std::string()));
        Vec3 out;
        for (int i = 0; i < 3; ++i) out[i] = number(v[i], field + "[" + std::to_string(i) + "]");
        return out;
    }

    static std::string fmt(double x) {
        std::ostringstream s;
        s.precision(6);
        s << x;
        return s.str();
    }
};


// A line of a CSV input without spaces, tabs and carriage returns at either end.
inline std::string trim(const std::string& s) {
    const auto a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The comma-separated cells of a CSV line, each trimmed (a trailing comma: a last empty cell).
inline std::vector<std::string> split_csv(const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream in(line);
    std::string cell;
    while (std::getline(in, cell, ',')) cells.push_back(trim(cell));
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
}

// A CSV cell as a finite number (all of it read by strtod); false if it is empty, not a number or
// not finite.
inline bool finite_number(const std::string& cell, double& v) {
    char* end = nullptr;
    v = std::strtod(cell.c_str(), &end);
    return !cell.empty() && *end == '\0' && std::isfinite(v);
}

// The whole text of an input file; one that cannot be opened is an InputError "PATH: cannot open WHAT".
inline std::string read_input_file(const std::string& path, const std::string& what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot open " + what);
    std::stringstream buf;
    buf << in.rdbuf();
    return buf.str();
}

}   // namespace plate::detail
