// Campaigns read from their JSON file (every field checked, messages name file and field), and what
// follows from a campaign alone: its cases' values and scenes, its table's columns, its fingerprint.
// Running the cases, the journal and the tables: sweep.cpp.
#include "plate/sweep.hpp"

#include "plate/output.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace plate::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kMaxCases = 10'000'000;

// ---- reading a campaign file: every field checked, messages name file and field ---------------

struct Reader {
    std::string source;
    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw InputError(source + ": " + field + ": " + what);
    }
    void only(const json& o, const std::string& field, const std::set<std::string>& keys) const {
        if (!o.is_object()) fail(field.empty() ? "the file" : field, "expected an object");
        for (const auto& [k, v] : o.items())
            if (!keys.count(k)) {
                std::string known;
                for (const auto& s : keys) known += (known.empty() ? "" : ", ") + s;
                fail(field.empty() ? k : field + "." + k, "unknown field (known: " + known + ")");
            }
    }
    const json& need(const json& o, const std::string& field, const std::string& key) const {
        if (!o.contains(key)) fail(field.empty() ? key : field + "." + key, "missing");
        return o.at(key);
    }
    double number(const json& v, const std::string& field) const {
        if (!v.is_number() || !std::isfinite(v.get<double>())) fail(field, "expected a finite number");
        return v.get<double>();
    }
    long whole(const json& v, const std::string& field, long lo, long hi) const {
        const double x = number(v, field);
        if (x != std::floor(x) || x < lo || x > hi)
            fail(field, "expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi));
        return static_cast<long>(x);
    }
    std::string text(const json& v, const std::string& field) const {
        if (!v.is_string() || v.get<std::string>().empty()) fail(field, "expected a non-empty string");
        return v.get<std::string>();
    }
    std::vector<double> numbers(const json& v, const std::string& field, std::size_t lo, std::size_t hi) const {
        if (!v.is_array() || v.size() < lo || v.size() > hi)
            fail(field, "expected an array of " + std::to_string(lo) + (lo < hi ? " to " + std::to_string(hi) : "") + " numbers");
        std::vector<double> x;
        for (std::size_t i = 0; i < v.size(); ++i) x.push_back(number(v[i], field + "[" + std::to_string(i) + "]"));
        return x;
    }
};

json read_json_file(const std::string& path, const std::string& what) {
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot open " + what);
    std::stringstream s;
    s << in.rdbuf();
    try {
        return json::parse(s.str());
    } catch (const json::parse_error& e) {
        throw InputError(path + ": malformed JSON: " + e.what());
    }
}

// splitmix64: the random case values depend on (seed, index, parameter) only.
std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

// The base scene (into c.base): a path relative to the campaign file, or (sent between ranks)
// inlined. Returns the name its errors are reported under.
std::string read_base_scene(const Reader& r, const json& file, const std::string& source, Campaign& c) {
    const json& scene = r.need(file, "", "scene");
    std::string scene_source = source + ": scene";
    if (scene.is_string()) {
        fs::path p = r.text(scene, "scene");
        if (p.is_relative()) p = fs::path(source).parent_path() / p;
        scene_source = p.string();
        try {
            c.base = read_json_file(p.string(), "the scene file");
        } catch (const InputError& e) {
            r.fail("scene", e.what());
        }
    } else if (scene.is_object()) {
        c.base = scene;
    } else {
        r.fail("scene", "expected the base scene's file name");
    }
    return scene_source;
}

// "sampling": "grid" (the default) or {"random": N, "seed": S}.
void read_sampling(const Reader& r, const json& file, Campaign& c) {
    const json sampling = file.value("sampling", json("grid"));
    if (sampling.is_string() && sampling.get<std::string>() == "grid") {
        c.random = false;
    } else if (sampling.is_object()) {
        r.only(sampling, "sampling", {"random", "seed"});
        c.random = true;
        c.samples = static_cast<int>(r.whole(r.need(sampling, "sampling", "random"), "sampling.random", 1, kMaxCases));
        if (sampling.contains("seed"))
            c.seed = static_cast<std::uint64_t>(r.whole(sampling["seed"], "sampling.seed", 0, 1L << 52));
    } else {
        r.fail("sampling", "expected \"grid\" or {\"random\": N, \"seed\": S}");
    }
}

