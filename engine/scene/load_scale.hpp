#pragma once
// The load scale s(t) of a scene's [load_scale] table (scene.hpp, LoadScale).

#include "engine/scene/scene.hpp"

namespace psq {

/// s(t): s_0 before the first keyframe, the last s_i from the last keyframe's time on, linear in
/// between. Keyframes at one time make a jump: from that time on, s is the later one's.
double load_scale_at(const LoadScale& scale, double time);

}  // namespace psq
