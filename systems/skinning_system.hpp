// The skinning system (phase skinning, method §1.2): linear blend skinning of every
// character's mesh into world space (its Transform applied), on structure-of-arrays Eigen
// data, in parallel over vertex blocks for big meshes.
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

[[nodiscard]] System make_skinning_system();

}  // namespace drape
