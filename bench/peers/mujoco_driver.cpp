// MuJoCo 2.2.2 (Debian libmujoco-dev). Settings, and why:
//   cone="elliptic"     the friction disk (the default pyramid turns a part the wrong way in yaw);
//   impratio=100        friction rows 100x stiffer than the normal's: little creep while sticking;
//   solver Newton, 100 iterations, tolerance 1e-12: the contact problem solved, not approximated;
//   solref (4 dt, 1)    the contacts' time constant a few steps, critically damped. Measured on fig4's
//                       first second against plate (turn ratio, 1 = plate's): at MuJoCo's floor of 2 dt
//                       a part sliding at 1 m/s hops 3.8 mm with Euler and fig4's turn flips sign
//                       between dt 1e-4 and 5e-5; at 4 dt 0.69-0.72 for dt 5e-5 and 2.5e-5; from ~10 dt
//                       on the soft contact turns the part the wrong way (MuJoCo's default 0.02 s: -6.8);
//                       solimp 0.95 0.99 1e-4: stiff impedance (penetration ~ microns);
//   the plate: a free body of 10 t whose pose and velocity are set to the plate's before every step,
//   with the force and torque that give it u(t) during the step (a mocap body would have zero
//   velocity in the contact rows: friction would see the wrong slip).
#include "peers.hpp"

#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>

