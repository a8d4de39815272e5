// The model of Vose, Umbanhowar & Lynch, "Sliding manipulation of rigid bodies on a
// controlled 6-DoF plate": a part sigma (Section III-B) and a periodic plate motion u(t).
// These are constant inputs to every algorithm (the "Model" half of a Model/Data split).
#pragma once

#include <Eigen/Dense>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace plate {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

constexpr double kPi = 3.14159265358979323846;

// Value-initialisation ({}) does not zero Eigen's fixed-size vectors (their default constructor
// leaves them uninitialised): arrays of them start from zeros<V>().
template <class V, std::size_t N = 3>
std::array<V, N> zeros() {
    std::array<V, N> a;
    a.fill(V::Zero());
    return a;
}

class ContactFriction;   // friction.hpp

// sigma = (m, J, c1, c2, c3, mu_k1, mu_k2, mu_k3), and the static coefficients mu_s1..3.
// A point part has only m and mu (one contact at the centre of mass, no rotation).
struct Part {
    bool point = false;
    double m = 0;                            // mass [kg]
    Mat3 J = Mat3::Zero();                   // rotational inertia about s, in S [kg m^2]
    std::array<Vec3, 3> c = zeros<Vec3>();   // contacts c_i in S [m]; all share one z (flat plate)
    Vec3 mu = Vec3::Zero();                  // kinetic friction coefficients mu_ki (read them through friction())
    std::optional<Vec3> mu_static;           // static coefficients mu_si >= mu_ki; unset: equal to the kinetic ones

    int contacts() const { return point ? 1 : 3; }
    // The contacts' kinetic and static friction coefficients (friction.hpp, which defines it).
    ContactFriction friction() const;
    // Height of the centre of mass above the plate: s_z = -c_iz (assumption 1).
    double s_z() const { return point ? 0.0 : -c[0].z(); }
    // Radius of gyration rho = sqrt(J_zz / m) (Appendix footnote); 1 m for a point part.
    double rho() const;
    // Thin part (Appendix A): contacts in the plane of s and J_xz = J_yz = 0.
    bool thin(double rel_tol = 1e-12) const;
};

enum class Axis { x = 0, y = 1, z = 2, rx = 3, ry = 4, rz = 5 };
const char* axis_name(Axis a);

// One term amp * sin(n * 2 pi t / T + phase) of one component of u(t).
struct Harmonic {
    Axis axis = Axis::x;
    int n = 1;
    double amp = 0;     // m/s^2 (x y z) or rad/s^2 (rx ry rz)
    double phase = 0;   // rad
};

// u(t) = [p''(t); omega1'(t)] in W (eq. 11). The plate's velocity and position are the
// unique zero-mean periodic integrals (Section III-H: the plate state x_plate0 follows from u).
struct PlateMotion {
    double T = 0;   // period [s]
    std::vector<Harmonic> harmonics;

    double omega() const { return 2 * kPi / T; }
    // u(t): plate acceleration p'' and angular acceleration omega1' (world frame).
    void acceleration(double t, Vec3& pdd, Vec3& wd) const;
    // Zero-mean velocity p' and angular velocity omega1.
    void velocity(double t, Vec3& pd, Vec3& w1) const;
    // Zero-mean position p and zero-mean integral of omega1 (the linearised rotation vector).
    void displacement(double t, Vec3& p, Vec3& phi) const;
    // Largest amplitude of the horizontal acceleration of the plate at its centre [m/s^2].
    double horizontal_amplitude() const;
    // Largest angular-acceleration amplitude [rad/s^2].
    double angular_amplitude() const;
};

struct Scene {
    std::string name;
    std::string source;   // file it was read from (for messages)
    double g = 9.81;      // gravity [m/s^2], along -z of W
    Part part;
    PlateMotion plate;

    // Characteristic slip speed: the velocity amplitude a/omega of the dominant
    // horizontal acceleration a = max(mu g, plate horizontal amplitude). Used to scale
    // tolerances so that they are relative, whatever the units of a scene.
    double v_ref() const;
};

}   // namespace plate
