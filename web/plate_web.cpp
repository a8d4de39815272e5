// The playground's API (issue 55): one C function, JSON in and JSON out, over the numeric core
// compiled to WebAssembly (web/CMakeLists.txt). The scene is the scene file's text, read and judged
// by the same parse_scene as `plate field`, so a bad scene gets the program's own messages; the field
// and fixed points are written by the program's own to_json.
//
//   request  {"op": "scene" | "field" | "fixed_points" | "trajectory" | "design", "scene": TEXT, "source": NAME, ...}
//            or {"op": "about"} (whether this module designs: {"design": true} or {"design": false, "why": ...})
//     field, fixed_points: "grid": {"nx", "ny", "x": [MIN, MAX], "y": [MIN, MAX], "theta": THETA},
//                          "max_work": right-hand sides (default a tenth of `plate field`'s)
//                          (a rigid part's field is the slice at theta; a point part has no theta)
//     trajectory:          "q0": [s_x, s_y(, theta)], "duration": s, "dt": s (full dynamics from rest)
//     design:              a point part's sink (plate_web_design.cpp)
//   answer   {"ok": true, ...} or {"ok": false, "error": MESSAGE}
#include "plate_web.hpp"

#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <exception>
#include <string>

namespace plate::web {
namespace {

using nlohmann::json;

Scene scene_of(const json& rq) {
    return parse_scene(rq.at("scene").get<std::string>(), rq.value("source", std::string("scene")));
}

// The grid of a field request: nx x ny over [x0, x1] x [y0, y1] at one theta (the slice).
GridSpec grid_of(const json& rq) {
    const json& g = rq.at("grid");
    GridSpec grid;
    grid.nx = g.value("nx", 7);
    grid.ny = g.value("ny", 7);
    grid.nth = 1;
    grid.th0 = g.value("theta", 0.0);
    if (g.contains("x")) grid.x0 = g["x"].at(0), grid.x1 = g["x"].at(1);
    if (g.contains("y")) grid.y0 = g["y"].at(0), grid.y1 = g["y"].at(1);
    if (grid.nx < 1 || grid.ny < 1 || grid.nx > 201 || grid.ny > 201)
        throw std::invalid_argument("grid: nx and ny must be within 1..201");
    if (!(grid.x1 >= grid.x0) || !(grid.y1 >= grid.y0)) throw std::invalid_argument("grid: x and y take MIN MAX with MIN <= MAX");
    return grid;
}

// The field of the request's scene and grid. The last one is kept: the page asks for a field, then for
// its fixed points, and the second request finds the field it needs here.
const Field& field_of(const Scene& sc, const json& rq) {
    static std::string last_key;
    static Field last;
    const GridSpec grid = grid_of(rq);
    const std::string key = rq.at("scene").get<std::string>() + "\n" + rq.at("grid").dump();
    if (key != last_key) {
        last_key.clear();
        FieldOptions fo;
        fo.threads = 1;   // (no threads in the browser's module; the field is the same on any number)
        // Bounded as `plate field` bounds it (field.hpp): refused up front when estimated over the
        // budget, stopped (and refused) if it spends it anyway. A tenth of the program's default: tens
        // of seconds in a page.
        fo.max_rhs_evaluations = rq.value("max_work", kDefaultFieldWork / 10);
        require_field_work(sc, grid, fo.cycle, fo.max_rhs_evaluations, "the request's max_work");
        last = compute_field(sc, grid, fo);
        if (last.budget_spent) throw std::invalid_argument("the field spent its work budget (max_work) before it was complete");
        last_key = key;
    }
    return last;
}

json trajectory_of(const Scene& sc, const json& rq) {
    const json& q = rq.at("q0");
    const Vec3 q0(q.at(0), q.at(1), sc.part.point || q.size() < 3 ? 0.0 : q[2].get<double>());
    const double duration = rq.value("duration", 10 * sc.plate.T), dt = rq.value("dt", sc.plate.T / 4);
    if (!(duration > 0) || !(dt > 0) || duration / dt > 1e5)
        throw std::invalid_argument("trajectory: duration and dt must be > 0, at most 1e5 samples");
    const Trajectory tr = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), duration, dt);
    json t = json::array(), qs = json::array(), modes = json::array(), held = json::array();
    for (const Sample& s : tr.samples) {
        t.push_back(s.t);
        qs.push_back({s.q[0], s.q[1], s.q[2]});
        modes.push_back(mode_name(s.mode));
        held.push_back({s.mode.holds(0), s.mode.holds(1), s.mode.holds(2)});
    }
    return {{"t", t},
            {"q", qs},
            {"mode", modes},
            {"held", held},
            {"stop", stop_name(tr.stop.reason)},
            {"stop_words", tr.stop.reason == StopReason::None ? std::string() : tr.stop.describe()}};
}

json answer(const json& rq) {
    const std::string op = rq.at("op");
    json out = {{"ok", true}};
    if (op == "about") {
        std::string why;
        out["design"] = design_available(why);
        if (!why.empty()) out["why"] = why;
        return out;
    }
    const Scene sc = scene_of(rq);
    if (op == "scene") {
        out["scene"] = scene_to_json(sc);
        out["warnings"] = scene_warnings(sc);
        out["point_part"] = sc.part.point;
    } else if (op == "field") {
        out["field"] = to_json(sc, field_of(sc, rq));
        out["warnings"] = scene_warnings(sc);
    } else if (op == "fixed_points") {
        const Field& f = field_of(sc, rq);
        out["field"] = to_json(sc, f);
        FixedPointOptions fo;
        fo.max_orbit_starts = 0;   // (a slice has one theta: no orbit turns through it)
        out["fixed_points"] = to_json(sc, find_fixed_points(sc, f, fo));
    } else if (op == "trajectory") {
        out["trajectory"] = trajectory_of(sc, rq);
    } else if (op == "design") {
        out["design"] = design_answer(sc, rq);
    } else {
        throw std::invalid_argument("unknown op '" + op + "' (expected about, scene, field, fixed_points, trajectory or design)");
    }
    return out;
}

}   // namespace
}   // namespace plate::web

// The answer stays valid until the next call (the JS side copies it at once).
extern "C" const char* plate_call(const char* request) {
    static std::string reply;
    using nlohmann::json;
    const auto t0 = std::chrono::steady_clock::now();
    json out;
    try {
        out = plate::web::answer(json::parse(request));
    } catch (const std::exception& e) {
        out = {{"ok", false}, {"error", e.what()}};
    }
    out["milliseconds"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    reply = out.dump();
    return reply.c_str();
}