// "parameters": each a name, a JSON pointer into the base scene and its values (a list, a range, or
// for random sampling an interval).
void read_parameters(const Reader& r, const json& file, const std::string& scene_source, Campaign& c) {
    const json& ps = r.need(file, "", "parameters");
    if (!ps.is_array() || ps.empty() || ps.size() > 16) r.fail("parameters", "expected an array of 1 to 16 parameters");
    std::set<std::string> names;
    for (std::size_t i = 0; i < ps.size(); ++i) {
        const std::string f = "parameters[" + std::to_string(i) + "]";
        const json& p = ps[i];
        r.only(p, f, {"name", "pointer", "values", "from", "to", "count"});
        Parameter q;
        q.name = r.text(r.need(p, f, "name"), f + ".name");
        if (q.name.find_first_of(",\"\n\r") != std::string::npos) r.fail(f + ".name", "no commas, quotes or line breaks");
        if (!names.insert(q.name).second) r.fail(f + ".name", "'" + q.name + "' named twice");
        q.pointer = r.text(r.need(p, f, "pointer"), f + ".pointer");
        try {
            const json::json_pointer ptr(q.pointer);
            const bool numbers =
                c.base.contains(ptr) && c.base.at(ptr).is_array() && !c.base.at(ptr).empty() &&
                std::all_of(c.base.at(ptr).begin(), c.base.at(ptr).end(), [](const json& x) { return x.is_number(); });
            if (!c.base.contains(ptr) || !(c.base.at(ptr).is_number() || numbers))
                r.fail(f + ".pointer",
                       "'" + q.pointer + "' addresses no number (or array of numbers) of the base scene " + scene_source);
        } catch (const json::exception&) {
            r.fail(f + ".pointer", "'" + q.pointer + "' is no JSON pointer (RFC 6901, e.g. /plate/harmonics/0/amp)");
        }
        const bool range = p.contains("from") || p.contains("to");
        if (c.random) {
            if (p.contains("values") || p.contains("count")) r.fail(f, "random sampling takes \"from\" and \"to\" only");
            q.from = r.number(r.need(p, f, "from"), f + ".from");
            q.to = r.number(r.need(p, f, "to"), f + ".to");
            if (!(q.to >= q.from)) r.fail(f + ".to", "expected to >= from");
        } else if (p.contains("values")) {
            if (range || p.contains("count")) r.fail(f, "either \"values\" or \"from\", \"to\", \"count\"");
            q.values = r.numbers(p["values"], f + ".values", 1, kMaxCases);
        } else {
            const double a = r.number(r.need(p, f, "from"), f + ".from"), b = r.number(r.need(p, f, "to"), f + ".to");
            const long n = r.whole(r.need(p, f, "count"), f + ".count", 1, kMaxCases);
            if (n == 1 && a != b) r.fail(f + ".count", "1 value needs from == to");
            for (long k = 0; k < n; ++k)
                q.values.push_back(n == 1       ? a
                                   : k == n - 1 ? b
                                                : a + (b - a) * static_cast<double>(k) / static_cast<double>(n - 1));
        }
        c.parameters.push_back(q);
    }
    if (!c.random) {
        double n = 1;
        for (const auto& p : c.parameters) n *= static_cast<double>(p.values.size());
        if (n > kMaxCases) r.fail("parameters", "more than " + std::to_string(kMaxCases) + " cases");
    }
}

