// Where an entity stands in the world.
#pragma once

#include "drape/engine/core/math.hpp"

namespace drape {

/// World placement of a character (its model space -> world). Root motion moves it.
struct Transform {
    Vec3 position = Vec3::Zero();          ///< m
    Quat rotation = Quat::Identity();
    Real scale = 1;                         ///< Uniform.

    [[nodiscard]] Affine3 matrix() const {
        Affine3 m = Affine3::Identity();
        m.translate(position);
        m.rotate(rotation);
        m.scale(scale);
        return m;
    }
};

}  // namespace drape
