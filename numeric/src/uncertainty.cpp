#include "plate/uncertainty.hpp"

#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include "input_reader.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <complex>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace plate {
namespace {

using nlohmann::json;

using detail::Reader;

// A spread's object {"spread": s, "distribution": "normal" | "uniform"}; absent: no spread.
Spread read_spread(const Reader& r, const json& doc, const std::string& field) {
    Spread s;
    if (!doc.contains(field)) return s;
    const json& v = doc[field];
    r.only_keys(v, field, {"spread", "distribution"}, {"spread"});
    s.spread = r.number(v["spread"], field + ".spread");
    if (v.contains("distribution")) {
        const json& d = v["distribution"];
        if (d == "normal")
            s.distribution = Distribution::normal;
        else if (d == "uniform")
            s.distribution = Distribution::uniform;
        else
            r.fail(field + ".distribution", "expected \"normal\" or \"uniform\"");
    }
    return s;
}

// splitmix64's finaliser: a bijection of 64-bit words that mixes every input bit into every output bit.
std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// The perturbations of one draw, each from its own stream keyed by (seed, index, what, attempt): a
// draw depends on nothing but these, and a spread added to one quantity leaves the others' draws as
// they were.
enum class Stream : std::uint64_t { friction = 1, mass, inertia, contacts, com, amplitude, phase, unmodelled, period };

Rng stream(const UncertaintySpec& spec, std::uint64_t index, Stream what, int attempt) {
    std::uint64_t k = mix64(spec.seed + 0x9E3779B97F4A7C15ull);
    k = mix64(k ^ (index + 0x632BE59BD9B4E019ull));
    k = mix64(k ^ (static_cast<std::uint64_t>(what) << 32) ^ static_cast<std::uint64_t>(attempt));
    return Rng(k);
}

double sample(const Spread& s, Rng& r) {
    if (s.spread == 0) return 0;
    return s.distribution == Distribution::uniform ? r.uniform(-s.spread, s.spread) : s.spread * standard_normal(r);
}

// The unmodelled harmonics a spec adds to `nominal`: on each axis with a commanded signal, every n up to
// spec.unmodelled_up_to that the axis does not command (UncertaintySpec::unmodelled_up_to), with the
// standard deviation of each of their two coefficients (UncertainParameter).
struct Unmodelled {
    int axis = 0, n = 0;
    double sd = 0;
};
std::vector<Unmodelled> unmodelled_of(const PlateMotion& nominal, const UncertaintySpec& spec) {
    std::vector<Unmodelled> out;
    if (spec.unmodelled_up_to < 1 || spec.unmodelled_rms_fraction <= 0) return out;
    const Vec6 rms = axis_rms(nominal);
    for (int a = 0; a < 6; ++a) {
        if (rms[a] <= 0) continue;
        std::set<int> commanded;
        for (const auto& h : nominal.harmonics)
            if (static_cast<int>(h.axis) == a) commanded.insert(h.n);
        const std::size_t first = out.size();
        for (int n = 1; n <= spec.unmodelled_up_to; ++n)
            if (!commanded.count(n)) out.push_back(Unmodelled{a, n, 0});
        const double K = static_cast<double>(out.size() - first);
        for (std::size_t k = first; k < out.size(); ++k) out[k].sd = spec.unmodelled_rms_fraction * rms[a] / std::sqrt(K);
    }
    return out;
}

// The deviations p of one attempt at draw `index` (the layout of uncertain_parameters). Unmodelled
// harmonics: per axis, random amplitudes (normal) and phases (uniform), scaled so that their sum's RMS
// is exactly the spec's fraction of the axis's; p holds each one's (cos, sin) coefficients.
std::vector<double> deviations(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index, int attempt) {
    const Part& part = nominal.part;
    std::vector<double> p;
    Rng rf = stream(spec, index, Stream::friction, attempt);
    for (int i = 0; i < part.contacts(); ++i) p.push_back(sample(spec.friction, rf));
    Rng rm = stream(spec, index, Stream::mass, attempt);
    p.push_back(sample(spec.mass, rm));
    if (!part.point) {
        Rng ri = stream(spec, index, Stream::inertia, attempt);
        p.push_back(sample(spec.inertia, ri));
        Rng rc = stream(spec, index, Stream::contacts, attempt), rd = stream(spec, index, Stream::com, attempt);
        const double dx = 1e-3 * sample(spec.com_offset_mm, rd), dy = 1e-3 * sample(spec.com_offset_mm, rd);
        for (int i = 0; i < 3; ++i) {
            const double ex = 1e-3 * sample(spec.contacts_mm, rc), ey = 1e-3 * sample(spec.contacts_mm, rc);
            p.push_back(ex);
            p.push_back(ey);
        }
        p.push_back(dx);
        p.push_back(dy);
    }
    const std::size_t H = nominal.plate.harmonics.size();
    Rng ra = stream(spec, index, Stream::amplitude, attempt), rp = stream(spec, index, Stream::phase, attempt);
    for (std::size_t h = 0; h < H; ++h) p.push_back(sample(spec.amplitude, ra));
    for (std::size_t h = 0; h < H; ++h) p.push_back(sample(spec.phase, rp));
    Rng ru = stream(spec, index, Stream::unmodelled, attempt);
    const std::vector<Unmodelled> added = unmodelled_of(nominal.plate, spec);
    for (std::size_t k = 0; k < added.size();) {   // one axis's harmonics at a time
        std::size_t end = k;
        double power = 0;   // their mean square before scaling
        std::vector<std::pair<double, double>> amp_phase;
        for (; end < added.size() && added[end].axis == added[k].axis; ++end) {
            const double amp = standard_normal(ru), phase = ru.uniform(0, 2 * kPi);
            amp_phase.emplace_back(amp, phase);
            power += amp * amp / 2;
        }
        // The scale f RMS_a / sqrt(power), with sd = f RMS_a / sqrt(K_a).
        const double scale = added[k].sd * std::sqrt(static_cast<double>(end - k) / power);
        for (const auto& [amp, phase] : amp_phase) {   // amp sin(x + phase) = amp sin(phase) cos x + amp cos(phase) sin x
            p.push_back(scale * amp * std::sin(phase));
            p.push_back(scale * amp * std::cos(phase));
        }
        k = end;
    }
    Rng rT = stream(spec, index, Stream::period, attempt);
    p.push_back(sample(spec.period, rT));
    return p;
}

}   // namespace

