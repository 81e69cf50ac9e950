// Bullet soft-body cloth, driven like a Drape garment (see bullet_cloth.hpp).
//
// Step order of one frame (Bullet 3.24, btSoftRigidDynamicsWorld):
//   1. each ellipsoid's kinematic body gets its new pose through its motion state; Bullet
//      derives its velocity over the frame (saveKinematicState) for the contacts;
//   2. each pinned node gets the velocity that carries it to its target over the frame
//      (pinned nodes have inverse mass 0 but are still advected by predictMotion);
//   3. stepSimulation(frame, substeps, frame / substeps);
//   4. pinned nodes are snapped to their targets (no drift).
#include "bench/bullet_cloth.hpp"

#include <cmath>
#include <limits>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

namespace drape::bench {

namespace {

btVector3 to_bt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// Splits a unit-sphere -> world ellipsoid transform into a rigid pose and radii.
btTransform rigid_pose(const Affine3& world, const Vec3& radii) {
    const Mat3 rotation = world.linear() * radii.cwiseInverse().asDiagonal();
    Quat q(rotation);
    q.normalize();
    return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), to_bt(world.translation()));
}

}  // namespace

struct BulletCloth::Impl {
    btSoftBodyRigidBodyCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
    btSoftBodyWorldInfo* info = nullptr;

    std::vector<std::unique_ptr<btMultiSphereShape>> shapes;
    std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
    std::vector<Vec3> radii;
    std::unique_ptr<btSoftBody> cloth;
    std::vector<std::uint32_t> pinned;
    BulletTuning tuning;

    ~Impl() {
        if (cloth) world.removeSoftBody(cloth.get());
        for (auto& body : bodies) world.removeRigidBody(body.get());
    }
};

