// Coulomb friction at the part's contacts: the one file to open when friction changes.
//   ContactFriction   each contact's coefficients, read through kinetic(i) (a sliding contact's force,
//                     (17)) and static_(i) (the friction disk that bounds a held contact's force)
//   FrictionLaw       how a sliding contact's force depends on its slip (exact Coulomb or regularised)
//   the disks         a held contact's friction lies in its disk |f_i| <= mu_si N_i (disk, hold_margin:
//                     a pivot's break-away is the margin's zero)
//   FrictionGauge     the smallest scaling of the three disks that supplies a wrench: the stuck part's
//                     stick test (gamma <= 1) and, at gamma = 1, where it breaks away
// The mode equations that produce the forces these judge live in modes.hpp (stick_test and
// stick_test_all there evaluate a mode and judge it here); the engine's guards read hold_margin and
// the gauge.
#pragma once

#include "plate/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace plate {

namespace gen {
struct WrenchInput;   // (plate_kernels.hpp, generated)
}

// The friction coefficients of a part's contacts. The part sigma (Section III-B) has a kinetic
// coefficient per contact, mu_ki (Part::mu), and a static one, mu_si >= mu_ki (Part::mu_static;
// unset: equal to the kinetic one, the paper's model). Every reader of a coefficient asks this class
// which of the two it means:
//   kinetic  a sliding contact's force, -mu_ki N_i v_i/|v_i| (17): the slide modes, a pivot's
//            sliding contacts, the limit surface of a sliding part (Theorem 1)
//   static   the disk |f_i| <= mu_si N_i of a held contact: whether a contact or the whole part
//            holds (stick tests, the gauge) and when it breaks away (hold_margin)
// With mu_s > mu_k a contact that breaks away at |f_i| = mu_si N_i slides on at mu_ki N_i: its
// friction drops at the event, and it re-sticks only where the needed force fits the static disk.
class ContactFriction {
public:
    explicit ContactFriction(const Part& part)
        : mu_(part.mu), mus_(part.mu_static ? *part.mu_static : part.mu), point_(part.point) {}

    // Kinetic coefficient of contact i: a sliding contact's force is -kinetic(i) N_i v_i/|v_i| (17).
    double kinetic(int i) const { return mu_[i]; }
    // Static coefficient of contact i: a held contact's force lies in |f_i| <= static_(i) N_i.
    double static_(int i) const { return mus_[i]; }
    // The three, in contact order (the generated kernels' inputs: mu1..mu3 kinetic, mus1..mus3 static).
    const Vec3& kinetic() const { return mu_; }
    const Vec3& static_() const { return mus_; }
    // The largest kinetic coefficient of the part's contacts (a point part: its one).
    double largest_kinetic() const { return point_ ? mu_[0] : mu_.maxCoeff(); }
    // Does every contact's static coefficient equal its kinetic one (one coefficient per contact)?
    bool single() const { return mus_ == mu_; }
    // Throws std::invalid_argument naming `who` (a method or peer engine with one coefficient per
    // contact) unless single().
    void require_single(const char* who) const;

    // Radius of contact i's friction disk at normal force N (none while N < 0).
    double disk(int i, double N) const { return static_(i) * std::max(N, 0.0); }
    // Static-friction margin of held contact i carrying force f at normal force N: positive while it
    // holds; its zero is a break-away, opposite f (maximal dissipation at the disk's rim).
    double hold_margin(int i, double N, const Vec2& f) const { return static_(i) * N - f.norm(); }

private:
    Vec3 mu_, mus_;
    bool point_;
};

inline ContactFriction Part::friction() const { return ContactFriction(*this); }

// How the friction force of a sliding contact depends on its sliding velocity v (17):
//   Coulomb  exact kinetic Coulomb friction, direction v/|v| (discontinuous at v = 0)
//   Tanh     regularised: (v/|v|) tanh(|v|/eps)
//   Sqrt     regularised: v / sqrt(|v|^2 + eps^2) (the stick-slip reference of limit_cycle.hpp)
//   Linear   regularised: v / max(|v|, eps) (a viscous law below eps)
// The regularised laws change the model near zero slip: they trade the kink for an error of
// order eps in the average twist (charted in the speed-accuracy report).
enum class FrictionLaw { Coulomb, Tanh, Linear, Sqrt };
const char* friction_law_name(FrictionLaw f);

// The friction direction u = factor * v of a regularised law (not Coulomb) at slip speed |v| [eps,
// speed in m/s]. Coulomb's, 1/|v| (zero at zero slip), is computed with the slips (dynamics.cpp).
inline double regularised_factor(FrictionLaw law, double eps, double speed) {
    if (law == FrictionLaw::Tanh) return speed > 1e-8 * eps ? std::tanh(speed / eps) / speed : 1.0 / eps;
    if (law == FrictionLaw::Sqrt) return 1.0 / std::hypot(speed, eps);
    return 1.0 / std::max(speed, eps);
}

// d u/d v (2x2) of the friction law at sliding velocity v (Coulomb at zero slip: zero, no sliding term).
Eigen::Matrix2d direction_derivative(FrictionLaw law, double eps, const Vec2& v);

// The friction-disk gauge: the smallest gamma such that friction forces f_i with
// |f_i| <= gamma mu_i N_i supply the wrench (F, tau) about s:
//   sum_i f_i = F,  sum_i r_i x f_i = tau.
// The part can be held (static friction) iff gamma <= 1. Exact (no direction sampling): by
// duality gamma = max_d (d . w) / h(d) with h(d) = sum_i mu_i N_i |G_i^T d| the support function of
// the friction set (G_i^T d = the velocity of contact i under the twist d, in the paper's scaled
// coordinates: w = (F, tau/rho), d = (d_x, d_y, rho d_theta)); we minimise the convex h over the
// plane d . w = 1 -- at a kink G_k^T d = 0 (a rotation about contact k, tested in closed form) or
// by Newton's method where h is smooth; where Newton stalls next to a kink, a pattern search, and
// where that stops short (its distribution misses the wrench), Newton on h smoothed by delta -> 0.
// The optimal distribution is unique at a smooth boundary point: f_i = gamma mu_i N_i G_i^T d/|G_i^T d|.
// (mu_i: the static coefficients.)
struct FrictionGauge {
    double gamma = 0;                        // 0 for w = 0; inf if no friction can supply w
    std::array<Vec2, 3> f = zeros<Vec2>();   // the optimal friction distribution [N], P frame
    int pivot = -1;                          // contact whose force lies inside its disk at the optimum, if any
    Vec3 direction = Vec3::Zero();           // d: the twist (s_x', s_y', theta') the needed friction opposes
    int iterations = 0;                      // Newton iterations (0: closed form)
};
FrictionGauge friction_gauge(const Part& part, double theta, const Vec3& n, const Vec2& F, double tau);

// The inputs of the generated limit-surface kernels: contacts r_i from the centre of mass (plate frame,
// horizontal), normal forces n, the friction coefficients -- kinetic mu1..3 for a sliding part's wrench
// (thin_wrench), static mus1..3 for the friction set's support function (friction_support) -- and the
// radius of gyration; the twist (vx, vy, xith) is left at zero for the caller. (The caller includes
// plate_kernels.hpp for the type.)
gen::WrenchInput wrench_input(const std::array<Vec2, 3>& r, const Vec3& n, const ContactFriction& mu, double rho);

}   // namespace plate
