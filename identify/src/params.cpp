// The named parameters of an identification: which part's number each sets, the solver's internal
// coordinates (static as an excess over kinetic, so that static >= kinetic by construction) and the
// one function that applies them to a scene.
#include "internal.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plate {
namespace identify_detail {
namespace {

Param parse_name(const std::string& n, bool point) {
    Param q;
    q.name = n;
    if (n == "mu_k" || n == "mu_s") {
        q.kind = n == "mu_k" ? Param::Kinetic : Param::Static;
        return q;
    }
    if (n.size() == 5 && (n.rfind("mu_k", 0) == 0 || n.rfind("mu_s", 0) == 0) && n[4] >= '1' && n[4] <= '3') {
        if (point) throw std::invalid_argument(n + ": a point part has one contact (use " + n.substr(0, 4) + ")");
        q.kind = n[3] == 'k' ? Param::Kinetic : Param::Static;
        q.contact = n[4] - '1';
        return q;
    }
    if (n == "com_x" || n == "com_y") {
        if (point) throw std::invalid_argument(n + ": a point part has no centre-of-mass offset (its one contact is its centre)");
        q.kind = n == "com_x" ? Param::ComX : Param::ComY;
        return q;
    }
    throw std::invalid_argument(n + ": no such parameter (mu_k, mu_k1..3, mu_s, mu_s1..3, com_x, com_y)");
}

}   // namespace

Layout::Layout(const Scene& scene, const std::vector<std::string>& names) : part(scene.part) {
    if (names.empty()) throw std::invalid_argument("no parameter to fit");
    bool kinetic[3] = {false, false, false}, static_[3] = {false, false, false}, com[2] = {false, false};
    for (const std::string& n : names) {
        const Param q = parse_name(n, scene.part.point);
        if (q.kind == Param::ComX || q.kind == Param::ComY) {
            bool& seen = com[q.kind == Param::ComY];
            if (seen) throw std::invalid_argument(n + ": given twice");
            seen = true;
        } else {
            bool* seen = q.kind == Param::Kinetic ? kinetic : static_;
            for (int i = 0; i < 3; ++i)
                if (q.contact < 0 || q.contact == i) {
                    if (seen[i])
                        throw std::invalid_argument(n + ": contact " + std::to_string(i + 1) +
                                                    "'s coefficient is fitted by another name too");
                    seen[i] = true;
                }
        }
        p.push_back(q);
    }
}

std::vector<double> Layout::natural(const std::vector<double>& x) const {
    Vec3 mu = part.mu;
    for (int j = 0; j < size(); ++j)
        if (p[j].kind == Param::Kinetic) {
            if (p[j].contact < 0)
                mu.setConstant(x[j]);
            else
                mu[p[j].contact] = x[j];
        }
    const int n = part.contacts();
    std::vector<double> v(x);
    for (int j = 0; j < size(); ++j) {
        if (p[j].kind == Param::Static) v[j] = x[j] + (p[j].contact < 0 ? mu.head(n).maxCoeff() : mu[p[j].contact]);
        if (p[j].kind == Param::ComX || p[j].kind == Param::ComY) v[j] = x[j] * 1e-3;
    }
    return v;
}

std::vector<double> Layout::internal(const std::vector<double>& v) const {
    std::vector<double> x(v);
    for (int j = 0; j < size(); ++j)
        if (p[j].kind == Param::ComX || p[j].kind == Param::ComY) x[j] = v[j] * 1e3;
    // The kinetic ones are themselves: the statics' bases follow from them.
    const std::vector<double> base = natural(x);
    for (int j = 0; j < size(); ++j)
        if (p[j].kind == Param::Static) x[j] = v[j] - (base[j] - x[j]);
    return x;
}

std::vector<double> Layout::scene_values() const {
    const Vec3 mus = part.mu_static ? *part.mu_static : part.mu;
    std::vector<double> v;
    for (const Param& q : p) {
        const int i = std::max(q.contact, 0);
        if (q.kind == Param::Kinetic) v.push_back(q.contact < 0 ? part.mu.head(part.contacts()).mean() : part.mu[i]);
        if (q.kind == Param::Static) v.push_back(q.contact < 0 ? mus.head(part.contacts()).maxCoeff() : mus[i]);
        if (q.kind == Param::ComX || q.kind == Param::ComY) v.push_back(0);
    }
    // Raised where a static value lies below the kinetic one it must exceed.
    std::vector<double> x = internal(v);
    for (int j = 0; j < size(); ++j)
        if (p[j].kind == Param::Static) x[j] = std::max(x[j], 0.0);
    return natural(x);
}

double Layout::lower(int j, const IdentifyOptions& o) const {
    if (p[j].kind == Param::Kinetic) return o.mu_min;
    if (p[j].kind == Param::Static) return 0;
    return -o.com_max * 1e3;
}

double Layout::upper(int j, const IdentifyOptions& o) const {
    if (p[j].kind == Param::Kinetic) return o.mu_max;
    if (p[j].kind == Param::Static) return o.mu_max - o.mu_min;
    return o.com_max * 1e3;
}

double Layout::range(int j, const IdentifyOptions& o) const { return upper(j, o) - lower(j, o); }

// Friction: 1e-4 (a hundredth of the accuracy asked, far above the simulation's relative error, rtol 1e-7);
// centre of mass: 1e-3 mm.
double Layout::step(int j) const { return p[j].kind == Param::ComX || p[j].kind == Param::ComY ? 1e-3 : 1e-4; }

Scene at(const Scene& scene, const Layout& layout, const std::vector<double>& x) {
    std::vector<std::string> names;
    for (const Param& q : layout.p) names.push_back(q.name);
    return apply_parameters(scene, names, layout.natural(x));
}

std::vector<double> restart(const Layout& layout, const std::vector<double>& fit, const std::vector<double>& statics,
                            const std::vector<double>& draw) {
    std::vector<double> x = fit;
    bool any = false;
    for (int j = 0; j < layout.size(); ++j) {
        if (layout.p[j].kind != Param::Static) continue;
        x[j] = statics[j];
        any = true;
    }
    return any ? x : draw;
}

}   // namespace identify_detail

