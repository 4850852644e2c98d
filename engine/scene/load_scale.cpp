#include "engine/scene/load_scale.hpp"

#include <algorithm>

namespace psq {

double load_scale_at(const LoadScale& scale, double time) {
  const auto& keys = scale.keyframes;
  // The first keyframe later than `time`: the end of the segment `time` lies in.
  const auto after = std::upper_bound(keys.begin(), keys.end(), time,
                                      [](double t, const auto& key) { return t < key.first; });
  if (after == keys.begin()) return keys.front().second;
  if (after == keys.end()) return keys.back().second;
  const auto& [t0, s0] = *(after - 1);
  const auto& [t1, s1] = *after;
  return s0 + (s1 - s0) * (time - t0) / (t1 - t0);
}

}  // namespace psq