double Spread::standard_deviation() const { return distribution == Distribution::uniform ? spread / std::sqrt(3.0) : spread; }

Vec6 axis_rms(const PlateMotion& plate) {
    std::map<std::pair<int, int>, std::complex<double>> phasor;   // (axis, n) -> amp e^{i phase}
    for (const auto& h : plate.harmonics)                         // (std::polar wants amp >= 0; a scene's may be negative)
        phasor[{static_cast<int>(h.axis), h.n}] += h.amp * std::complex<double>(std::cos(h.phase), std::sin(h.phase));
    Vec6 ms = Vec6::Zero();
    for (const auto& [key, z] : phasor) ms[key.first] += std::norm(z) / 2;
    return ms.cwiseSqrt();
}

UncertaintySpec parse_uncertainty(const std::string& text, const std::string& source) {
    Reader r{source};
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::exception& e) {
        throw InputError(source + ": malformed JSON: " + e.what());
    }
    r.only_keys(
        doc, "",
        {"seed", "friction", "mass", "inertia", "contacts_mm", "com_offset_mm", "amplitude", "phase", "unmodelled", "period"},
        {"seed"});
    UncertaintySpec s;
    s.source = source;
    if (!doc["seed"].is_number_unsigned()) r.fail("seed", "expected a whole number from 0 to 2^64 - 1");
    s.seed = doc["seed"].get<std::uint64_t>();
    s.friction = read_spread(r, doc, "friction");
    s.mass = read_spread(r, doc, "mass");
    s.inertia = read_spread(r, doc, "inertia");
    s.contacts_mm = read_spread(r, doc, "contacts_mm");
    s.com_offset_mm = read_spread(r, doc, "com_offset_mm");
    s.amplitude = read_spread(r, doc, "amplitude");
    s.phase = read_spread(r, doc, "phase");
    s.period = read_spread(r, doc, "period");
    if (doc.contains("unmodelled")) {
        const json& u = doc["unmodelled"];
        r.only_keys(u, "unmodelled", {"up_to", "rms_fraction"}, {"up_to", "rms_fraction"});
        if (!u["up_to"].is_number_integer() || u["up_to"].get<long>() < 1 || u["up_to"].get<long>() > 1000)
            r.fail("unmodelled.up_to", "expected a whole number from 1 to 1000 (the highest harmonic added)");
        s.unmodelled_up_to = u["up_to"].get<int>();
        s.unmodelled_rms_fraction = r.number(u["rms_fraction"], "unmodelled.rms_fraction");
    }
    validate_uncertainty(s);
    return s;
}

