// Bullet's soft-body cloth (btSoftBody in a btSoftRigidDynamicsWorld) driven exactly like a
// Drape garment, for the `peers` benchmark: the same particles and masses, one Bullet link
// per spring given, with the rest length given (Drape's fabric's, not the distance at
// creation), the same pinned particles moved kinematically to follow the body every frame,
// and the same ellipsoids as kinematic rigid bodies (a one-sphere btMultiSphereShape with
// local scaling is an ellipsoid). Bullet adds no link of its own (no bending links unless
// they are among the springs given).
//
// Bullet headers stay inside bullet_cloth.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"

namespace drape::bench {

/// A particle grid both engines simulate.
struct ClothSpec {
    Matrix3X x;                                          ///< Initial positions, m.
    std::vector<std::array<std::uint32_t, 2>> springs;   ///< One Bullet link each.
    std::vector<Real> rest_m;                             ///< Per spring; empty: the distance at creation.
    std::vector<std::uint32_t> pinned;                    ///< Particles that follow the body.
    Real mass_kg = 0.002f;                                ///< Per particle, unless `masses_kg` is given.
    std::vector<Real> masses_kg;                          ///< Per particle (pinned ones ignored); empty: mass_kg.
};

/// Bullet's knobs and the values the benchmark uses (documented in docs/reports/peers.md).
struct BulletTuning {
    int substeps = 4;              ///< Internal fixed steps per 1/60 s frame.
    int position_iterations = 8;   ///< piterations (Bullet's default: 1).
    int drift_iterations = 0;      ///< diterations.
    float damping = 0.05f;         ///< kDP (default 0).
    float link_stiffness = 1.0f;   ///< Material kLST (default 1).
    float rigid_hardness = 1.0f;   ///< kCHR (default 1).
    float kinetic_hardness = 1.0f; ///< kKHR (default 0.1): contacts with kinematic bodies.
    float friction = 0.2f;         ///< kDF (default 0.2).
    float margin_m = 0.01f;        ///< Soft body collision margin (default 0.25 * SDF cell).
    float sdf_voxel_m = 0.05f;     ///< Sparse SDF cell (default 0.25 m: coarser than a hip).
};

/// What Bullet's last frame did, measured outside its solver.
struct BulletFrame {
    double penetration_before_m = 0;  ///< Deepest free node inside an ellipsoid after Bullet's prediction,
                                      ///< before its contact and link solve, over the frame's internal steps.
    double probe_ms = 0;              ///< Time spent measuring that (inside the step; subtract it).
};

/// Bullet's soft-body world holding one cloth and its ellipsoids.
class BulletCloth {
public:
    /// `ellipsoids`: unit sphere -> world of each ellipsoid at the start.
    [[nodiscard]] static Result<BulletCloth> create(const ClothSpec& cloth, const std::vector<Affine3>& ellipsoids,
                                                    const BulletTuning& tuning);
    BulletCloth(BulletCloth&&) noexcept;
    BulletCloth& operator=(BulletCloth&&) noexcept;
    ~BulletCloth();

    /// One frame of `frame_dt_s`: ellipsoids move to their new poses (kinematic bodies), pinned
    /// particles move to `pinned_x` (3 x pinned count, the order of ClothSpec::pinned).
    void step(const Matrix3X& pinned_x, const std::vector<Affine3>& ellipsoids, double frame_dt_s);

    /// Current particle positions (3 x particle count).
    [[nodiscard]] Matrix3X positions() const;

    /// The last step's measurements.
    [[nodiscard]] BulletFrame last_frame() const;

    /// Rest length of each link as Bullet holds it now, in the order of ClothSpec::springs.
    [[nodiscard]] std::vector<Real> link_rest_lengths() const;

private:
    struct Impl;
    explicit BulletCloth(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

/// Deepest penetration of any point into any ellipsoid, m: a point p inside the unit sphere
/// after mapping into ellipsoid space (|q| < 1, q = world^-1 p) is |p - c| (1/|q| - 1) deep,
/// measured along the line from the centre, as Drape's response moves it (method §5).
/// Particles listed in `skip` (sorted; e.g. the pinned ones, which sit on the skin and may
/// lie inside a fitted ellipsoid) are not tested.
[[nodiscard]] double max_penetration_m(const Matrix3X& x, const std::vector<Affine3>& ellipsoids,
                                       const std::vector<std::uint32_t>& skip = {});

/// Largest spring strain, length / rest - 1 (0 when no spring is stretched).
[[nodiscard]] double max_strain(const Matrix3X& x, const std::vector<std::array<std::uint32_t, 2>>& springs,
                                const std::vector<Real>& rest_m);

/// Rest lengths of springs from positions.
[[nodiscard]] std::vector<Real> rest_lengths(const Matrix3X& x, const std::vector<std::array<std::uint32_t, 2>>& springs);

/// One Bullet configuration's figures over a run, as the selection rule reads them.
struct BulletCandidate {
    bool usable = false;              ///< Ran to the end without blowing up or crashing.
    double ms_per_frame = 0;
    double strain_p99 = 0;            ///< After the frame, over the run.
    double penetration_after_m = 0;   ///< Deepest after any frame.
};

/// What a Bullet configuration must reach to qualify (Bullet's own figures only).
struct BulletSelectionRule {
    double strain_p99_max = 0.10;
    double penetration_after_max_m = 0.002;
};

struct BulletSelection {
    int index = -1;          ///< The chosen candidate; -1 when none is usable.
    bool qualified = false;  ///< It meets the rule (else: the least strain p99 of the usable ones).
};

/// The cheapest usable candidate that meets the rule; when none does, the usable one with the
/// least strain p99 (the cheaper on a tie).
[[nodiscard]] BulletSelection select_bullet_configuration(const std::vector<BulletCandidate>& candidates,
                                                          const BulletSelectionRule& rule);

}  // namespace drape::bench
