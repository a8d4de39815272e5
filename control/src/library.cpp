// The library of motions, the controller's model (each motion's field, tabulated once) and the goal.
#include "plate/control.hpp"

#include "input_reader.hpp"
#include "internal.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace plate {

using detail::Reader;
using nlohmann::json;

namespace {

bool same_part(const Part& a, const Part& b) {
    if (a.point != b.point || a.m != b.m || a.mu != b.mu || a.mu_static.has_value() != b.mu_static.has_value()) return false;
    if (a.mu_static && *a.mu_static != *b.mu_static) return false;
    if (a.point) return true;
    if (a.J != b.J) return false;
    for (int i = 0; i < 3; ++i)
        if (a.c[i] != b.c[i]) return false;
    return true;
}

}   // namespace

MotionLibrary load_motion_library(const std::string& path, const Scene& nominal) {
    return parse_motion_library(detail::read_input_file(path, "motion library"), path,
                                std::filesystem::path(path).parent_path().string(), nominal);
}

MotionLibrary parse_motion_library(const std::string& text, const std::string& source, const std::string& dir,
                                   const Scene& nominal) {
    const Reader r{source};
    const json doc = r.parse(text);
    r.only_keys(doc, "", {"motions"}, {"motions"});
    const json& M = doc["motions"];
    if (!M.is_array() || M.empty()) r.fail("motions", "expected a non-empty array of motions");
    MotionLibrary lib;
    lib.source = source;
    for (std::size_t k = 0; k < M.size(); ++k) {
        const std::string f = "motions[" + std::to_string(k) + "]";
        const json& m = M[k];
        r.only_keys(m, f, {"name", "scene", "still"}, {"name"});
        if (!m["name"].is_string() || m["name"].get<std::string>().empty()) r.fail(f + ".name", "expected a non-empty string");
        const std::string name = m["name"].get<std::string>();
        if (std::find(lib.names.begin(), lib.names.end(), name) != lib.names.end())
            r.fail(f + ".name", "\"" + name + "\" is listed twice");
        const bool still = m.contains("still");
        if (still && (!m["still"].is_boolean() || !m["still"].get<bool>())) r.fail(f + ".still", "expected true");
        if (still == m.contains("scene")) r.fail(f, "expected exactly one of \"scene\" and \"still\"");
        PlateMotion u;
        u.T = nominal.plate.T;
        if (still) {
            if (lib.still >= 0) r.fail(f + ".still", "a second still plate");
            lib.still = static_cast<int>(k);
        } else {
            if (!m["scene"].is_string()) r.fail(f + ".scene", "expected a scene file's path");
            const std::filesystem::path p = std::filesystem::path(dir) / m["scene"].get<std::string>();
            const Scene sc = load_scene(p.string());
            if (!same_part(sc.part, nominal.part))
                r.fail(f + ".scene", p.string() + ": its part differs from the controlled scene's (" + nominal.source + ")");
            if (sc.plate.T != nominal.plate.T)
                r.fail(f + ".scene", p.string() + ": period " + Reader::fmt(sc.plate.T) + " s, not the controlled scene's " +
                                         Reader::fmt(nominal.plate.T) + " s: every motion must share the period");
            u = sc.plate;
        }
        lib.names.push_back(name);
        lib.motions.push_back(u);
    }
    return lib;
}

namespace {

// Index and weight of x on a grid axis of n points from x0 spaced h, clamped to the grid.
void axis_cell(double x, double x0, double h, int n, int& i, double& w) {
    if (n < 2 || h <= 0) {
        i = 0;
        w = 0;
        return;
    }
    const double u = std::clamp((x - x0) / h, 0.0, static_cast<double>(n - 1));
    i = std::min(static_cast<int>(u), n - 2);
    w = u - i;
}

// A point part, or a rigid part whose contacts share one friction coefficient (kinetic and static): on a
// plate that only translates the latter moves as the point part does, without turning, at every
// position and orientation (design_target.hpp's transport), so its field there is uniform too.
bool moves_as_point(const Part& part) {
    if (part.point) return true;
    const ContactFriction mu = part.friction();
    for (int i = 1; i < part.contacts(); ++i)
        if (mu.kinetic(i) != mu.kinetic(0) || mu.static_(i) != mu.static_(0)) return false;
    return true;
}

}   // namespace

