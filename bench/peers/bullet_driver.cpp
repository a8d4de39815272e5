// Bullet 3.24 (Debian libbullet-dev, the double-precision build bullet-float64). Settings, and why:
//   fixed steps of dt (stepSimulation(dt, 0): no interpolation, no sub-stepping);
//   sequential impulses, 100 iterations, split impulse off (position errors corrected in the
//   velocity solve, as the other engines do), no deactivation (a sleeping part would stop);
//   one friction direction, along the slip (Bullet's default): a sliding contact feels mu N against
//   its slip (the disk's answer), where two fixed directions would make a box; friction combines as a
//   product, so the plate has 1 and the part mu;
//   collision margins 0.1 mm (the default 4 cm would lift a small part off the plate);
//   the plate: a kinematic body, its pose at the end of each step given through its motion state
//   (Bullet takes the velocity from the pose change over the step).
#include "peers.hpp"

#include <btBulletDynamicsCommon.h>

#include <chrono>
#include <cmath>
#include <memory>

namespace plate::peers {

namespace {
btVector3 bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
btQuaternion bt(const Eigen::Quaterniond& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
}   // namespace

PeerRun run_bullet(const Scene& sc, const Vec3& q0, double duration, double sample_dt, const PeerOptions& opt) {
    PeerRun r;
    r.engine = "Bullet " + std::to_string(btGetVersion() / 100) + "." + std::to_string(btGetVersion() % 100) +
               (sizeof(btScalar) == 8 ? " (double)" : " (float)");
    const Part& P = sc.part;
    if (P.point) {
        r.failure = "point parts are not modelled here (a ball would roll)";
        return r;
    }
    if (!P.friction().single()) {
        r.failure = "Bullet has one friction coefficient per contact: static friction above kinetic is not modelled";
        return r;
    }
    if (P.friction().kinetic().maxCoeff() != P.friction().kinetic().minCoeff()) {
        r.failure = "Bullet has one friction coefficient per body: contacts with different mu are not modelled";
        return r;
    }
    const double dt = opt.dt, rad = opt.sphere_radius;
    const long n = whole_steps(duration, dt, r.failure), every = whole_steps(sample_dt, dt, r.failure);
    if (!r.failure.empty()) return r;
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.setGravity(btVector3(0, 0, -sc.g));
    world.getSolverInfo().m_numIterations = 100;
    world.getSolverInfo().m_splitImpulse = 0;
    if (opt.pyramid)   // two friction directions, fixed in the contact's plane: a box
        world.getSolverInfo().m_solverMode |=
            SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
    // The plate: a box whose top face is the plate plane.
    btBoxShape box(btVector3(1, 1, 0.05));
    box.setMargin(1e-4);
    btCompoundShape plate_shape;
    plate_shape.addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -0.05)), &box);
    PlateTrack plate(sc.plate, opt.drift);
    btDefaultMotionState plate_motion(btTransform(bt(plate.R), bt(plate.p)));
    btRigidBody plate_body(0, &plate_motion, &plate_shape);
    plate_body.setCollisionFlags(plate_body.getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    plate_body.setActivationState(DISABLE_DEACTIVATION);
    plate_body.setFriction(1);
    world.addRigidBody(&plate_body);
    // The part in its principal axes (Bullet's inertia is diagonal): body frame = part frame V.
    Eigen::SelfAdjointEigenSolver<Mat3> eig(P.J);
    Mat3 V = eig.eigenvectors();
    if (V.determinant() < 0) V.col(2) *= -1;
    const Eigen::Quaterniond Vq(V);
    btCompoundShape part_shape;
    std::vector<std::unique_ptr<btSphereShape>> spheres;
    const double mu = P.friction().kinetic(0);
    for (int i = 0; i < 3; ++i) {
        spheres.push_back(std::make_unique<btSphereShape>(rad));
        const Vec3 at = V.transpose() * (P.c[i] + Vec3(0, 0, rad));
        part_shape.addChildShape(btTransform(btQuaternion::getIdentity(), bt(at)), spheres.back().get());
    }
    part_shape.setMargin(1e-4);
    const BodyState b = at_rest_on_plate(P, plate, q0);
    btDefaultMotionState part_motion(btTransform(bt(b.R * Vq), bt(b.x)));
    btRigidBody::btRigidBodyConstructionInfo info(P.m, &part_motion, &part_shape, bt(eig.eigenvalues()));
    btRigidBody part(info);
    part.setActivationState(DISABLE_DEACTIVATION);
    part.setFriction(mu);
    part.setRollingFriction(0);
    part.setLinearVelocity(bt(b.v));
    part.setAngularVelocity(bt(b.w));
    world.addRigidBody(&part);
    r.settings =
        std::string(
            "double precision, fixed steps (no interpolation or sub-steps), 100 sequential-impulse iterations, "
            "no split impulse, ") +
        (opt.pyramid ? "TWO FIXED friction directions (a box), "
                     : "one friction direction, along the slip (Bullet's default: a sliding contact feels mu N against its "
                       "slip), ") +
        "collision margins 0.1 mm (the default 4 cm lifts a small part off the plate), no deactivation (a sleeping part "
        "stops); the plate a kinematic body; spheres r = " +
        std::to_string(std::lround(rad * 1e6)) + " um";
    auto record = [&](double t) {
        const btTransform& T = part.getCenterOfMassTransform();
        const btQuaternion q = T.getRotation();
        const Eigen::Quaterniond R = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()) * Vq.conjugate();
        return record_sample(r, P, plate, t, Vec3(T.getOrigin().x(), T.getOrigin().y(), T.getOrigin().z()), R, q0[2]);
    };
    record(0);
    double cpu = 0;
    for (long k = 1; k <= n; ++k) {
        plate.advance(k * dt);   // the plate's pose at the end of the step
        plate_motion.setWorldTransform(btTransform(bt(plate.R), bt(plate.p)));
        const double c0 = cpu_now();
        world.stepSimulation(dt, 0);
        cpu += cpu_now() - c0;
        if ((k % every == 0 || k == n) && !record(k * dt)) break;
    }
    r.cpu_seconds = cpu;
    r.steps = n;
    world.removeRigidBody(&part);
    world.removeRigidBody(&plate_body);
    return r;
}

}   // namespace plate::peers
