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

double standard_normal(Rng& r) {
    // Box-Muller; 1 - uniform() lies in (0, 1], so the log is finite.
    const double u1 = 1 - r.uniform(), u2 = r.uniform();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
}

double sample(const Spread& s, Rng& r) {
    if (s.spread == 0) return 0;
    return s.distribution == Distribution::uniform ? r.uniform(-s.spread, s.spread) : s.spread * standard_normal(r);
}

// The unmodelled harmonics of one draw (UncertaintySpec::unmodelled_up_to).
void add_unmodelled(const PlateMotion& nominal, const UncertaintySpec& spec, Rng& r, PlateMotion& out) {
    if (spec.unmodelled_up_to < 1 || spec.unmodelled_rms_fraction <= 0) return;
    const Vec6 rms = axis_rms(nominal);
    for (int a = 0; a < 6; ++a) {
        if (rms[a] <= 0) continue;
        std::set<int> commanded;
        for (const auto& h : nominal.harmonics)
            if (static_cast<int>(h.axis) == a) commanded.insert(h.n);
        std::vector<Harmonic> added;
        double power = 0;   // mean square of the added harmonics before scaling
        for (int n = 1; n <= spec.unmodelled_up_to; ++n) {
            if (commanded.count(n)) continue;
            const double amp = standard_normal(r), phase = r.uniform(0, 2 * kPi);
            added.push_back(Harmonic{static_cast<Axis>(a), n, amp, phase});
            power += amp * amp / 2;
        }
        if (power <= 0) continue;
        const double scale = spec.unmodelled_rms_fraction * rms[a] / std::sqrt(power);
        for (auto& h : added) {
            h.amp *= scale;
            out.harmonics.push_back(h);
        }
    }
}

Scene draw_once(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index, int attempt) {
    Scene s = nominal;
    Part& p = s.part;
    Rng rf = stream(spec, index, Stream::friction, attempt);
    for (int i = 0; i < p.contacts(); ++i) p.mu[i] *= 1 + sample(spec.friction, rf);
    if (p.point) p.mu.tail<2>().setConstant(p.mu[0]);
    Rng rm = stream(spec, index, Stream::mass, attempt);
    p.m *= 1 + sample(spec.mass, rm);
    if (!p.point) {
        Rng ri = stream(spec, index, Stream::inertia, attempt);
        p.J *= 1 + sample(spec.inertia, ri);
        Rng rc = stream(spec, index, Stream::contacts, attempt), rd = stream(spec, index, Stream::com, attempt);
        const double dx = 1e-3 * sample(spec.com_offset_mm, rd), dy = 1e-3 * sample(spec.com_offset_mm, rd);
        for (auto& c : p.c) {
            const double ex = 1e-3 * sample(spec.contacts_mm, rc), ey = 1e-3 * sample(spec.contacts_mm, rc);
            c += Vec3(ex - dx, ey - dy, 0);
        }
    }
    Rng ra = stream(spec, index, Stream::amplitude, attempt), rp = stream(spec, index, Stream::phase, attempt);
    for (auto& h : s.plate.harmonics) {
        h.amp *= 1 + sample(spec.amplitude, ra);
        h.phase += sample(spec.phase, rp);
    }
    Rng ru = stream(spec, index, Stream::unmodelled, attempt);
    add_unmodelled(nominal.plate, spec, ru, s.plate);
    Rng rT = stream(spec, index, Stream::period, attempt);
    s.plate.T *= 1 + sample(spec.period, rT);
    s.name = nominal.name + "~" + std::to_string(index);
    return s;
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

UncertaintySpec load_uncertainty(const std::string& path) {
    return parse_uncertainty(detail::read_input_file(path, "uncertainty spec"), path);
}

Scene draw(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index) {
    validate_uncertainty(spec);
    std::string last;
    for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
        Scene s = draw_once(nominal, spec, index, attempt);
        try {
            validate_scene(s);
            return s;
        } catch (const InputError& e) {
            last = e.what();
        }
    }
    throw InputError((spec.source.empty() ? std::string("(uncertainty)") : spec.source) + ": draw " + std::to_string(index) +
                     " of " + (nominal.source.empty() ? nominal.name : nominal.source) + " gave no valid scene in " +
                     std::to_string(kMaxRedraws) + " tries (the spreads are too wide for this part); the last: " + last);
}

}   // namespace plate