Vec3 MotionField::at(const Vec3& q) const {
    if (uniform) return twist[0];
    int i, j;
    double wx, wy;
    axis_cell(q.x(), grid.x0, grid.dx(), grid.nx, i, wx);
    axis_cell(q.y(), grid.y0, grid.dy(), grid.ny, j, wy);
    const int i1 = grid.nx > 1 ? i + 1 : i, j1 = grid.ny > 1 ? j + 1 : j;
    int k = 0, k1 = 0;
    double wt = 0;
    if (grid.nth > 1) {   // periodic in theta
        const double u = (q.z() - grid.th0) / grid.dth();
        const double fl = std::floor(u);
        k = static_cast<int>(fl - grid.nth * std::floor(fl / grid.nth));
        k1 = (k + 1) % grid.nth;
        wt = u - fl;
    }
    auto v = [&](int a, int b, int c) { return twist[grid.index(a, b, c)]; };
    auto plane = [&](int c) {
        return ((1 - wx) * ((1 - wy) * v(i, j, c) + wy * v(i, j1, c)) + wx * ((1 - wy) * v(i1, j, c) + wy * v(i1, j1, c))).eval();
    };
    return grid.nth > 1 ? Vec3((1 - wt) * plane(k) + wt * plane(k1)) : plane(0);
}

void ControlModelOptions::validate() const {
    if (grid.nx < 2 || grid.ny < 2 || grid.nth < 1) throw std::invalid_argument("grid: expected nx, ny >= 2 and nth >= 1");
    if (!(grid.x1 > grid.x0) || !(grid.y1 > grid.y0)) throw std::invalid_argument("grid: expected x0 < x1 and y0 < y1");
}

ControlModel build_control_model(const Scene& nominal, MotionLibrary library, const ControlModelOptions& opt) {
    opt.validate();
    ControlModel m;
    m.nominal = nominal;
    m.library = std::move(library);
    const Reader r{m.library.source};
    for (std::size_t k = 0; k < m.library.motions.size(); ++k) {
        const PlateMotion& u = m.library.motions[k];
        const std::string f = "motions[" + std::to_string(k) + "] (" + m.library.names[k] + ")";
        MotionField fld;
        Scene sc = nominal;
        sc.plate = u;
        const bool translates = std::all_of(u.harmonics.begin(), u.harmonics.end(), [](const Harmonic& h) {
            return h.axis == Axis::x || h.axis == Axis::y || h.axis == Axis::z;
        });
        if (u.harmonics.empty() || (translates && moves_as_point(nominal.part))) {
            fld.uniform = true;
            Vec3 xi = Vec3::Zero();   // a still plate: a part at rest stays put
            try {
                if (!u.harmonics.empty()) xi = field_at(sc, Vec3::Zero(), opt.field.cycle);
            } catch (const FieldUndefined& e) {
                r.fail(f, std::string("its field is undefined: ") + e.what());
            }
            fld.twist = {xi};
        } else {
            GridSpec g = opt.grid;
            if (nominal.part.point) g.nth = 1;
            const Field field = compute_field(sc, g, opt.field);
            for (const FieldPoint& p : field.points)
                if (!p.converged && p.stop != StopReason::Sticking)
                    r.fail(f, "its field is undefined at (" + Reader::fmt(p.q.x()) + ", " + Reader::fmt(p.q.y()) +
                                  "): " + stop_name(p.stop));
            fld.grid = g;
            for (const FieldPoint& p : field.points) fld.twist.push_back(p.converged ? p.twist : Vec3::Zero());
        }
        m.fields.push_back(std::move(fld));
    }
    if (opt.transitions) detail::add_transitions(m, opt);
    return m;
}

Vec3 ControlModel::step(int from, int to, const Vec3& q) const {
    if (from < 0 || from == to || transitions.empty() || transitions[from * motions() + to].twist.empty())
        return fields[to].at(q) * T();
    return transitions[from * motions() + to].at(q) * T();
}

double Goal::error(const Vec3& x) const { return std::hypot(x.x() - q.x(), x.y() - q.y()); }
double Goal::theta_error(const Vec3& x) const { return point ? 0.0 : std::abs(wrap_angle(x.z() - q.z())); }
bool Goal::within(const Vec3& x) const { return error(x) <= tolerance && theta_error(x) <= tolerance_theta; }
double Goal::distance(const Vec3& x) const { return std::hypot(error(x), theta_weight * theta_error(x)); }

}   // namespace plate
