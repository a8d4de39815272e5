#include "plate/scene_io.hpp"

#include "plate/friction.hpp"

#include "input_reader.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <sstream>

namespace plate {
namespace {

using detail::Reader;
using nlohmann::json;

// The support triangle of a rigid part's contacts (finite; none for a point part): its size L (the
// longest side), the contacts' reach from the centre of mass, the matrix of the static normal-force
// solve [1 1 1; x_i / L; y_i / L], the shares N_i / (m g) at rest on a level plate (the barycentric
// coordinates of the centre of mass's projection) and its distance to the nearest edge.
struct Support {
    double size = 0, reach = 0, edge = std::numeric_limits<double>::infinity();
    Mat3 A = Mat3::Zero();
    Vec3 share = Vec3::Zero();
    explicit Support(const Part& p) {
        if (p.point) return;
        for (int i = 0; i < 3; ++i) {
            reach = std::max(reach, p.c[i].head<2>().norm());
            for (int j = 0; j < i; ++j) size = std::max(size, (p.c[i] - p.c[j]).norm());
        }
        if (size <= 0) return;
        for (int i = 0; i < 3; ++i) {
            A.col(i) = Vec3(1, p.c[i].x() / size, p.c[i].y() / size);
            const Vec2 a = p.c[i].head<2>(), e = p.c[(i + 1) % 3].head<2>() - a;
            edge = std::min(edge, std::abs(e.x() * a.y() - e.y() * a.x()) / e.norm());
        }
        share = A.colPivHouseholderQr().solve(Vec3(1, 0, 0));
    }
};

// One set of friction coefficients: a number (every contact), [mu] (a point part) or [mu1, mu2,
// mu3] (a rigid part's contacts in order), each >= 0.
Vec3 friction_coefficients(const Reader& r, const json& f, const std::string& field, bool point) {
    Vec3 mu;
    if (f.is_number()) {
        mu.setConstant(r.number(f, field));
    } else if (f.is_array() && f.size() == 3 && !point) {
        mu = r.vec3(f, field);
    } else if (f.is_array() && f.size() == 1 && point) {
        mu.setConstant(r.number(f[0], field + "[0]"));
    } else {
        r.fail(field, point ? "expected one number for a point part" : "expected one number or an array of 3 numbers");
    }
    for (int i = 0; i < (point ? 1 : 3); ++i)
        if (mu[i] < 0) r.fail(field, "expected friction coefficients >= 0, got " + Reader::fmt(mu[i]));
    return mu;
}

// The part's friction as a scene file has it: the one-coefficient form while static equals kinetic
// (so such scenes write as before), else {"static": ..., "kinetic": ...}.
json friction_json(const Part& p, int n) {
    const auto coefficients = [n](const Vec3& mu) { return n == 1 ? json(mu[0]) : json{mu[0], mu[1], mu[2]}; };
    if (p.friction().single()) return coefficients(p.mu);
    return json{{"static", coefficients(*p.mu_static)}, {"kinetic", coefficients(p.mu)}};
}

}   // namespace

Scene parse_scene(const std::string& text, const std::string& source) {
    Reader r{source};
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::out_of_range& e) {   // a number too large for a double
        throw InputError(source + ": malformed JSON: " + e.what());
    } catch (const json::parse_error& e) {
        // Report a line and column rather than a byte offset.
        std::size_t line = 1, col = 1;
        for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
            if (text[i] == '\n') {
                ++line;
                col = 1;
            } else {
                ++col;
            }
        }
        throw InputError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": malformed JSON: " + e.what());
    }

    Scene s;
    s.source = source;
    r.only_keys(doc, "", {"name", "gravity", "part", "plate"}, {"name", "gravity", "part", "plate"});
    if (!doc["name"].is_string() || doc["name"].get<std::string>().empty()) r.fail("name", "expected a non-empty string");
    s.name = doc["name"].get<std::string>();
    s.g = r.positive(doc["gravity"], "gravity");

    // part
    const json& p = doc["part"];
    if (!p.is_object()) r.fail("part", "expected an object");
    const bool point = !p.contains("inertia") && !p.contains("contacts");
    if (point) {
        r.only_keys(p, "part", {"mass", "friction"}, {"mass", "friction"});
    } else {
        r.only_keys(p, "part", {"mass", "inertia", "contacts", "friction"}, {"mass", "inertia", "contacts", "friction"});
    }
    Part& part = s.part;
    part.point = point;
    part.m = r.positive(p["mass"], "part.mass");
    const json& f = p["friction"];
    if (f.is_object()) {
        // {"static": ..., "kinetic": ...}: each in the one-coefficient forms below.
        r.only_keys(f, "part.friction", {"static", "kinetic"}, {"static", "kinetic"});
        part.mu = friction_coefficients(r, f["kinetic"], "part.friction.kinetic", point);
        part.mu_static = friction_coefficients(r, f["static"], "part.friction.static", point);
    } else {
        part.mu = friction_coefficients(r, f, "part.friction", point);
    }
    if (!point) {
        const json& I = p["inertia"];
        if (!I.is_array() || I.size() != 3) r.fail("part.inertia", "expected a 3x3 array of numbers");
        for (int i = 0; i < 3; ++i) part.J.row(i) = r.vec3(I[i], "part.inertia[" + std::to_string(i) + "]").transpose();
        const json& C = p["contacts"];
        if (!C.is_array() || C.size() != 3) r.fail("part.contacts", "expected exactly 3 contact points, each [x, y, z]");
        for (int i = 0; i < 3; ++i) part.c[i] = r.vec3(C[i], "part.contacts[" + std::to_string(i) + "]");
    }

    // plate
    const json& q = doc["plate"];
    r.only_keys(q, "plate", {"period", "harmonics"}, {"period", "harmonics"});
    s.plate.T = r.positive(q["period"], "plate.period");
    const json& H = q["harmonics"];
    if (!H.is_array()) r.fail("plate.harmonics", "expected an array of harmonics");
    static const std::pair<const char*, Axis> axes[] = {{"x", Axis::x},   {"y", Axis::y},   {"z", Axis::z},
                                                        {"rx", Axis::rx}, {"ry", Axis::ry}, {"rz", Axis::rz}};
    for (std::size_t k = 0; k < H.size(); ++k) {
        const std::string fk = "plate.harmonics[" + std::to_string(k) + "]";
        r.only_keys(H[k], fk, {"axis", "n", "amp", "phase"}, {"axis", "n", "amp", "phase"});
        Harmonic h;
        const json& a = H[k]["axis"];
        bool found = false;
        if (a.is_string())
            for (const auto& [name, axis] : axes)
                if (a.get<std::string>() == name) {
                    h.axis = axis;
                    found = true;
                }
        if (!found) r.fail(fk + ".axis", "expected one of \"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"");
        const json& n = H[k]["n"];
        if (!n.is_number_integer() || n.get<long>() < 1 || n.get<long>() > 1000)
            r.fail(fk + ".n", "expected a whole number from 1 to 1000 (harmonic of the base frequency)");
        h.n = n.get<int>();
        h.amp = r.number(H[k]["amp"], fk + ".amp");
        h.phase = r.number(H[k]["phase"], fk + ".phase");
        s.plate.harmonics.push_back(h);
    }
    validate_scene(s);
    return s;
}

