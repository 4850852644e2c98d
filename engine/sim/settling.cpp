#include "engine/sim/settling.hpp"

#include <algorithm>
#include <cmath>

namespace psq {

double settling_time_step(double time_step, int growth) {
  return time_step * std::pow(4.0, std::min(growth, kSettlingGrowthSteps));
}

bool settling_done(int growth, double change, double tolerance) {
  return growth >= kSettlingGrowthSteps && change < tolerance;
}

int next_settling_growth(int growth, bool converged_at_start) {
  return converged_at_start ? std::max(growth + 1, kSettlingGrowthSteps) : growth + 1;
}

}  // namespace psq
