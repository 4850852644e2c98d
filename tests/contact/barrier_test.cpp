#include "engine/contact/barrier.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"
#include "engine/core/psd_projection.hpp"
#include "support/derivative_check.hpp"
#include "support/random_geometry.hpp"

namespace psq {
namespace {

using Eigen::VectorXd;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

TEST(Barrier, VanishesFromTheActivationOnAndIsInfiniteAtContact) {
  const double s_hat = 1e-4;
  for (double s : {s_hat, 1.5 * s_hat, 100 * s_hat}) {
    EXPECT_EQ(barrier(s, s_hat), 0);
    EXPECT_EQ(barrier_first_derivative(s, s_hat), 0);
    EXPECT_EQ(barrier_second_derivative(s, s_hat), 0);
  }
  for (double s : {0.0, -1e-12, -s_hat}) {
    EXPECT_EQ(barrier(s, s_hat), kInfinity);
    EXPECT_EQ(barrier_first_derivative(s, s_hat), -kInfinity);
    EXPECT_EQ(barrier_second_derivative(s, s_hat), kInfinity);
  }
}

TEST(Barrier, HasTheValueOfItsFormula) {
  // At s = ŝ/e the logarithm is −1: b = ŝ² (1 − 1/e)².
  const double s_hat = 0.3;
  EXPECT_NEAR(barrier(s_hat / M_E, s_hat), s_hat * s_hat * std::pow(1 - 1 / M_E, 2), 1e-15);
}

TEST(Barrier, IsPositiveDecreasingAndConvexInsideTheBand) {
  const double s_hat = 2e-6;
  double previous = kInfinity;
  for (int i = 1; i < 1000; ++i) {
    const double s = s_hat * i / 1000;
    const double b = barrier(s, s_hat);
    EXPECT_GT(b, 0);
    EXPECT_LT(b, previous);
    EXPECT_LT(barrier_first_derivative(s, s_hat), 0);
    EXPECT_GT(barrier_second_derivative(s, s_hat), 0);
    previous = b;
  }
  // … and grows without bound toward contact.
  EXPECT_GT(barrier(1e-20 * s_hat, s_hat), 40 * s_hat * s_hat);
}

TEST(Barrier, IsTwiceContinuouslyDifferentiableAtTheActivation) {
  // Below ŝ by a fraction ε: b ≈ ŝ² ε³, b′ ≈ −3 ŝ ε², b″ ≈ 6 ε (Taylor expansion of the
  // formula in ε), all tending to the zero values beyond ŝ.
  const double s_hat = 3e-6;
  for (double eps : {1e-2, 1e-3, 1e-4}) {
    const double s = s_hat * (1 - eps);
    EXPECT_NEAR(barrier(s, s_hat), s_hat * s_hat * std::pow(eps, 3),
                2 * eps * s_hat * s_hat * std::pow(eps, 3));
    EXPECT_NEAR(barrier_first_derivative(s, s_hat), -3 * s_hat * eps * eps,
                2 * eps * 3 * s_hat * eps * eps);
    EXPECT_NEAR(barrier_second_derivative(s, s_hat), 6 * eps, 2 * eps * 6 * eps);
  }
}

TEST(Barrier, DerivativesMatchFiniteDifferences) {
  const double s_hat = 1e-4;
  for (double fraction : {1e-4, 0.01, 0.3, 0.9}) {
    const double s = fraction * s_hat, h = 1e-6 * s;
    const double fd1 = (barrier(s + h, s_hat) - barrier(s - h, s_hat)) / (2 * h);
    const double fd2 =
        (barrier_first_derivative(s + h, s_hat) - barrier_first_derivative(s - h, s_hat)) / (2 * h);
    EXPECT_NEAR(barrier_first_derivative(s, s_hat), fd1, 1e-6 * std::abs(fd1));
    EXPECT_NEAR(barrier_second_derivative(s, s_hat), fd2, 1e-6 * std::abs(fd2));
  }
}

TEST(BarrierBand, OffsetsTheSquaredDistanceByTheThickness) {
  const BarrierBand band{0.1, 0.02};
  // ŝ = (ξ + d̂)² − ξ² = 0.0144 − 0.0004.
  EXPECT_DOUBLE_EQ(band.barrier_activation(), 0.014);
  const auto contact = [&](double unsigned_distance) {
    const double d = unsigned_distance * unsigned_distance;
    return barrier(band.barrier_argument(d), band.barrier_activation());
  };
  EXPECT_NEAR(contact(0.12), 0, 1e-40);  // at ξ + d̂ (up to rounding): the band's outer edge
  EXPECT_EQ(contact(0.12 + 1e-12), 0);   // beyond it
  EXPECT_GT(contact(0.12 - 1e-6), 0);    // just inside
  EXPECT_EQ(contact(0.02), kInfinity);   // at the thickness
  EXPECT_EQ(contact(0.019), kInfinity);  // within it
  EXPECT_GT(contact(0.02 + 1e-9), contact(0.02 + 1e-6));
  // Without thickness it is plain IPC: s = d, ŝ = d̂².
  const BarrierBand plain{0.1, 0};
  EXPECT_DOUBLE_EQ(plain.barrier_activation(), 0.01);
  EXPECT_EQ(plain.barrier_argument(0.004), 0.004);
}

/// b(d(x)) with its derivatives, for the stencil distance `distance`, on flat 12-vectors.
using StencilDistance = std::function<StencilDerivatives<12>(const VectorXd&)>;

void expect_composite_matches_finite_differences(const StencilDistance& distance, const VectorXd& x,
                                                 const BarrierBand& band) {
  const auto composite = [&](const VectorXd& y) { return barrier_of_distance(distance(y), band); };
  ASSERT_GT(composite(x).value, 0);
  const test::DerivativeErrors errors = test::derivative_errors(composite, x, 1e-6);
  EXPECT_LT(errors.gradient, 1e-6);
  EXPECT_LT(errors.hessian, 1e-6);
}

TEST(BarrierOfDistance, MatchesFiniteDifferencesOnRandomPointTriangleAndEdgeEdgePairs) {
  const StencilDistance point_triangle = [](const VectorXd& x) {
    return point_triangle_distance_derivatives(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6),
                                               x.segment<3>(9));
  };
  const StencilDistance edge_edge = [](const VectorXd& x) {
    return edge_edge_distance_derivatives(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6),
                                          x.segment<3>(9));
  };
  std::mt19937 rng(31);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd x = test::random_stencil(rng).reshaped();
    for (const StencilDistance& distance : {point_triangle, edge_edge}) {
      // A band around the pair's distance: thickness 0.3 of it, reach twice it.
      const double gap = std::sqrt(distance(x).value);
      expect_composite_matches_finite_differences(distance, x, {2 * gap, 0.3 * gap});
    }
  }
}

