// The same part on the same shaking plate in general-purpose physics engines (issue 19): Bullet,
// ODE and MuJoCo, each set up as a careful user would, so that `plate`'s answers can be compared
// with what a roboticist would otherwise compute. Built only for the engines found at configure time.
//
// Each engine gets the part as one rigid body (mass m, inertia J about its centre of mass) carrying
// three small spheres whose lowest points are the contacts c_i, and the plate as a large box whose
// top face is the plate plane, moved kinematically along the full dynamics' plate trajectory (31):
// p(t), p'(t) the zero-mean integrals of u(t), R1' = omega1^ R1 from R1(0) = exp(phi(0)). Coulomb
// friction mu with the engine's closest thing to a friction disk. The part starts at rest relative
// to the plate at q0 and is read back in the plate frame as q = (s_x, s_y, theta).
#pragma once

#include "plate/friction.hpp"
#include "plate/model.hpp"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace plate::peers {

// The plate's pose and velocities, advanced in time (monotone). An optional constant velocity is
// added to the plate's (the tests: a plate translating uniformly must carry the part along).
class PlateTrack {
public:
    explicit PlateTrack(const PlateMotion& u, const Vec3& drift = Vec3::Zero());
    void advance(double t);   // to time t >= the current one (RK4 on the orientation, steps <= T/4000)
    double t = 0;
    Vec3 p = Vec3::Zero(), v = Vec3::Zero();                 // origin of the plate frame, its velocity (W)
    Vec3 w = Vec3::Zero();                                   // omega1 (W)
    Vec3 a = Vec3::Zero(), alpha = Vec3::Zero();             // p'', omega1' (W)
    Eigen::Quaterniond R = Eigen::Quaterniond::Identity();   // R1: P -> W

private:
    const PlateMotion* u_;
    Vec3 drift_;
    Vec3 p0_ = Vec3::Zero();
    void read(double t);
};

// The part's world pose at rest relative to the plate at q = (s_x, s_y, theta): its centre of mass
// at p + R1 (s_x, s_y, s_z), orientation R1 Rz(theta), velocity that of the plate point there.
struct BodyState {
    Vec3 x = Vec3::Zero(), v = Vec3::Zero(), w = Vec3::Zero();
    Eigen::Quaterniond R = Eigen::Quaterniond::Identity();
};
BodyState at_rest_on_plate(const Part& part, const PlateTrack& plate, const Vec3& q);
// The configuration q of a body pose relative to the plate; theta continued from `previous`.
Vec3 plate_frame_config(const Part& part, const PlateTrack& plate, const Vec3& x, const Eigen::Quaterniond& R,
                        double previous_theta);

struct PeerOptions {
    double dt = 1e-4;              // the engine's fixed step [s]
    double sphere_radius = 5e-4;   // the contact spheres [m]
    Vec3 drift = Vec3::Zero();     // a constant plate velocity added to the scene's (tests)
    // The pitfall, for the study and the tests to show: the engine's friction pyramid/box (MuJoCo's
    // default pyramidal cone, ODE's box along fixed directions; Bullet: two fixed friction directions).
    bool pyramid = false;
    double contact_time = 0;   // MuJoCo's contact time constant (solref) [s]; 0: the driver's choice
};

struct PeerRun {
    std::string engine;       // "MuJoCo 2.2.2", ...
    std::string settings;     // what was set and why, in a line
    std::string failure;      // empty if the run went through
    std::vector<double> t;    // samples every sample_dt from 0
    std::vector<Vec3> q;      // (s_x, s_y, theta) in the plate frame
    double cpu_seconds = 0;   // the engine's stepping only (set-up excluded), this thread's CPU time
    long steps = 0;
    double max_lift = 0;   // largest |centre of mass height above the plate - s_z| over the samples [m]
};

// Records the part's body pose (x, R: its centre of mass and frame in W) at time t as a sample of r in
// the plate frame, and its lift off the resting height; false (r.failure set) if it left the plate.
bool record_sample(PeerRun& r, const Part& part, const PlateTrack& plate, double t, const Vec3& x, const Eigen::Quaterniond& R,
                   double first_theta);

// This thread's CPU time [s] (the study runs one thread each).
double cpu_now();
// The whole number of steps dt in `span`; 0 and `failure` set if span is not one (samples would drift).
long whole_steps(double span, double dt, std::string& failure);

// One engine: its name and its run. The part starts at rest relative to the plate at q0.
struct Engine {
    std::string name;
    PeerRun (*run)(const Scene& scene, const Vec3& q0, double duration, double sample_dt, const PeerOptions& opt);
};
// The engines this build has (in the order Bullet, ODE, MuJoCo).
std::vector<Engine> engines();

PeerRun run_bullet(const Scene&, const Vec3&, double, double, const PeerOptions&);
PeerRun run_ode(const Scene&, const Vec3&, double, double, const PeerOptions&);
PeerRun run_mujoco(const Scene&, const Vec3&, double, double, const PeerOptions&);

}   // namespace plate::peers