BulletCloth::BulletCloth(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
BulletCloth::BulletCloth(BulletCloth&&) noexcept = default;
BulletCloth& BulletCloth::operator=(BulletCloth&&) noexcept = default;
BulletCloth::~BulletCloth() = default;

Result<BulletCloth> BulletCloth::create(const ClothSpec& spec, const std::vector<Affine3>& ellipsoids,
                                        const BulletTuning& tuning) {
    const auto n = static_cast<std::uint32_t>(spec.x.cols());
    if (n == 0) return fail("bullet peer: the cloth has no particles");
    if (!(spec.mass_kg > 0)) return fail("bullet peer: particle mass must be > 0");
    for (const auto& s : spec.springs)
        if (s[0] >= n || s[1] >= n || s[0] == s[1]) return fail("bullet peer: a spring names a missing particle");
    for (auto p : spec.pinned)
        if (p >= n) return fail("bullet peer: a pinned index is out of range");
    if (tuning.substeps < 1 || tuning.position_iterations < 1) return fail("bullet peer: substeps and iterations must be >= 1");

    auto impl = std::make_unique<Impl>();
    impl->tuning = tuning;
    impl->pinned = spec.pinned;
    impl->world.setGravity(btVector3(0, -standard_gravity_m_s2, 0));
    impl->info = &impl->world.getWorldInfo();
    impl->info->m_gravity = btVector3(0, -standard_gravity_m_s2, 0);
    impl->info->air_density = 1.2f;
    impl->info->m_sparsesdf.Initialize();
    impl->info->m_sparsesdf.setDefaultVoxelsz(tuning.sdf_voxel_m);
    impl->info->m_sparsesdf.Reset();

    // Ellipsoids: kinematic rigid bodies with a scaled unit sphere.
    for (const auto& world : ellipsoids) {
        Vec3 radii(world.linear().col(0).norm(), world.linear().col(1).norm(), world.linear().col(2).norm());
        if (!(radii.minCoeff() > 0)) return fail("bullet peer: an ellipsoid has a zero radius");
        const btVector3 centre(0, 0, 0);
        const btScalar unit = 1;
        auto shape = std::make_unique<btMultiSphereShape>(&centre, &unit, 1);
        shape->setLocalScaling(to_bt(radii));
        auto motion = std::make_unique<btDefaultMotionState>(rigid_pose(world, radii));
        btRigidBody::btRigidBodyConstructionInfo ci(0, motion.get(), shape.get());
        auto body = std::make_unique<btRigidBody>(ci);
        body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
        body->setActivationState(DISABLE_DEACTIVATION);
        body->setFriction(tuning.friction);
        impl->world.addRigidBody(body.get());
        impl->shapes.push_back(std::move(shape));
        impl->motion_states.push_back(std::move(motion));
        impl->bodies.push_back(std::move(body));
        impl->radii.push_back(radii);
    }

    // The cloth: the same particles and structural springs.
    std::vector<btVector3> x(n);
    std::vector<btScalar> m(n, spec.mass_kg);
    for (std::uint32_t i = 0; i < n; ++i) x[i] = to_bt(spec.x.col(i));
    for (auto p : spec.pinned) m[p] = 0;
    impl->cloth = std::make_unique<btSoftBody>(impl->info, static_cast<int>(n), x.data(), m.data());
    btSoftBody& sb = *impl->cloth;
    btSoftBody::Material* material = sb.appendMaterial();
    material->m_kLST = tuning.link_stiffness;
    material->m_kAST = 1;
    material->m_kVST = 1;
    for (const auto& s : spec.springs) sb.appendLink(static_cast<int>(s[0]), static_cast<int>(s[1]), material);
    if (tuning.bending_links) sb.generateBendingConstraints(2, material);
    sb.m_cfg.piterations = tuning.position_iterations;
    sb.m_cfg.diterations = tuning.drift_iterations;
    sb.m_cfg.kDP = tuning.damping;
    sb.m_cfg.kCHR = tuning.rigid_hardness;
    sb.m_cfg.kKHR = tuning.kinetic_hardness;
    sb.m_cfg.kDF = tuning.friction;
    sb.m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
    sb.getCollisionShape()->setMargin(tuning.margin_m);
    sb.setActivationState(DISABLE_DEACTIVATION);
    impl->world.addSoftBody(&sb);
    return BulletCloth(std::move(impl));
}

void BulletCloth::step(const Matrix3X& pinned_x, const std::vector<Affine3>& ellipsoids, double frame_dt_s) {
    Impl& impl = *m_impl;
    for (std::size_t i = 0; i < impl.bodies.size() && i < ellipsoids.size(); ++i)
        impl.motion_states[i]->setWorldTransform(rigid_pose(ellipsoids[i], impl.radii[i]));
    btSoftBody& sb = *impl.cloth;
    const auto inv_dt = static_cast<btScalar>(1.0 / frame_dt_s);
    for (std::size_t k = 0; k < impl.pinned.size(); ++k) {
        btSoftBody::Node& node = sb.m_nodes[static_cast<int>(impl.pinned[k])];
        node.m_v = (to_bt(pinned_x.col(static_cast<Eigen::Index>(k))) - node.m_x) * inv_dt;
    }
    impl.world.stepSimulation(static_cast<btScalar>(frame_dt_s), impl.tuning.substeps,
                              static_cast<btScalar>(frame_dt_s / impl.tuning.substeps));
    for (std::size_t k = 0; k < impl.pinned.size(); ++k) {
        btSoftBody::Node& node = sb.m_nodes[static_cast<int>(impl.pinned[k])];
        node.m_x = to_bt(pinned_x.col(static_cast<Eigen::Index>(k)));
        node.m_q = node.m_x;
    }
}

Matrix3X BulletCloth::positions() const {
    const btSoftBody& sb = *m_impl->cloth;
    Matrix3X x(3, sb.m_nodes.size());
    for (int i = 0; i < sb.m_nodes.size(); ++i) {
        const btVector3& p = sb.m_nodes[i].m_x;
        x.col(i) = Vec3(p.x(), p.y(), p.z());
    }
    return x;
}

double max_penetration_m(const Matrix3X& x, const std::vector<Affine3>& ellipsoids,
                         const std::vector<std::uint32_t>& skip) {
    std::vector<bool> skipped(static_cast<std::size_t>(x.cols()), false);
    for (auto i : skip)
        if (i < skipped.size()) skipped[i] = true;
    double deepest = 0;
    for (const auto& world : ellipsoids) {
        const Affine3 inverse = world.inverse();
        const Vec3 centre = world.translation();
        for (Eigen::Index i = 0; i < x.cols(); ++i) {
            if (skipped[static_cast<std::size_t>(i)]) continue;
            const Vec3 q = inverse * x.col(i);
            const Real r = q.norm();
            if (!std::isfinite(r)) return std::numeric_limits<double>::infinity();
            if (r >= 1) continue;
            const double depth = r > 1e-6f ? (x.col(i) - centre).norm() * (1.0 / r - 1.0)
                                           : (world.linear() * Vec3::UnitX()).norm();
            deepest = std::max(deepest, depth);
        }
    }
    return deepest;
}

double max_strain(const Matrix3X& x, const std::vector<std::array<std::uint32_t, 2>>& springs,
                  const std::vector<Real>& rest_m) {
    double strain = 0;
    for (std::size_t s = 0; s < springs.size(); ++s) {
        const double length = (x.col(springs[s][0]) - x.col(springs[s][1])).norm();
        if (!std::isfinite(length)) return std::numeric_limits<double>::infinity();
        if (rest_m[s] > 0) strain = std::max(strain, length / rest_m[s] - 1.0);
    }
    return strain;
}

std::vector<Real> rest_lengths(const Matrix3X& x, const std::vector<std::array<std::uint32_t, 2>>& springs) {
    std::vector<Real> rest(springs.size());
    for (std::size_t s = 0; s < springs.size(); ++s) rest[s] = (x.col(springs[s][0]) - x.col(springs[s][1])).norm();
    return rest;
}

}  // namespace drape::bench