// "compute": {"field": {...}}: the grid of each case's field.
void read_field(const Reader& r, const json& f, std::size_t d, const Scene& base, Campaign& c) {
    r.only(f, "compute.field", {"grid", "x", "y", "theta0"});
    if (f.contains("grid")) {
        const auto g = r.numbers(f["grid"], "compute.field.grid", d, d);
        for (std::size_t i = 0; i < d; ++i)
            if (g[i] != std::floor(g[i]) || g[i] < 1 || g[i] > 201)
                r.fail("compute.field.grid", "expected whole numbers from 1 to 201");
        c.grid.nx = static_cast<int>(g[0]);
        c.grid.ny = static_cast<int>(g[1]);
        c.grid.nth = d == 3 ? static_cast<int>(g[2]) : 1;
    }
    if (base.part.point) c.grid.nth = 1;
    if (c.grid.size() > 1'000'000) r.fail("compute.field.grid", "at most 10^6 configurations per case");
    if (f.contains("x")) {
        const auto x = r.numbers(f["x"], "compute.field.x", 2, 2);
        c.grid.x0 = x[0];
        c.grid.x1 = x[1];
    }
    if (f.contains("y")) {
        const auto y = r.numbers(f["y"], "compute.field.y", 2, 2);
        c.grid.y0 = y[0];
        c.grid.y1 = y[1];
    }
    if (f.contains("theta0")) c.grid.th0 = r.number(f["theta0"], "compute.field.theta0");
    if (!(c.grid.x1 >= c.grid.x0) || !(c.grid.y1 >= c.grid.y0)) r.fail("compute.field", "x and y are [MIN, MAX] with MIN <= MAX");
}

// "compute": {"design": {...}}: the target and the search, judged by the library on the base scene.
void read_design(const Reader& r, const json& g, const Scene& base, Campaign& c) {
    r.only(g, "compute.design", {"target", "limits", "corner_limits", "plate_half_size", "starts", "evaluations", "seed"});
    // [KIND, numbers...]: the library's parser and judgement, as the CLI's --target and Python's target=
    const json& t = r.need(g, "compute.design", "target");
    if (!t.is_array() || t.empty() || t.size() > 100 || !t[0].is_string())   // (the count: the parser's)
        r.fail("compute.design.target", "expected [KIND, numbers...]: " + design_target_usage());
    std::vector<double> values;
    for (std::size_t i = 1; i < t.size(); ++i)
        values.push_back(r.number(t[i], "compute.design.target[" + std::to_string(i) + "]"));
    try {
        c.design = parse_design_target(t[0].get<std::string>(), values, base.part.point);
    } catch (const std::invalid_argument& e) {
        r.fail("compute.design.target", e.what());
    }
    // [A, B] fields: plate design's pairs of numbers, judged with the rest by validate_design_options below
    const auto pair = [&](const char* key, double& a, double& b) {
        if (!g.contains(key)) return;
        const auto v = r.numbers(g[key], std::string("compute.design.") + key, 2, 2);
        a = v[0];
        b = v[1];
    };
    DesignOptions& o = c.design_options;
    pair("limits", o.lin_limit, o.ang_limit);
    pair("corner_limits", o.corner_displacement_limit, o.corner_velocity_limit);
    pair("plate_half_size", o.plate_half_size.x(), o.plate_half_size.y());
    if (g.contains("starts")) c.design_options.starts = static_cast<int>(r.whole(g["starts"], "compute.design.starts", 1, 10000));
    if (g.contains("evaluations"))
        c.design_options.local_evaluations =
            static_cast<int>(r.whole(g["evaluations"], "compute.design.evaluations", 1, 1'000'000));
    if (g.contains("seed"))
        c.design_options.seed = static_cast<std::uint64_t>(r.whole(g["seed"], "compute.design.seed", 0, 1L << 52));
    c.design_options.threads = 1;   // one case, one thread: the farm shares the cases
    try {                           // (the limits and the target judged once, in the library, on the base scene)
        validate_design_options(c.design_options);
        validate_design_target(*c.design, base, c.design_options);
    } catch (const std::invalid_argument& e) {
        r.fail("compute.design", e.what());
    }
}