TEST(BarrierOfDistance, RefusesAStateWithinTheThickness) {
  StencilDerivatives<12> distance;
  distance.value = 1e-6;
  EXPECT_THROW(barrier_of_distance(distance, {1e-2, 1e-3}), NumericalError);
  EXPECT_NO_THROW(barrier_of_distance(distance, {1e-2, 0.9e-3}));
}

TEST(BarrierStiffness, InitialBoundsFollowTheInertiaScale) {
  // l = 1, d̂ = 1e-3, m̄ = 2: the probe gap is 1e-8, d₀ = 1e-16, ŝ = 1e-6, and
  // b″(d₀) = 1e20 + 2e10 + 2 ln(1e10) − 3, so κ_min = 1e11 · 2 / (4e-16 b″) ≈ 5e6.
  const BarrierBand band{1e-3, 0};
  const VectorXd zero = VectorXd::Zero(3);
  const BarrierStiffness k = initial_barrier_stiffness(1, band, 2, zero, zero);
  EXPECT_NEAR(k.value, 5e6, 5e6 * 1e-9);  // no active pair: κ_min
  EXPECT_NEAR(k.max, 100 * k.value, 1e-6);
  // Heavier vertices need a stiffer barrier, in proportion.
  EXPECT_NEAR(initial_barrier_stiffness(1, band, 6, zero, zero).value, 3 * k.value, 1e-6);
}