void validate_uncertainty(const UncertaintySpec& s) {
    Reader r{s.source.empty() ? std::string("(uncertainty)") : s.source};
    auto check = [&](const Spread& sp, const char* field, double max, const char* unit) {
        if (!(std::isfinite(sp.spread) && sp.spread >= 0 && sp.spread <= max))
            r.fail(std::string(field) + ".spread",
                   "expected a number from 0 to " + Reader::fmt(max) + unit + ", got " + Reader::fmt(sp.spread));
    };
    check(s.friction, "friction", kMaxRelativeSpread, " (relative)");
    check(s.mass, "mass", kMaxRelativeSpread, " (relative)");
    check(s.inertia, "inertia", kMaxRelativeSpread, " (relative)");
    check(s.contacts_mm, "contacts_mm", kMaxSpreadMm, " mm");
    check(s.com_offset_mm, "com_offset_mm", kMaxSpreadMm, " mm");
    check(s.amplitude, "amplitude", kMaxRelativeSpread, " (relative)");
    check(s.phase, "phase", kPi, " rad");
    check(s.period, "period", kMaxRelativeSpread, " (relative)");
    if (s.unmodelled_up_to < 0 || s.unmodelled_up_to > 1000)
        r.fail("unmodelled.up_to", "expected a whole number from 1 to 1000 (the highest harmonic added)");
    if (!(std::isfinite(s.unmodelled_rms_fraction) && s.unmodelled_rms_fraction >= 0 && s.unmodelled_rms_fraction <= 1))
        r.fail("unmodelled.rms_fraction",
               "expected a number from 0 to 1 (of the commanded signal's RMS), got " + Reader::fmt(s.unmodelled_rms_fraction));
}

std::vector<UncertainParameter> uncertain_parameters(const Scene& nominal, const UncertaintySpec& spec) {
    static const char* axis_name[6] = {"x", "y", "z", "rx", "ry", "rz"};
    static const char* axis_unit[6] = {"m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2"};
    const Part& part = nominal.part;
    std::vector<UncertainParameter> out;
    auto add = [&](const std::string& name, const char* unit, double sd) { out.push_back(UncertainParameter{name, unit, sd}); };
    for (int i = 0; i < part.contacts(); ++i)
        add("friction[" + std::to_string(i) + "]", "relative", spec.friction.standard_deviation());
    add("mass", "relative", spec.mass.standard_deviation());
    if (!part.point) {
        add("inertia", "relative", spec.inertia.standard_deviation());
        for (int i = 0; i < 3; ++i)
            for (const char* c : {".x", ".y"})
                add("contact[" + std::to_string(i) + "]" + c, "m", 1e-3 * spec.contacts_mm.standard_deviation());
        add("com.x", "m", 1e-3 * spec.com_offset_mm.standard_deviation());
        add("com.y", "m", 1e-3 * spec.com_offset_mm.standard_deviation());
    }
    auto harmonic = [&](const Harmonic& h) {
        return std::string("[") + axis_name[static_cast<int>(h.axis)] + ",n=" + std::to_string(h.n) + "]";
    };
    for (const auto& h : nominal.plate.harmonics) add("amp" + harmonic(h), "relative", spec.amplitude.standard_deviation());
    for (const auto& h : nominal.plate.harmonics) add("phase" + harmonic(h), "rad", spec.phase.standard_deviation());
    for (const auto& u : unmodelled_of(nominal.plate, spec)) {
        const std::string at = std::string("unmodelled[") + axis_name[u.axis] + ",n=" + std::to_string(u.n) + "]";
        add(at + ".cos", axis_unit[u.axis], u.sd);
        add(at + ".sin", axis_unit[u.axis], u.sd);
    }
    add("period", "relative", spec.period.standard_deviation());
    return out;
}