// "compute": what each case computes.
void read_compute(const Reader& r, const json& file, const Scene& base, Campaign& c) {
    const json& comp = r.need(file, "", "compute");
    r.only(comp, "compute", {"twist_at", "field", "fixed_points", "design", "cycle"});
    const std::size_t d = base.part.point ? 2 : 3;
    if (comp.contains("twist_at")) {
        const json& t = comp["twist_at"];
        if (!t.is_array() || t.size() > 100) r.fail("compute.twist_at", "expected an array of up to 100 configurations");
        for (std::size_t i = 0; i < t.size(); ++i) {
            const auto v = r.numbers(t[i], "compute.twist_at[" + std::to_string(i) + "]", d, d);
            c.twist_at.push_back(Vec3(v[0], v[1], d == 3 ? v[2] : 0.0));
        }
    }
    if (comp.contains("field")) {
        c.field = true;
        read_field(r, comp["field"], d, base, c);
    }
    if (comp.contains("fixed_points")) {
        if (!comp["fixed_points"].is_boolean()) r.fail("compute.fixed_points", "expected true or false");
        c.fixed_points = comp["fixed_points"].get<bool>();
        if (c.fixed_points && !c.field) r.fail("compute.fixed_points", "needs compute.field (the grid searched)");
    }
    if (comp.contains("design")) read_design(r, comp["design"], base, c);
    c.cycle.max_rhs_evaluations = 2'000'000;   // as the command line's (about 0.3 s per cycle)
    if (comp.contains("cycle")) {
        const json& y = comp["cycle"];
        r.only(y, "compute.cycle", {"tol", "rtol", "max_periods", "max_rhs"});
        if (y.contains("tol")) c.cycle.tol = r.number(y["tol"], "compute.cycle.tol");
        if (y.contains("rtol")) c.cycle.integration.rtol = r.number(y["rtol"], "compute.cycle.rtol");
        if (y.contains("max_periods"))
            c.cycle.max_periods = static_cast<int>(r.whole(y["max_periods"], "compute.cycle.max_periods", 2, 100000));
        if (y.contains("max_rhs"))
            c.cycle.max_rhs_evaluations = r.whole(y["max_rhs"], "compute.cycle.max_rhs", 1000, 1'000'000'000'000L);
        if (!(c.cycle.tol > 0) || !(c.cycle.integration.rtol > 0 && c.cycle.integration.rtol < 1e-2))
            r.fail("compute.cycle", "tol must be > 0 and rtol in (0, 1e-2)");
    }
    if (c.twist_at.empty() && !c.field && !c.design)
        r.fail("compute", "nothing to compute (twist_at, field, fixed_points or design)");
}

// A parameter named like a column the case itself fills would be overwritten by it.
void check_parameter_names(const Reader& r, const Campaign& c) {
    std::set<std::string> builtin{"fixed_points"};   // (the JSON-lines table's list of fixed points)
    {
        const std::vector<std::string> col = columns(c);
        builtin.insert(col.begin() + 1 + static_cast<long>(c.parameters.size()), col.end());
        builtin.insert("case");
    }
    for (std::size_t i = 0; i < c.parameters.size(); ++i)
        if (builtin.count(c.parameters[i].name))
            r.fail("parameters[" + std::to_string(i) + "].name",
                   "'" + c.parameters[i].name + "' is a column the table fills itself; choose another name");
}

}   // namespace

int Campaign::cases() const {
    if (random) return samples;
    long n = 1;
    for (const auto& p : parameters) n *= static_cast<long>(p.values.size());
    return static_cast<int>(n);
}

Campaign campaign_from_json(const json& file, const std::string& source) {
    const Reader r{source};
    r.only(file, "", {"name", "scene", "sampling", "parameters", "compute"});
    Campaign c;
    c.source = source;
    c.name = r.text(r.need(file, "", "name"), "name");
    const std::string scene_source = read_base_scene(r, file, source, c);
    const Scene base = parse_scene(c.base.dump(), scene_source);   // (throws InputError naming the file)
    read_sampling(r, file, c);
    read_parameters(r, file, scene_source, c);
    read_compute(r, file, base, c);
    check_parameter_names(r, c);
    c.file = file;
    c.file["scene"] = c.base;
    return c;
}

Campaign load_campaign(const std::string& path) {
    Campaign c = campaign_from_json(read_json_file(path, "campaign file"), path);
    return c;
}

std::string fingerprint(const Campaign& c) {
    return fnv1a_hex(c.file.dump());   // (keys sorted: a canonical text)
}

