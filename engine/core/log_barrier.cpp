#include "engine/core/log_barrier.hpp"

#include <cmath>
#include <limits>

namespace psq {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

double barrier(double s, double s_hat) {
  if (s <= 0) return kInfinity;
  if (s >= s_hat) return 0;
  return -(s - s_hat) * (s - s_hat) * std::log(s / s_hat);
}

double barrier_first_derivative(double s, double s_hat) {
  if (s <= 0) return -kInfinity;
  if (s >= s_hat) return 0;
  return (s_hat - s) * (2 * std::log(s / s_hat) - s_hat / s + 1);
}

double barrier_second_derivative(double s, double s_hat) {
  if (s <= 0) return kInfinity;
  if (s >= s_hat) return 0;
  const double r = s_hat / s;
  return -2 * std::log(s / s_hat) + r * (r + 2) - 3;
}

}  // namespace psq