TEST(BarrierStiffness, InitialValueBalancesTheGradientsWithinItsBounds) {
  const BarrierBand band{1e-3, 0};
  const double k_min = 5e6, k_max = 5e8;  // see InitialBoundsFollowTheInertiaScale
  const VectorXd barrier_gradient = Eigen::Vector3d(1, -2, 0.5);
  std::mt19937 rng(32);
  std::normal_distribution<> normal;
  // Energy gradients that the barrier must balance with κ = 1e7: κ∇B + ∇E ⟂ ∇B.
  const VectorXd energy_gradient =
      -1e7 * barrier_gradient + Eigen::Vector3d(2, 1, 0) * normal(rng);  // (2,1,0) ⟂ ∇B
  const BarrierStiffness k =
      initial_barrier_stiffness(1, band, 2, energy_gradient, barrier_gradient);
  EXPECT_NEAR(k.value, 1e7, 1e-3);
  EXPECT_NEAR((energy_gradient + k.value * barrier_gradient).dot(barrier_gradient), 0, 1e-3);
  // Out of bounds: clamped.
  EXPECT_NEAR(
      initial_barrier_stiffness(1, band, 2, -1e10 * barrier_gradient, barrier_gradient).value,
      k_max, k_max * 1e-9);
  EXPECT_NEAR(initial_barrier_stiffness(1, band, 2, 3 * barrier_gradient, barrier_gradient).value,
              k_min, k_min * 1e-9);
}

TEST(BarrierStiffness, InitialValueStaysFiniteForActivationDistancesBelowTheProbeGap) {
  const VectorXd zero = VectorXd::Zero(3);
  for (double thickness : {0.0, 1e-3}) {
    const BarrierStiffness k = initial_barrier_stiffness(1, {1e-9, thickness}, 1, zero, zero);
    EXPECT_TRUE(std::isfinite(k.value) && k.value > 0) << "ξ = " << thickness;
  }
}

TEST(BarrierStiffness, RefusesNonPositiveScales) {
  const VectorXd zero = VectorXd::Zero(3);
  EXPECT_THROW(initial_barrier_stiffness(0, {1e-3, 0}, 1, zero, zero), NumericalError);
  EXPECT_THROW(initial_barrier_stiffness(1, {0, 0}, 1, zero, zero), NumericalError);
  EXPECT_THROW(initial_barrier_stiffness(1, {1e-3, 0}, -1, zero, zero), NumericalError);
}

TEST(BarrierStiffness, DoublesOnlyWhileTheMinimumGapKeepsShrinkingBelowTheTolerance) {
  // l = 2: the gap tolerance is 2e-9. The CCD did not cut the steps: IPC's rule alone.
  const BarrierStiffness k{1e6, 1e8};
  const auto update = [&](double previous_gap, double gap, double thickness = 0) {
    const BarrierBand band{1e-3, thickness};
    return update_barrier_stiffness(k, std::pow(thickness + previous_gap, 2),
                                    std::pow(thickness + gap, 2), 2, band)
        .value;
  };
  EXPECT_EQ(update(1.5e-9, 1e-9), 2e6);        // below the tolerance and shrinking
  EXPECT_EQ(update(1e-9, 1e-9), 1e6);          // not shrinking
  EXPECT_EQ(update(1e-9, 1.5e-9), 1e6);        // growing
  EXPECT_EQ(update(3e-9, 1e-9), 1e6);          // was above the tolerance
  EXPECT_EQ(update(1e-8, 5e-9), 1e6);          // above the tolerance
  EXPECT_EQ(update(1.5e-9, 1e-9, 1e-3), 2e6);  // gaps measured from the thickness
  EXPECT_EQ(update(3e-9, 1e-9, 1e-3), 1e6);
  // No pair in reach: nothing to push apart.
  EXPECT_EQ(update_barrier_stiffness(k, kInfinity, kInfinity, 2, {1e-3, 0}).value, 1e6);
  // Never beyond κ_max.
  EXPECT_EQ(update_barrier_stiffness({0.7e8, 1e8}, 1e-18, 0.5e-18, 2, {1e-3, 0}).value, 1e8);
}

