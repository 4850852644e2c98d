#include "engine/scene/rigid_motion.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <numbers>

namespace psq {

Eigen::Vector3d apply_motions(const std::vector<RigidMotion>& motions, const Eigen::Vector3d& rest,
                              double time) {
  Eigen::Vector3d p = rest;
  for (const RigidMotion& m : motions) {
    const double span = m.end_time - m.start_time;
    const double s = span > 0 ? std::clamp((time - m.start_time) / span, 0.0, 1.0)
                              : (time >= m.end_time ? 1.0 : 0.0);
    const double angle = s * m.angle_degrees * std::numbers::pi / 180.0;
    const Eigen::AngleAxisd rotation(angle, m.axis_direction.normalized());
    p = m.axis_point + rotation * (p - m.axis_point) + s * m.translation;
  }
  return p;
}

}  // namespace psq
