// Seeded random parts and plate motions (Fig. 3 of the paper; the proofs' random campaigns).
// The generator is splitmix64 with its own uniform mapping, so a seed gives the same scene on
// every platform.
#pragma once

#include "plate/model.hpp"

#include <cmath>
#include <cstdint>

namespace plate {

struct RandomSceneOptions {
    bool thin = false;             // contacts in the plane of s, J_xz = J_yz = 0 (Theorem 1)
    bool point = false;            // point part
    int max_harmonic = 2;          // harmonics n = 1..max_harmonic per axis
    double config_radius = 0.03;   // the part is meant for |s| <= this; contact is kept there
};

class Rng {
public:
    explicit Rng(std::uint64_t seed) : s_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return (next() >> 11) * 0x1.0p-53; }   // [0, 1)
    double uniform(double a, double b) { return a + (b - a) * uniform(); }

private:
    std::uint64_t s_;
};

// A standard normal draw from two uniforms of r (Box-Muller; 1 - uniform() lies in (0, 1], so the
// log is finite): the same on every platform, where std::normal_distribution is the library's own.
inline double standard_normal(Rng& r) {
    const double u1 = 1 - r.uniform(), u2 = r.uniform();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
}

Scene random_scene(std::uint64_t seed, const RandomSceneOptions& opt = {});

}   // namespace plate
