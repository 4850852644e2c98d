#pragma once
#include "engine/scene/scene.hpp"

namespace psq {

/// Where a pinned point at rest position `rest` is at time t under its motions (in order).
Eigen::Vector3d apply_motions(const std::vector<RigidMotion>& motions, const Eigen::Vector3d& rest,
                              double time);

}  // namespace psq