void check_parameter_names(const Scene& scene, const std::vector<std::string>& names) { identify_detail::Layout(scene, names); }

Scene apply_parameters(const Scene& scene, const std::vector<std::string>& names, const std::vector<double>& values) {
    using identify_detail::Param;
    const identify_detail::Layout layout(scene, names);
    if (values.size() != names.size())
        throw std::invalid_argument("apply_parameters: " + std::to_string(values.size()) + " values for " +
                                    std::to_string(names.size()) + " names");
    Scene s = scene;
    Part& part = s.part;
    Vec3 mus = part.mu_static ? *part.mu_static : part.mu;
    bool static_fitted[3] = {false, false, false};
    Vec2 com = Vec2::Zero();
    for (int j = 0; j < layout.size(); ++j) {
        const Param& q = layout.p[j];
        for (int i = 0; i < 3; ++i) {
            if (q.contact >= 0 && q.contact != i) continue;
            if (q.kind == Param::Kinetic) part.mu[i] = values[j];
            if (q.kind == Param::Static) {
                mus[i] = values[j];
                static_fitted[i] = true;
            }
        }
        if (q.kind == Param::ComX) com.x() = values[j];
        if (q.kind == Param::ComY) com.y() = values[j];
    }
    // A scene with one coefficient per contact (no static ones of its own) keeps them one: an unfitted
    // static coefficient follows its contact's fitted kinetic one.
    const bool one_coefficient = !scene.part.mu_static;
    for (int i = 0; i < 3; ++i) {
        if (one_coefficient && !static_fitted[i]) mus[i] = part.mu[i];
        if (static_fitted[i] && mus[i] < part.mu[i])
            throw std::invalid_argument("apply_parameters: contact " + std::to_string(i + 1) + "'s static coefficient " +
                                        std::to_string(mus[i]) + " below its kinetic one " + std::to_string(part.mu[i]));
        mus[i] = std::max(mus[i], part.mu[i]);
    }
    if (part.point) {
        part.mu.tail<2>().setConstant(part.mu[0]);
        mus.tail<2>().setConstant(mus[0]);
    }
    part.mu_static = mus;
    if (mus == part.mu) part.mu_static.reset();
    for (auto& c : part.c) c -= Vec3(com.x(), com.y(), 0);
    return s;
}

}   // namespace plate