std::vector<double> case_values(const Campaign& c, int index) {
    std::vector<double> v(c.parameters.size());
    if (c.random) {
        std::uint64_t state = c.seed * 0xD1B54A32D192ED03ULL + static_cast<std::uint64_t>(index);
        for (std::size_t p = 0; p < v.size(); ++p) {
            const double u = static_cast<double>(splitmix(state) >> 11) * 0x1.0p-53;
            v[p] = c.parameters[p].from + u * (c.parameters[p].to - c.parameters[p].from);
        }
        return v;
    }
    long rest = index;   // mixed radix, the last parameter fastest
    for (std::size_t p = v.size(); p-- > 0;) {
        const long n = static_cast<long>(c.parameters[p].values.size());
        v[p] = c.parameters[p].values[static_cast<std::size_t>(rest % n)];
        rest /= n;
    }
    return v;
}

Scene case_scene(const Campaign& c, int index) {
    json s = c.base;
    const std::vector<double> v = case_values(c, index);
    for (std::size_t p = 0; p < v.size(); ++p) {
        json& x = s[json::json_pointer(c.parameters[p].pointer)];
        if (x.is_array())   // every element (e.g. /part/friction: every contact's)
            for (json& e : x) e = v[p];
        else
            x = v[p];
    }
    return parse_scene(s.dump(), c.name + " case " + std::to_string(index));
}

std::vector<std::string> columns(const Campaign& c) {
    const bool point = c.base.contains("part") && !c.base["part"].contains("contacts");
    std::vector<std::string> col{"case"};
    for (const auto& p : c.parameters) col.push_back(p.name);
    for (const char* s : {"status", "reason", "note", "rhs_evaluations"}) col.push_back(s);
    for (std::size_t k = 0; k < c.twist_at.size(); ++k) {
        const std::string t = "twist" + std::to_string(k) + "_";
        col.push_back(t + "vx");
        col.push_back(t + "vy");
        if (!point) col.push_back(t + "omega");
        col.push_back(t + "stick");
    }
    if (c.field) {
        for (const char* s : {"field_defined", "field_contact_lost", "field_unconverged", "field_mean_speed", "field_max_speed"})
            col.push_back(s);
        if (!point) col.push_back("field_mean_abs_omega");
        col.push_back("field_mean_stick");
    }
    if (c.fixed_points) {
        for (const char* s : {"fp_stable", "fp_saddle", "fp_unstable", "fp_lines", "fp_undefined_cells", "stable_x", "stable_y"})
            col.push_back(s);
        if (!point) col.push_back("stable_theta");
        col.push_back("stable_rate");
        col.push_back("fp_summary");
    }
    if (c.design)
        for (const char* s : {"design_verified", "design_unique", "design_x", "design_y", "design_rate",
                              "design_worst_end_distance", "design_evaluations"})
            col.push_back(s);
    return col;
}

std::string column_heading(const Campaign& c, const std::string& column) {
    for (const auto& p : c.parameters)
        if (p.name == column) return column + " [as " + p.pointer + "]";
    auto ends = [&](const char* tail) {
        const std::string t(tail);
        return column.size() >= t.size() && column.compare(column.size() - t.size(), t.size(), t) == 0;
    };
    const char* unit = nullptr;
    if (column.rfind("twist", 0) == 0)
        unit = ends("_omega") ? "rad/s" : ends("_stick") ? "period" : "m/s";
    else if (column == "field_mean_speed" || column == "field_max_speed")
        unit = "m/s";
    else if (column == "field_mean_abs_omega")
        unit = "rad/s";
    else if (column == "field_mean_stick")
        unit = "period";
    else if (column == "stable_x" || column == "stable_y" || column == "design_x" || column == "design_y" ||
             column == "design_worst_end_distance")
        unit = "m";
    else if (column == "stable_theta")
        unit = "rad";
    else if (column == "stable_rate" || column == "design_rate")
        unit = "1/s";
    return unit ? column + " [" + unit + "]" : column;
}

}   // namespace plate::sweep