/// |∂b/∂g| across a gap g for ŝ = d̂² (ξ = 0), from IPC's b(s) = −(s − ŝ)² ln(s/ŝ) with s = g²,
/// differentiated by hand: ∂b/∂s = −2 (s − ŝ) ln(s/ŝ) − (s − ŝ)²/s.
double push_across(double gap, double activation) {
  const double s = gap * gap;
  const double s_hat = activation * activation;
  return 2 * gap * std::abs(-2 * (s - s_hat) * std::log(s / s_hat) - (s - s_hat) * (s - s_hat) / s);
}

TEST(BarrierStiffness, CatchesUpWithTheForceWhereTheCcdCutsStepsAtAStalledGap) {
  // l = 2: the gap tolerance is 2e-9; d̂ = 1e-3.
  const BarrierStiffness k{1e6, 1e15};
  const double tolerance = 2e-9;
  const auto cut = [&](double previous_gap, double gap) {
    return update_barrier_stiffness(k, previous_gap * previous_gap, gap * gap, 2, {1e-3, 0},
                                    1e-9, true)
        .value;
  };
  const auto held_at_tolerance = [&](double gap) {
    return 1e6 * push_across(gap, 1e-3) / push_across(tolerance, 1e-3);
  };
  // Stuck far below the tolerance (the crushed can's 1e-10 m gaps): one update catches up,
  // by about the gap ratio 2e-9 / 1e-12.
  EXPECT_NEAR(cut(1e-12, 1e-12), held_at_tolerance(1e-12), 1e-9 * held_at_tolerance(1e-12));
  EXPECT_GT(cut(1e-12, 1e-12), 1e3 * 1e6);
  // Stalled while creeping up slowly: the push ratio alone (about 4/3), no doubling.
  EXPECT_NEAR(cut(1e-9, 1.5e-9), held_at_tolerance(1.5e-9), 1e-9 * 1e6);
  EXPECT_LT(cut(1e-9, 1.5e-9), 1.5e6);
  // Stalled and shrinking a little: at least IPC's doubling.
  EXPECT_NEAR(cut(1.2e-9, 1e-9), std::max(2e6, held_at_tolerance(1e-9)), 1e-9 * 2e6);
  // Falling fast (a transient of the iteration, not a held contact): IPC's doubling only.
  EXPECT_EQ(cut(1.5e-9, 1e-12), 2e6);
  // Recovering (the gap at least doubled): unchanged.
  EXPECT_EQ(cut(0.5e-9, 1e-9), 1e6);
  // Just fell below the tolerance: nothing is stalled yet.
  EXPECT_EQ(cut(3e-9, 1e-9), 1e6);
  // At or above the tolerance: unchanged.
  EXPECT_EQ(cut(1e-8, tolerance), 1e6);
  // Never beyond κ_max.
  EXPECT_EQ(update_barrier_stiffness({1e6, 1e7}, 1e-24, 1e-24, 2, {1e-3, 0}, 1e-9, true).value,
            1e7);
}

TEST(Barrier, PairHessiansProjectInTheirRelativeMotionsLikeTheFullEigensolver) {
  // Point-triangle pairs in the triangle's interior, edge and vertex regions (12, 9 and 6
  // coordinates the distance depends on) and a crossing edge-edge pair, all within the band.
  const BarrierBand band{0.5, 0};
  const Eigen::Vector3d t0(0, 0, 0), t1(1, 0, 0), t2(0, 1, 0);
  std::vector<StencilDerivatives<12>> pairs;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.2, 0.3, 0.2), Eigen::Vector3d(0.5, -0.2, 0.2),
                                  Eigen::Vector3d(-0.2, -0.1, 0.2)})
    pairs.push_back(barrier_of_distance(point_triangle_distance_derivatives(p, t0, t1, t2), band));
  pairs.push_back(barrier_of_distance(
      edge_edge_distance_derivatives(t0, t1, Eigen::Vector3d(0.4, -0.5, 0.25),
                                     Eigen::Vector3d(0.6, 0.5, 0.3)),
      band));
  for (const StencilDerivatives<12>& pair : pairs) {
    Eigen::Matrix<double, 12, 12> reduced = pair.hessian;
    Eigen::MatrixXd full = pair.hessian;
    project_translation_invariant_to_psd(reduced);
    project_to_psd(full);
    EXPECT_LT((reduced - full).norm(), 1e-12 * full.norm());
  }
}

}  // namespace
}  // namespace psq
