// Bullet soft-body cloth, driven like a Drape garment (see bullet_cloth.hpp).
//
// Step order of one frame (Bullet 3.24, btSoftRigidDynamicsWorld):
//   1. each ellipsoid's kinematic body gets its new pose through its motion state; Bullet
//      derives its velocity over the frame (saveKinematicState) for the contacts;
//   2. each pinned node gets the velocity that carries it to its target over the frame
//      (pinned nodes have inverse mass 0 but are still advected by predictMotion);
//   3. stepSimulation(frame, substeps, frame / substeps); in each internal step Bullet
//      predicts the nodes, collects the contacts, calls the world's internal tick callback
//      (here: the deepest free node inside an ellipsoid, before the response), then solves
//      links and contacts;
//   4. pinned nodes are snapped to their targets (no drift).
// Rest lengths: Bullet takes a link's rest length from the nodes' distance when it first
// updates its constants (btSoftBody::updateConstants, on the first predictMotion after
// appendLink); create() runs that update itself and then writes the given rest lengths.
#include "bench/bullet_cloth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include "bench/report.hpp"

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
    std::vector<Affine3> ellipsoids;   ///< This frame's poses (what the kinematic bodies hold).
    BulletFrame frame;

    // After Bullet's prediction and contact collection, before its solve (see step 3).
    static void after_prediction(btDynamicsWorld* world, btScalar) {
        auto* self = static_cast<Impl*>(world->getWorldUserInfo());
        const std::int64_t start = now_ns();
        self->frame.penetration_before_m =
            std::max(self->frame.penetration_before_m, max_penetration_m(self->node_positions(), self->ellipsoids, self->pinned));
        self->frame.probe_ms += elapsed_ms(start);
    }
    Matrix3X node_positions() const {
        Matrix3X x(3, cloth->m_nodes.size());
        for (int i = 0; i < cloth->m_nodes.size(); ++i) {
            const btVector3& p = cloth->m_nodes[i].m_x;
            x.col(i) = Vec3(p.x(), p.y(), p.z());
        }
        return x;
    }

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
    if (!spec.rest_m.empty() && spec.rest_m.size() != spec.springs.size())
        return fail("bullet peer: " + std::to_string(spec.rest_m.size()) + " rest lengths for " +
                    std::to_string(spec.springs.size()) + " springs");
    for (Real rest : spec.rest_m)
        if (!(rest > 0) || !std::isfinite(rest)) return fail("bullet peer: a rest length is not a positive number");
    if (!spec.masses_kg.empty() && spec.masses_kg.size() != n)
        return fail("bullet peer: " + std::to_string(spec.masses_kg.size()) + " masses for " + std::to_string(n) + " particles");
    for (auto p : spec.pinned)
        if (p >= n) return fail("bullet peer: a pinned index is out of range");
    if (tuning.substeps < 1 || tuning.position_iterations < 1) return fail("bullet peer: substeps and iterations must be >= 1");

    auto impl = std::make_unique<Impl>();
    impl->tuning = tuning;
    impl->pinned = spec.pinned;
    std::sort(impl->pinned.begin(), impl->pinned.end());
    impl->ellipsoids = ellipsoids;
    impl->world.setInternalTickCallback(&Impl::after_prediction, impl.get(), false);
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

    // The cloth: the same particles, masses and springs.
    std::vector<btVector3> x(n);
    std::vector<btScalar> m(n, spec.mass_kg);
    for (std::uint32_t i = 0; i < n; ++i) {
        x[i] = to_bt(spec.x.col(i));
        if (!spec.masses_kg.empty()) m[i] = spec.masses_kg[i];
        if (!(m[i] > 0) || !std::isfinite(m[i])) return fail("bullet peer: particle " + std::to_string(i) + " has no positive mass");
    }
    for (auto p : spec.pinned) m[p] = 0;
    impl->cloth = std::make_unique<btSoftBody>(impl->info, static_cast<int>(n), x.data(), m.data());
    btSoftBody& sb = *impl->cloth;
    btSoftBody::Material* material = sb.appendMaterial();
    material->m_kLST = tuning.link_stiffness;
    material->m_kAST = 1;
    material->m_kVST = 1;
    for (const auto& s : spec.springs) sb.appendLink(static_cast<int>(s[0]), static_cast<int>(s[1]), material);
    // Bullet's own constant update (rest lengths from the distances, link and area
    // constants), done now so that it does not run again, then the given rest lengths.
    sb.updateConstants();
    sb.m_bUpdateRtCst = false;
    if (!spec.rest_m.empty())
        for (int i = 0; i < sb.m_links.size(); ++i) {
            btSoftBody::Link& link = sb.m_links[i];
            link.m_rl = spec.rest_m[static_cast<std::size_t>(i)];
            link.m_c1 = link.m_rl * link.m_rl;
        }
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
    impl.frame = {};
    impl.ellipsoids = ellipsoids;
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

Matrix3X BulletCloth::positions() const { return m_impl->node_positions(); }

BulletFrame BulletCloth::last_frame() const { return m_impl->frame; }

std::vector<Real> BulletCloth::link_rest_lengths() const {
    const btSoftBody& sb = *m_impl->cloth;
    std::vector<Real> rest(static_cast<std::size_t>(sb.m_links.size()));
    for (int i = 0; i < sb.m_links.size(); ++i) rest[static_cast<std::size_t>(i)] = sb.m_links[i].m_rl;
    return rest;
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

BulletSelection select_bullet_configuration(const std::vector<BulletCandidate>& candidates, const BulletSelectionRule& rule) {
    BulletSelection chosen;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
        const BulletCandidate& c = candidates[i];
        if (!c.usable || !(c.strain_p99 <= rule.strain_p99_max) || !(c.penetration_after_m <= rule.penetration_after_max_m)) continue;
        if (chosen.index < 0 || c.ms_per_frame < candidates[static_cast<std::size_t>(chosen.index)].ms_per_frame)
            chosen = {static_cast<int>(i), true};
    }
    if (chosen.index >= 0) return chosen;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
        const BulletCandidate& c = candidates[i];
        if (!c.usable || !std::isfinite(c.strain_p99)) continue;
        if (chosen.index < 0) {
            chosen.index = static_cast<int>(i);
            continue;
        }
        const BulletCandidate& best = candidates[static_cast<std::size_t>(chosen.index)];
        if (c.strain_p99 < best.strain_p99 || (c.strain_p99 == best.strain_p99 && c.ms_per_frame < best.ms_per_frame))
            chosen.index = static_cast<int>(i);
    }
    return chosen;
}

std::vector<Real> rest_lengths(const Matrix3X& x, const std::vector<std::array<std::uint32_t, 2>>& springs) {
    std::vector<Real> rest(springs.size());
    for (std::size_t s = 0; s < springs.size(); ++s) rest[s] = (x.col(springs[s][0]) - x.col(springs[s][1])).norm();
    return rest;
}

}  // namespace drape::bench
