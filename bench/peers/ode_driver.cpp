// ODE 0.16 (Debian libode-dev, double precision). Settings, and why:
//   dWorldStep          the Dantzig LCP solver (exact for the step's linearised contact problem), not
//                       the iterative QuickStep;
//   dContactApprox1     friction bounded by mu N (without it mu is a force in newtons);
//   dContactFDir1       ODE's friction is a box (two directions, each bounded by mu N): its first
//   + dContactMu2 = 0   direction is set along the contact's slip before every step and, for a contact
//                       slipping faster than 1e-5 m/s, the second row (across the slip) is freed, so a
//                       sliding contact feels mu N against its slip (the disk's answer; with both rows it
//                       could push up to sqrt 2 mu N, across its slip: fig4's turn came out 0.37 of
//                       plate's, 0.98 now) -- the box otherwise turns the part the wrong way in yaw;
//                       sticking contacts keep the box;
//   ERP 0.2, CFM 1e-9   stiff contacts (penetration ~ microns), the default error reduction;
//   the plate: a kinematic body whose pose and velocity are set before every step.
#include "peers.hpp"

#include <ode/ode.h>

#include <chrono>
#include <cmath>
#include <mutex>

namespace plate::peers {

namespace {

constexpr double kSliding = 1e-4;   // [m/s]: a contact slipping faster slides (friction along its slip only)

struct World {
    dWorldID world;
    dSpaceID space;
    dJointGroupID contacts;
    dBodyID plate, part;
    dGeomID box;
    dGeomID spheres[3];
    double mu[3];
    bool pyramid;
};

void near(void* data, dGeomID o1, dGeomID o2) {
    World& w = *static_cast<World*>(data);
    if (dGeomGetBody(o1) == dGeomGetBody(o2)) return;
    dContact c[4];
    const int n = dCollide(o1, o2, 4, &c[0].geom, sizeof(dContact));
    const dGeomID sphere = o1 == w.box ? o2 : o1;
    int i = 0;
    while (i < 3 && w.spheres[i] != sphere) ++i;
    if (i == 3) return;
    for (int k = 0; k < n; ++k) {
        dContactGeom& g = c[k].geom;
        // The slip at the contact point: the part's velocity there minus the plate's, in the plane.
        dVector3 vp, vq;
        dBodyGetPointVel(w.part, g.pos[0], g.pos[1], g.pos[2], vp);
        dBodyGetPointVel(w.plate, g.pos[0], g.pos[1], g.pos[2], vq);
        const Vec3 nrm(g.normal[0], g.normal[1], g.normal[2]);
        Vec3 slip(vp[0] - vq[0], vp[1] - vq[1], vp[2] - vq[2]);
        slip -= slip.dot(nrm) * nrm;
        const bool sliding = slip.norm() > kSliding;
        Vec3 dir = sliding ? Vec3(slip.normalized()) : Vec3(nrm.unitOrthogonal());
        c[k].surface.mode = dContactApprox1 | (w.pyramid ? 0 : dContactFDir1);
        c[k].surface.mu = w.mu[i];
        if (sliding && !w.pyramid) {   // the second row (across the slip) free: the disk's force, mu N against the slip
            c[k].surface.mode |= dContactMu2;
            c[k].surface.mu2 = 0;
        }
        c[k].fdir1[0] = dir.x(), c[k].fdir1[1] = dir.y(), c[k].fdir1[2] = dir.z();
        const dJointID j = dJointCreateContact(w.world, w.contacts, &c[k]);
        dJointAttach(j, dGeomGetBody(g.g1), dGeomGetBody(g.g2));
    }
}

std::once_flag ode_init;

}   // namespace

PeerRun run_ode(const Scene& sc, const Vec3& q0, double duration, double sample_dt, const PeerOptions& opt) {
    PeerRun r;
    r.engine = "ODE 0.16";
    const Part& P = sc.part;
    if (P.point) {
        r.failure = "point parts are not modelled here (a ball would roll)";
        return r;
    }
    if (!P.friction().single()) {
        r.failure = "ODE has one friction coefficient per contact: static friction above kinetic is not modelled";
        return r;
    }
    std::call_once(ode_init, [] { dInitODE2(0); });
    const double dt = opt.dt, rad = opt.sphere_radius;
    const long n = whole_steps(duration, dt, r.failure), every = whole_steps(sample_dt, dt, r.failure);
    if (!r.failure.empty()) return r;
    World w;
    w.pyramid = opt.pyramid;
    w.world = dWorldCreate();
    dWorldSetGravity(w.world, 0, 0, -sc.g);
    dWorldSetERP(w.world, 0.2);
    dWorldSetCFM(w.world, 1e-9);
    w.space = dSimpleSpaceCreate(nullptr);
    w.contacts = dJointGroupCreate(0);
    w.plate = dBodyCreate(w.world);
    dBodySetKinematic(w.plate);
    w.box = dCreateBox(w.space, 2, 2, 0.1);
    dGeomSetBody(w.box, w.plate);
    dGeomSetOffsetPosition(w.box, 0, 0, -0.05);
    w.part = dBodyCreate(w.world);
    dMass M;
    dMassSetParameters(&M, P.m, 0, 0, 0, P.J(0, 0), P.J(1, 1), P.J(2, 2), P.J(0, 1), P.J(0, 2), P.J(1, 2));
    dBodySetMass(w.part, &M);
    dBodySetAutoDisableFlag(w.part, 0);
    dBodySetGyroscopicMode(w.part, 1);
    for (int i = 0; i < 3; ++i) {
        w.spheres[i] = dCreateSphere(w.space, rad);
        dGeomSetBody(w.spheres[i], w.part);
        dGeomSetOffsetPosition(w.spheres[i], P.c[i].x(), P.c[i].y(), P.c[i].z() + rad);
        w.mu[i] = P.friction().kinetic(i);
    }
    r.settings = std::string(
                     "dWorldStep (the Dantzig LCP, exact for the step, not the iterative QuickStep), dContactApprox1 "
                     "(friction bounded by mu N, not a force in newtons), ") +
                 (opt.pyramid ? "FIXED friction directions (ODE's box)"
                              : "the first friction direction set along the slip every step and the second freed while it slides "
                                "(ODE's friction is a box: so a sliding contact feels mu N against its slip)") +
                 ", ERP 0.2 and CFM 1e-9 (stiff contacts); the plate a kinematic body; spheres r = " +
                 std::to_string(std::lround(rad * 1e6)) + " um";
    PlateTrack plate(sc.plate, opt.drift);
    auto set_plate = [&] {
        dBodySetPosition(w.plate, plate.p.x(), plate.p.y(), plate.p.z());
        const dQuaternion q = {plate.R.w(), plate.R.x(), plate.R.y(), plate.R.z()};
        dBodySetQuaternion(w.plate, q);
        dBodySetLinearVel(w.plate, plate.v.x(), plate.v.y(), plate.v.z());
        dBodySetAngularVel(w.plate, plate.w.x(), plate.w.y(), plate.w.z());
    };
    const BodyState b = at_rest_on_plate(P, plate, q0);
    dBodySetPosition(w.part, b.x.x(), b.x.y(), b.x.z());
    const dQuaternion bq = {b.R.w(), b.R.x(), b.R.y(), b.R.z()};
    dBodySetQuaternion(w.part, bq);
    dBodySetLinearVel(w.part, b.v.x(), b.v.y(), b.v.z());
    dBodySetAngularVel(w.part, b.w.x(), b.w.y(), b.w.z());
    auto record = [&](double t) {
        const dReal* x = dBodyGetPosition(w.part);
        const dReal* q = dBodyGetQuaternion(w.part);
        return record_sample(r, P, plate, t, Vec3(x[0], x[1], x[2]), Eigen::Quaterniond(q[0], q[1], q[2], q[3]), q0[2]);
    };
    record(0);
    double cpu = 0;
    for (long k = 1; k <= n; ++k) {
        set_plate();
        const double c0 = cpu_now();
        dSpaceCollide(w.space, &w, &near);
        dWorldStep(w.world, dt);
        dJointGroupEmpty(w.contacts);
        cpu += cpu_now() - c0;
        plate.advance(k * dt);
        if ((k % every == 0 || k == n) && !record(k * dt)) break;
    }
    r.cpu_seconds = cpu;
    r.steps = n;
    dJointGroupDestroy(w.contacts);
    dSpaceDestroy(w.space);
    dWorldDestroy(w.world);
    return r;
}

}   // namespace plate::peers