void validate_scene(const Scene& s) {
    Reader r{s.source.empty() ? std::string("(scene)") : s.source};
    const Part& p = s.part;
    if (!(std::isfinite(s.g) && s.g > 0)) r.fail("gravity", "expected a positive finite number");
    if (!(std::isfinite(p.m) && p.m > 0)) r.fail("part.mass", "expected a positive finite number");
    // Ranges of the model's world (a rigid part on a rigid plate under Coulomb friction): outside
    // them the numbers are unit errors or outside the physics, and products such as m g or mu N
    // would lose the range of a double in the solves.
    if (s.g > kMaxGravity)
        r.fail("gravity", Reader::fmt(s.g) + " m/s^2 is above " + Reader::fmt(kMaxGravity) + " m/s^2 (about 100 g)");
    if (p.m < kMassRange[0] || p.m > kMassRange[1])
        r.fail("part.mass", Reader::fmt(p.m) + " kg is outside " + Reader::fmt(kMassRange[0]) + " to " +
                                Reader::fmt(kMassRange[1]) + " kg (a microgram to a thousand tonnes)");
    if (!(std::isfinite(s.plate.T) && s.plate.T > 0)) r.fail("plate.period", "expected a positive finite number");
    if (s.plate.T < kPeriodRange[0] || s.plate.T > kPeriodRange[1])
        r.fail("plate.period", Reader::fmt(s.plate.T) + " s is outside " + Reader::fmt(kPeriodRange[0]) + " to " +
                                   Reader::fmt(kPeriodRange[1]) + " s (100 kHz to a thousandth of a hertz): a rigid plate " +
                                   "under Coulomb friction is not a model of it");
    const char* kinetic_field = p.mu_static ? "part.friction.kinetic" : "part.friction";
    for (int i = 0; i < p.contacts(); ++i)
        if (!(std::isfinite(p.mu[i]) && p.mu[i] >= 0)) r.fail(kinetic_field, "expected finite friction coefficients >= 0");
    if (p.mu_static) {
        for (int i = 0; i < p.contacts(); ++i) {
            const double ms = (*p.mu_static)[i];
            if (!std::isfinite(ms)) r.fail("part.friction.static", "expected finite friction coefficients");
            // A held contact that let go below the sliding force would re-stick at once: no model of it.
            if (ms < p.mu[i])
                r.fail("part.friction.static", "contact " + std::to_string(i + 1) + ": static coefficient " + Reader::fmt(ms) +
                                                   " below the kinetic " + Reader::fmt(p.mu[i]) + ": expected static >= kinetic");
        }
    }
    if (!p.point) {
        if (!p.J.allFinite()) r.fail("part.inertia", "expected finite numbers");
        const double scale = p.J.cwiseAbs().maxCoeff();
        if ((p.J - p.J.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) r.fail("part.inertia", "expected a symmetric matrix");
        Eigen::LLT<Mat3> llt(p.J);
        if (scale <= 0 || llt.info() != Eigen::Success ||
            Eigen::SelfAdjointEigenSolver<Mat3>(p.J).eigenvalues().minCoeff() <= 1e-12 * scale)
            r.fail("part.inertia", "expected a symmetric positive definite matrix");
        for (int i = 0; i < 3; ++i)
            if (!p.c[i].allFinite()) r.fail("part.contacts[" + std::to_string(i) + "]", "expected finite numbers");
        const Support sup(p);
        const double size = sup.size;
        if (size <= 0) r.fail("part.contacts", "expected three distinct contact points");
        for (int i = 1; i < 3; ++i)
            if (std::abs(p.c[i].z() - p.c[0].z()) > 1e-9 * size)
                r.fail("part.contacts", "expected coplanar contacts with one z (the plate is flat): contact " +
                                            std::to_string(i) + " has z different from contact 0");
        if (p.c[0].z() > 1e-12 * size)
            r.fail("part.contacts", "expected z <= 0: the centre of mass cannot lie below the plate surface");
        // Nearly collinear contacts: the normal forces come from the solve of
        //   [1 1 1; x_i / L; y_i / L] N = [m g; ...]
        // (the plate at rest; in motion the same geometry), whose relative rounding error is
        // cond * eps. Above kMaxContactCondition it would exceed 1e-10, the tightest integration
        // tolerance the references use: the results would not carry the accuracy asked for.
        const Eigen::JacobiSVD<Mat3> svd(sup.A);
        const double cond = svd.singularValues()[0] / svd.singularValues()[2];
        if (!(cond <= kMaxContactCondition))
            r.fail("part.contacts", "nearly collinear contacts (assumption 2): the normal-force solve's condition number is " +
                                        Reader::fmt(cond) + ", above " + Reader::fmt(kMaxContactCondition) +
                                        " (1e-10 / machine epsilon): its rounding would exceed the integration tolerance");
        // At rest on a level plate N_i / (m g) are the barycentric coordinates of the centre of
        // mass's projection in the support triangle: one below zero means the part tips over.
        const Vec3& share = sup.share;
        int k = 0;
        share.minCoeff(&k);
        if (share[k] < 0)
            r.fail("part.contacts",
                   "the part tips over: the centre of mass's projection (0, 0) lies outside the support "
                   "triangle (at rest contact " +
                       std::to_string(k + 1) + " would need a normal force of " + Reader::fmt(share[k]) + " m g)");
        // Inertia of a rigid body: principal moments satisfy the triangle inequality.
        const Vec3 lam = Eigen::SelfAdjointEigenSolver<Mat3>(p.J).eigenvalues();   // ascending
        if (lam[0] + lam[1] < lam[2] * (1 - 1e-9))
            r.fail("part.inertia", "principal moments " + Reader::fmt(lam[0]) + ", " + Reader::fmt(lam[1]) + ", " +
                                       Reader::fmt(lam[2]) +
                                       " violate the triangle inequality A + B >= C: no rigid body "
                                       "has this inertia");
        // Inertia against mass and size: the radius of gyration about z against the contacts'
        // distance from the centre of mass. Real parts lie within two orders of magnitude of each
        // other (a ring on close feet, a hub on long legs); beyond that it is a unit error.
        const double reach = sup.reach, rho = p.rho();
        if (!(rho >= reach / kGyrationRange && rho <= reach * kGyrationRange))
            r.fail("part.inertia", "radius of gyration sqrt(J_zz / m) = " + Reader::fmt(rho) + " m against contacts up to " +
                                       Reader::fmt(reach) + " m from the centre of mass: a ratio outside 1/" +
                                       Reader::fmt(kGyrationRange) + " to " + Reader::fmt(kGyrationRange) +
                                       " is almost surely a unit error (mass in kg, inertia in kg m^2, lengths in m)");
    }
    const Vec3 largest = p.friction().static_();   // (static >= kinetic)
    for (int i = 0; i < p.contacts(); ++i)
        if (largest[i] > kMaxFriction)
            r.fail(p.mu_static ? "part.friction.static" : "part.friction",
                   "friction coefficient " + Reader::fmt(largest[i]) + " above " + Reader::fmt(kMaxFriction) +
                       ": no pair of materials grips that hard (dry contacts lie below ~2)");

    for (std::size_t k = 0; k < s.plate.harmonics.size(); ++k) {
        const auto& h = s.plate.harmonics[k];
        if (!std::isfinite(h.amp) || !std::isfinite(h.phase) || h.n < 1)
            r.fail("plate.harmonics[" + std::to_string(k) + "]", "expected finite amp and phase, n >= 1");
        if (std::abs(h.amp) > kMaxAmplitude)
            r.fail("plate.harmonics[" + std::to_string(k) + "].amp",
                   Reader::fmt(h.amp) + " is above " + Reader::fmt(kMaxAmplitude) + " (m/s^2 or rad/s^2) in size");
    }
}

std::vector<std::string> scene_warnings(const Scene& s) {
    std::vector<std::string> w;
    const Part& p = s.part;
    const std::string src = s.source.empty() ? std::string("(scene)") : s.source;
    for (int i = 0; i < p.contacts(); ++i)
        if (p.friction().static_(i) > kHighFriction) {
            w.push_back(src + ": part.friction: " + Reader::fmt(p.friction().static_(i)) + " is above " +
                        Reader::fmt(kHighFriction) + ", more than dry contacts usually have");
            break;
        }
    const Support sup(p);
    const double reach = sup.reach;
    if (!p.point) {
        const Vec3& share = sup.share;
        int k = 0;
        if (share.minCoeff(&k) < kNearTipping)
            w.push_back(src + ": part.contacts: at rest contact " + std::to_string(k + 1) + " carries only " +
                        Reader::fmt(100 * share[k]) + "% of the weight: the part is close to tipping over");
    }
    // The downward acceleration at a contact of the part at the plate's centre: -(p''_z + (omega1' x
    // c_i)_z), its largest over 400 instants of a period (linear in u: no centripetal part).
    double down = 0;
    for (int k = 0; k < 400; ++k) {
        Vec3 pdd, wd;
        s.plate.acceleration(s.plate.T * k / 400, pdd, wd);
        for (int i = 0; i < p.contacts(); ++i) {
            const Vec3 r = p.point ? Vec3::Zero() : Vec3(p.c[i].x(), p.c[i].y(), 0);
            down = std::max(down, -(pdd.z() + wd.cross(r).z()));
        }
    }
    if (down >= s.g)
        w.push_back(src + ": plate.harmonics: the vertical acceleration at a contact can reach " + Reader::fmt(down) +
                    " m/s^2 downward at the plate's centre, at least g: the part may leave the plate (commands then stop with "
                    "'contact lost')");
    if (!p.point) {
        // Dynamic tipping: friction mu N at the contacts, a height h below the centre of mass, tips the
        // part about a support edge at distance d from the centre of mass's projection once mu h > d.
        const double d = sup.edge, h = p.s_z(), mu = p.friction().largest_kinetic();
        if (mu * h > d)
            w.push_back(src + ": part.contacts: sliding friction can tip the part: mu h = " + Reader::fmt(mu * h) +
                        " m exceeds the distance " + Reader::fmt(d) + " m from the centre of mass to the nearest support edge");
        const double rho = p.rho();
        if (rho < reach / kGyrationWarn || rho > reach * kGyrationWarn)
            w.push_back(src + ": part.inertia: radius of gyration sqrt(J_zz / m) = " + Reader::fmt(rho) +
                        " m against contacts up to " + Reader::fmt(reach) + " m from the centre of mass, a ratio beyond " +
                        Reader::fmt(kGyrationWarn) + ": check the units (a mass in grams gives about 1/30 of the ratio)");
    }
    if (reach > 0) {
        const double travel = s.v_ref() * s.plate.T;
        if (travel > kTravelPerPeriod * reach)
            w.push_back(src + ": the slip-speed scale v_ref = " + Reader::fmt(s.v_ref()) + " m/s moves the part " +
                        Reader::fmt(travel) + " m per period, more than " + Reader::fmt(kTravelPerPeriod) +
                        " times its size: it would cross a plate of practical size within a few periods");
    }
    return w;
}

nlohmann::json scene_to_json(const Scene& s) {
    json j;
    j["name"] = s.name;
    j["gravity"] = s.g;
    json part;
    part["mass"] = s.part.m;
    if (s.part.point) {
        part["friction"] = friction_json(s.part, 1);
    } else {
        json I = json::array(), C = json::array();
        for (int i = 0; i < 3; ++i) {
            I.push_back({s.part.J(i, 0), s.part.J(i, 1), s.part.J(i, 2)});
            C.push_back({s.part.c[i].x(), s.part.c[i].y(), s.part.c[i].z()});
        }
        part["inertia"] = I;
        part["contacts"] = C;
        part["friction"] = friction_json(s.part, 3);
    }
    j["part"] = part;
    json H = json::array();
    for (const auto& h : s.plate.harmonics)
        H.push_back({{"axis", axis_name(h.axis)}, {"n", h.n}, {"amp", h.amp}, {"phase", h.phase}});
    j["plate"] = {{"period", s.plate.T}, {"harmonics", H}};
    return j;
}

Scene load_scene(const std::string& path) { return parse_scene(detail::read_input_file(path, "scene file"), path); }

}   // namespace plate