namespace plate::peers {

namespace {
constexpr double kPlateMass = 1e4, kPlateInertia = 1e3;
}

PeerRun run_mujoco(const Scene& sc, const Vec3& q0, double duration, double sample_dt, const PeerOptions& opt) {
    PeerRun r;
    r.engine = "MuJoCo " + std::to_string(mj_version() / 100) + "." + std::to_string(mj_version() / 10 % 10) + "." +
               std::to_string(mj_version() % 10);
    const Part& P = sc.part;
    if (P.point) {
        r.failure = "point parts are not modelled here (a ball would roll)";
        return r;
    }
    if (!P.friction().single()) {
        r.failure = "MuJoCo has one friction coefficient per contact: static friction above kinetic is not modelled";
        return r;
    }
    const double dt = opt.dt, rad = opt.sphere_radius;
    const long n = whole_steps(duration, dt, r.failure), every = whole_steps(sample_dt, dt, r.failure);
    if (!r.failure.empty()) return r;
    std::ostringstream x;
    x.precision(17);
    x << "<mujoco><option timestep=\"" << dt << "\" gravity=\"0 0 " << -sc.g << "\" cone=\""
      << (opt.pyramid ? "pyramidal" : "elliptic")
      << "\" impratio=\"100\" solver=\"Newton\" iterations=\"100\" tolerance=\"1e-12\"/>"
      << "<default><geom condim=\"3\" solref=\"" << (opt.contact_time > 0 ? opt.contact_time : 4 * dt)
      << " 1\" solimp=\"0.95 0.99 0.0001\"/></default>"
      << "<worldbody><body name=\"plate\"><freejoint/><inertial pos=\"0 0 0\" mass=\"" << kPlateMass << "\" diaginertia=\""
      << kPlateInertia << " " << kPlateInertia << " " << kPlateInertia << "\"/>"
      << "<geom type=\"box\" size=\"1 1 0.05\" pos=\"0 0 -0.05\" friction=\"0 0 0\"/></body>"
      << "<body name=\"part\"><freejoint/><inertial pos=\"0 0 0\" mass=\"" << P.m << "\" fullinertia=\"" << P.J(0, 0) << " "
      << P.J(1, 1) << " " << P.J(2, 2) << " " << P.J(0, 1) << " " << P.J(0, 2) << " " << P.J(1, 2) << "\"/>";
    for (int i = 0; i < 3; ++i)
        x << "<geom type=\"sphere\" size=\"" << rad << "\" pos=\"" << P.c[i].x() << " " << P.c[i].y() << " " << P.c[i].z() + rad
          << "\" friction=\"" << P.friction().kinetic(i) << " 0 0\"/>";
    x << "</body></worldbody></mujoco>";
    const std::string xml = x.str();
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    mj_makeEmptyFileVFS(vfs.get(), "peer.xml", static_cast<int>(xml.size()));
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), "peer.xml")], xml.data(), xml.size());
    char err[1000] = "";
    mjModel* m = mj_loadXML("peer.xml", vfs.get(), err, sizeof err);
    mj_deleteVFS(vfs.get());
    if (!m) {
        r.failure = std::string("MuJoCo rejected the model: ") + err;
        return r;
    }
    mjData* d = mj_makeData(m);
    r.settings =
        std::string(opt.pyramid ? "PYRAMIDAL cone (MuJoCo's default)"
                                : "elliptic cone (the friction disk; the default pyramid turns the part the wrong way in yaw)") +
        ", impratio 100 (friction rows stiffer than the normal's: little creep while sticking), Newton solver with 100 "
        "iterations to 1e-12 (the contact problem solved, not approximated), solref (4 dt, 1) (a few steps, critically damped: "
        "at MuJoCo's floor of 2 dt a sliding part hops, from ~10 dt on the soft contact turns it the wrong way), solimp 0.95 "
        "0.99 1e-4 (stiff), Euler integrator; the plate a 10 t free body set "
        "to the plate's pose and velocity every step (a mocap body would have zero velocity in the contact rows); spheres r = " +
        std::to_string(std::lround(rad * 1e6)) + " um";
    PlateTrack plate(sc.plate, opt.drift);
    auto set_plate = [&] {
        d->qpos[0] = plate.p.x(), d->qpos[1] = plate.p.y(), d->qpos[2] = plate.p.z();
        d->qpos[3] = plate.R.w(), d->qpos[4] = plate.R.x(), d->qpos[5] = plate.R.y(), d->qpos[6] = plate.R.z();
        const Vec3 wl = plate.R.conjugate() * plate.w;   // (a free joint's angular velocity is in its body's frame)
        for (int k = 0; k < 3; ++k) {
            d->qvel[k] = plate.v[k];
            d->qvel[3 + k] = wl[k];
            d->xfrc_applied[6 + k] = kPlateMass * (plate.a[k] + (k == 2 ? sc.g : 0.0));   // body 1 (0: world)
            d->xfrc_applied[9 + k] = kPlateInertia * plate.alpha[k];
        }
    };
    const BodyState b = at_rest_on_plate(P, plate, q0);
    for (int k = 0; k < 3; ++k) {
        d->qpos[7 + k] = b.x[k];
        d->qvel[6 + k] = b.v[k];
    }
    d->qpos[10] = b.R.w(), d->qpos[11] = b.R.x(), d->qpos[12] = b.R.y(), d->qpos[13] = b.R.z();
    const Vec3 wl = b.R.conjugate() * b.w;
    for (int k = 0; k < 3; ++k) d->qvel[9 + k] = wl[k];
    set_plate();
    mj_forward(m, d);
    auto record = [&](double t) {
        const Vec3 xp(d->qpos[7], d->qpos[8], d->qpos[9]);
        const Eigen::Quaterniond R(d->qpos[10], d->qpos[11], d->qpos[12], d->qpos[13]);
        return record_sample(r, P, plate, t, xp, R, q0[2]);
    };
    record(0);
    double cpu = 0;
    for (long k = 1; k <= n; ++k) {
        set_plate();
        const double c0 = cpu_now();
        mj_step(m, d);
        cpu += cpu_now() - c0;
        plate.advance(k * dt);
        if ((k % every == 0 || k == n) && !record(k * dt)) break;
    }
    r.cpu_seconds = cpu;
    r.steps = n;
    mj_deleteData(d);
    mj_deleteModel(m);
    return r;
}

}   // namespace plate::peers