Scene perturbed(const Scene& nominal, const UncertaintySpec& spec, const std::vector<double>& p) {
    const std::vector<Unmodelled> added = unmodelled_of(nominal.plate, spec);
    const std::size_t H = nominal.plate.harmonics.size(), rigid = nominal.part.point ? 0 : 9;
    const std::size_t want = nominal.part.contacts() + 1 + rigid + 2 * H + 2 * added.size() + 1;
    if (p.size() != want)
        throw std::invalid_argument("perturbed: " + std::to_string(p.size()) + " deviations for a layout of " +
                                    std::to_string(want) + " (uncertain_parameters)");
    Scene s = nominal;
    Part& part = s.part;
    std::size_t k = 0;
    // A contact's static and kinetic coefficients move together (one deviation: their ratio is kept).
    for (int i = 0; i < part.contacts(); ++i, ++k) {
        part.mu[i] *= 1 + p[k];
        if (part.mu_static) (*part.mu_static)[i] *= 1 + p[k];
    }
    if (part.point) part.mu.tail<2>().setConstant(part.mu[0]);
    if (part.point && part.mu_static) part.mu_static->tail<2>().setConstant((*part.mu_static)[0]);
    part.m *= 1 + p[k++];
    if (!part.point) {
        part.J *= 1 + p[k++];
        const Vec3 com(p[k + 6], p[k + 7], 0);
        for (auto& c : part.c) {
            c += Vec3(p[k], p[k + 1], 0) - com;
            k += 2;
        }
        k += 2;
    }
    for (auto& h : s.plate.harmonics) h.amp *= 1 + p[k++];
    for (auto& h : s.plate.harmonics) h.phase += p[k++];
    for (const auto& u : added) {
        const double c = p[k++], sn = p[k++];   // c cos(n w t) + sn sin(n w t) = amp sin(n w t + phase)
        if (c != 0 || sn != 0)
            s.plate.harmonics.push_back(Harmonic{static_cast<Axis>(u.axis), u.n, std::hypot(c, sn), std::atan2(c, sn)});
    }
    s.plate.T *= 1 + p[k++];
    return s;
}

UncertaintySpec load_uncertainty(const std::string& path) {
    return parse_uncertainty(detail::read_input_file(path, "uncertainty spec"), path);
}

Draw draw_with_deviations(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index) {
    validate_uncertainty(spec);
    std::string last;
    for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
        Draw d;
        d.p = deviations(nominal, spec, index, attempt);
        d.scene = perturbed(nominal, spec, d.p);
        d.scene.name = nominal.name + "~" + std::to_string(index);
        try {
            validate_scene(d.scene);
            return d;
        } catch (const InputError& e) {
            last = e.what();
        }
    }
    throw InputError((spec.source.empty() ? std::string("(uncertainty)") : spec.source) + ": draw " + std::to_string(index) +
                     " of " + (nominal.source.empty() ? nominal.name : nominal.source) + " gave no valid scene in " +
                     std::to_string(kMaxRedraws) + " tries (the spreads are too wide for this part); the last: " + last);
}

Scene draw(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index) {
    return draw_with_deviations(nominal, spec, index).scene;
}

}   // namespace plate
