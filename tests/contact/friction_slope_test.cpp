// A point resting on a fixed slope under gravity, stepped quasistatically with the IPC
// barrier and lagged friction by a small Newton loop of its own: it must stick when
// μ > tan α (creeping only by the mollifier's slip, less than ε per step) and slide when
// μ < tan α, by the Coulomb amount per step.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "engine/contact/barrier.hpp"
#include "engine/contact/friction.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/psd_projection.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;

constexpr double kMass = 1;         // kg
constexpr double kGravity = 9.81;   // m/s²
constexpr double kTimeStep = 0.1;   // s
constexpr double kSlip = 1e-4;      // ε = ε_v Δt (m)
constexpr double kStiffness = 1e9;  // κ
const BarrierBand kBand{1e-3, 0};

class Slope {
 public:
  Slope(double angle, double friction)
      : friction_(friction),
        uphill_(0, std::cos(angle), std::sin(angle)),
        normal_(0, -std::sin(angle), std::cos(angle)) {
    const Vector3d across = Vector3d::UnitX();
    corners_ << -10 * across - 10 * uphill_, 10 * across - 10 * uphill_, 10 * uphill_;
  }

  [[nodiscard]] const Vector3d& uphill() const { return uphill_; }
  [[nodiscard]] const Vector3d& normal() const { return normal_; }

  /// One quasistatic step from `start`, with `outer` friction lagging iterations.
  [[nodiscard]] Vector3d step(const Vector3d& start, int outer = 4) const {
    Vector3d p = start;
    for (int k = 0; k < outer; ++k) {
      const Eigen::VectorXd lagged_state = stencil(p).reshaped();
      const LaggedFrictionContact contact = lag_friction_contact(
          ContactKind::PointTriangle, {0, 1, 2, 3}, lagged_state, kBand, kStiffness, friction_);
      p = minimize(start, p, contact);
    }
    return p;
  }

 private:
  [[nodiscard]] StencilPositions stencil(const Vector3d& p) const {
    StencilPositions x;
    x << p, corners_;
    return x;
  }

  /// E(p) = m/(2Δt²)‖p − pᵗ‖² + m g z + κ b(d(p)) + D(p), with its gradient and a PSD Hessian.
  [[nodiscard]] StencilDerivatives<3> energy(const Vector3d& start, const Vector3d& p,
                                             const LaggedFrictionContact& contact) const {
    const StencilPositions x = stencil(p);
    StencilPositions motion = StencilPositions::Zero();
    motion.col(0) = p - start;
    const StencilDerivatives<12> barrier = barrier_of_distance(
        point_triangle_distance_derivatives(x.col(0), x.col(1), x.col(2), x.col(3)), kBand);
    const StencilDerivatives<12> friction =
        friction_dissipation_derivatives(contact, motion, kSlip);
    const double inertia = kMass / (kTimeStep * kTimeStep);
    StencilDerivatives<3> e;
    e.value = 0.5 * inertia * (p - start).squaredNorm() + kMass * kGravity * p.z() +
              kStiffness * barrier.value + friction.value;
    e.gradient = inertia * (p - start) + kMass * kGravity * Vector3d::UnitZ() +
                 kStiffness * barrier.gradient.head<3>() + friction.gradient.head<3>();
    Eigen::MatrixXd contact_block = kStiffness * barrier.hessian.topLeftCorner<3, 3>();
    project_to_psd(contact_block);
    e.hessian = inertia * Eigen::Matrix3d::Identity() + contact_block +
                friction.hessian.topLeftCorner<3, 3>();
    return e;
  }

  /// Newton with a step bounded to keep the point above the plane and backtracking.
  [[nodiscard]] Vector3d minimize(const Vector3d& start, Vector3d p,
                                  const LaggedFrictionContact& contact) const {
    for (int iteration = 0; iteration < 100; ++iteration) {
      const StencilDerivatives<3> e = energy(start, p, contact);
      const Vector3d dp = -e.hessian.ldlt().solve(e.gradient);
      if (dp.lpNorm<Eigen::Infinity>() < 1e-13) break;
      double alpha = 1;
      const double approach = -normal_.dot(dp);
      const double height = normal_.dot(p - corners_.col(0));
      if (approach > 0) alpha = std::min(1.0, 0.9 * height / approach);
      while (energy(start, p + alpha * dp, contact).value > e.value && alpha > 1e-12) alpha /= 2;
      p += alpha * dp;
    }
    return p;
  }

  double friction_;
  Vector3d uphill_, normal_;
  Eigen::Matrix3d corners_;
};

constexpr double kAngle = M_PI / 6;  // tan α ≈ 0.577
constexpr int kSteps = 8;

/// Downhill distance travelled in each of kSteps steps from a point resting at the origin.
std::vector<double> downhill_steps(const Slope& slope) {
  Vector3d p = 3e-4 * slope.normal();
  p = slope.step(p);  // settle onto the barrier's equilibrium gap first
  std::vector<double> steps;
  for (int s = 0; s < kSteps; ++s) {
    const Vector3d next = slope.step(p);
    steps.push_back(-(next - p).dot(slope.uphill()));
    p = next;
  }
  return steps;
}

TEST(FrictionSlope, SlidesByTheCoulombAmountWhenFrictionIsBelowTheSlope) {
  const double mu = 0.3;
  // Sliding: the inertia-like spring m/Δt² balances m g (sin α − μ cos α) along the slope.
  const double expected =
      kTimeStep * kTimeStep * kGravity * (std::sin(kAngle) - mu * std::cos(kAngle));
  for (double step : downhill_steps(Slope(kAngle, mu)))
    EXPECT_NEAR(step, expected, 1e-3 * expected);
}

TEST(FrictionSlope, SticksWhenFrictionExceedsTheSlope) {
  const double mu = 0.8;
  // Sticking: μλ f₁(y) = m g sin α with λ = m g cos α gives f₁(y) = tan α/μ, a creep of
  // y = ε (1 − √(1 − tan α/μ)) per step (the inertia-like spring adds 0.1%).
  const double creep = kSlip * (1 - std::sqrt(1 - std::tan(kAngle) / mu));
  for (double step : downhill_steps(Slope(kAngle, mu))) {
    EXPECT_GT(step, 0);
    EXPECT_LT(step, kSlip);
    EXPECT_NEAR(step, creep, 1e-2 * creep);
  }
}

}  // namespace
}  // namespace psq
