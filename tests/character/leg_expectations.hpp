// The legs of a fitted body (systems/character/ellipsoid_fit.hpp, LegFit): each thigh and
// each shin bone carries one fitted ellipsoid (no thin pieces overlapping in creases), and
// with tight legs each shin bone also a sphere centred on its joint, the knee sphere; the
// fitted pieces keep to the budget (grown by tight_extra_ellipsoids with tight legs), the
// knee spheres come on top.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>

#include "drape/systems/character/character_body.hpp"

namespace drape::test {

inline bool is_knee_sphere(const EllipsoidShape& e) {
    return e.region == BodyRegion::lower_leg && e.center.norm() < 1e-6f && e.radii_m.x() == e.radii_m.y() &&
           e.radii_m.y() == e.radii_m.z();
}

// The fitted pieces a body may have: the budget, grown with tight legs.
inline std::size_t fitted_budget(const CharacterBody& body, const FitOptions& options) {
    return static_cast<std::size_t>(options.max_ellipsoids + (body.legs == LegFit::tight ? options.tight_extra_ellipsoids : 0));
}

inline void expect_legs(const CharacterBody& body, const FitOptions& options) {
    const auto count = [&](auto&& pred) { return std::count_if(body.ellipsoids.begin(), body.ellipsoids.end(), pred); };
    const auto knees = count(is_knee_sphere);
    EXPECT_NE(body.legs, LegFit::automatic);  // the fit used is reported
    EXPECT_EQ(knees, body.legs == LegFit::tight && options.knee_radius_share > 0 ? 2 : 0);
    EXPECT_EQ(count([](const EllipsoidShape& e) { return e.region == BodyRegion::upper_leg; }), 2);
    EXPECT_EQ(count([](const EllipsoidShape& e) { return e.region == BodyRegion::lower_leg && !is_knee_sphere(e); }), 2);
    for (const EllipsoidShape& knee : body.ellipsoids) {
        if (!is_knee_sphere(knee)) continue;
        EXPECT_TRUE(std::any_of(body.ellipsoids.begin(), body.ellipsoids.end(), [&](const EllipsoidShape& shin) {
            return shin.bone == knee.bone && !is_knee_sphere(shin);
        })) << "a knee sphere sits on a shin bone";
    }
    EXPECT_LE(body.ellipsoids.size() - static_cast<std::size_t>(knees), fitted_budget(body, options));
}

}  // namespace drape::test
