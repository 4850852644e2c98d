#include "engine/contact/friction.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "engine/contact/distance_type.hpp"
#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/contact/tangent_basis.hpp"
#include "engine/core/error.hpp"
#include "support/derivative_check.hpp"
#include "support/finite_difference.hpp"
#include "support/random_geometry.hpp"

namespace psq {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;
using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

/// A 4-vertex contact stencil in a known closest-feature sub-case.
struct Stencil {
  std::string name;
  ContactKind kind;
  StencilPositions x;
  std::optional<int> expected_case;  ///< none for parallel edges (any boundary case will do)
};

/// Every sub-case of both stencil kinds, about 0.01 apart, turned out of the coordinate
/// planes so no coordinate is special.
std::vector<Stencil> contact_stencils() {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Vector3d(1, 2, 3).normalized()).matrix();
  const Vector3d t0(0, 0, 0), t1(1, 0, 0), t2(0, 1, 0);
  const auto pt = [&](std::string name, Vector3d p, PointTriangleCase c) {
    return Stencil{std::move(name), ContactKind::PointTriangle, turn * stack_stencil(p, t0, t1, t2),
                   static_cast<int>(c)};
  };
  const auto ee = [&](std::string name, Vector3d b0, Vector3d b1, std::optional<int> c) {
    return Stencil{std::move(name), ContactKind::EdgeEdge, turn * stack_stencil(t0, t1, b0, b1), c};
  };
  using P = PointTriangleCase;
  using E = EdgeEdgeCase;
  const auto e = [](E c) { return std::optional<int>(static_cast<int>(c)); };
  return {pt("point-face", {0.2, 0.3, 0.01}, P::Face),
          pt("point-edge01", {0.5, -0.01, 0.008}, P::Edge01),
          pt("point-edge12", {0.51, 0.51, 0.007}, P::Edge12),
          pt("point-edge20", {-0.009, 0.5, 0.006}, P::Edge20),
          pt("point-vertex0", {-0.006, -0.005, 0.007}, P::Vertex0),
          pt("point-vertex1", {1.008, -0.004, 0.005}, P::Vertex1),
          pt("point-vertex2", {-0.004, 1.006, 0.008}, P::Vertex2),
          ee("line-line", {0.5, -0.5, 0.01}, {0.4, 0.5, 0.012}, e(E::LineLine)),
          ee("a0-edge-b", {-0.008, -0.5, 0.006}, {-0.008, 0.5, 0.006}, e(E::A0EdgeB)),
          ee("a1-edge-b", {1.007, -0.5, 0.008}, {1.007, 0.5, 0.008}, e(E::A1EdgeB)),
          ee("b0-edge-a", {0.5, 0.006, 0.008}, {0.5, 1, 0.01}, e(E::B0EdgeA)),
          ee("b1-edge-a", {0.5, 1, 0.01}, {0.3, 0.007, 0.006}, e(E::B1EdgeA)),
          ee("a0-b0", {-0.006, -0.007, 0.005}, {-0.5, -1, 0.01}, e(E::A0B0)),
          ee("a1-b1", {1.5, 1, 0.01}, {1.006, 0.005, 0.007}, e(E::A1B1)),
          ee("parallel", {0.3, 0.008, 0.006}, {1.4, 0.008, 0.006}, std::nullopt)};
}

int case_at(const Stencil& s) {
  const StencilPositions& x = s.x;
  return s.kind == ContactKind::PointTriangle
             ? static_cast<int>(point_triangle_case(x.col(0), x.col(1), x.col(2), x.col(3)))
             : static_cast<int>(edge_edge_case(x.col(0), x.col(1), x.col(2), x.col(3)));
}

double distance_at(const Stencil& s) {
  const StencilPositions& x = s.x;
  return s.kind == ContactKind::PointTriangle
             ? point_triangle_distance(x.col(0), x.col(1), x.col(2), x.col(3))
             : edge_edge_distance(x.col(0), x.col(1), x.col(2), x.col(3));
}

VectorXd flatten(const StencilPositions& x) { return x.reshaped(); }

const BarrierBand kBand{0.02, 0};
constexpr double kStiffness = 1e4;
constexpr double kFriction = 0.4;
constexpr double kSlip = 1e-4;

TEST(TangentBasis, IsOrthonormalAndOrthogonalToTheNormal) {
  std::vector<Vector3d> normals{Vector3d::UnitX(), -Vector3d::UnitY(), 1e-9 * Vector3d::UnitZ(),
                                Vector3d(1, 1, 1), Vector3d(3, -1e-8, 2)};
  for (int i = 0; i < 20; ++i) normals.push_back(Vector3d::Random());
  for (const Vector3d& n : normals) {
    const TangentBasis t = tangent_basis(n);
    EXPECT_LT((t.transpose() * t - Eigen::Matrix2d::Identity()).norm(), 1e-15);
    EXPECT_LT((t.transpose() * n).norm(), 1e-15 * n.norm());
    EXPECT_GT(t.col(0).cross(t.col(1)).dot(n), 0);  // right-handed about the normal
  }
}

TEST(ContactFrame, MatchesTheDistanceCodeInEverySubCase) {
  // The distance code finds the closest pair its own way. Σ wᵢ xᵢ must be the vector between
  // the closest points (its squared length the distance), the plane orthogonal to it, the two
  // sides' weights sum to +1 and −1 (the sub-case's point, whichever side, gets +1), and a
  // common translation of both sides is no relative motion.
  for (const Stencil& s : contact_stencils()) {
    SCOPED_TRACE(s.name);
    if (s.expected_case) {
      ASSERT_EQ(case_at(s), *s.expected_case);
    } else {
      ASSERT_NE(case_at(s), static_cast<int>(EdgeEdgeCase::LineLine));
    }
    const bool point_triangle = s.kind == ContactKind::PointTriangle;
    const ContactFrame frame = point_triangle ? point_triangle_frame(s.x) : edge_edge_frame(s.x);
    const Vector3d q = s.x * frame.weights;
    const double d = distance_at(s);
    EXPECT_NEAR(q.squaredNorm(), d, 1e-12 * d);
    EXPECT_LT((frame.basis.transpose() * q).norm(), 1e-12 * q.norm());
    EXPECT_LT((frame.basis.transpose() * frame.basis - Eigen::Matrix2d::Identity()).norm(), 1e-15);
    EXPECT_NEAR(std::abs(point_triangle ? frame.weights[0] : frame.weights.head<2>().sum()), 1,
                1e-15);
    EXPECT_NEAR(frame.weights.sum(), 0, 1e-15);
    const StencilPositions shifted = s.x.colwise() + Vector3d(0.3, -0.7, 1.1);
    EXPECT_LT((shifted * frame.weights - q).norm(), 1e-14);
  }
}

TEST(ContactFrame, FaceFrameMeasuresSlidingInThePlaneOfTheTriangle) {
  const StencilPositions x = stack_stencil(Vector3d(0.2, 0.3, 0.01), Vector3d(0, 0, 0),
                                           Vector3d(1, 0, 0), Vector3d(0, 1, 0));
  const ContactFrame frame = point_triangle_frame(x);
  // The point slides by (3, −4)·1e-4 in the plane and lifts off by 7e-4: only the slide counts.
  StencilPositions motion = StencilPositions::Zero();
  motion.col(0) = Vector3d(3e-4, -4e-4, 7e-4);
  const Eigen::Vector2d u = tangential_displacement(frame, motion);
  EXPECT_NEAR(u.norm(), 5e-4, 1e-18);
  // Moving the triangle the opposite way is the same relative slide.
  StencilPositions opposite = StencilPositions::Zero();
  opposite.rightCols<3>().colwise() = -motion.col(0);
  EXPECT_LT((tangential_displacement(frame, opposite) - u).norm(), 1e-18);
}

TEST(NormalForce, IsTheBarrierForceOnEitherSide) {
  // Independent route: κ times the barrier's gradient with respect to the point (point–
  // triangle) or summed over the first edge's endpoints (edge–edge).
  for (const Stencil& s : contact_stencils()) {
    SCOPED_TRACE(s.name);
    const StencilPositions& x = s.x;
    const StencilDerivatives<12> distance =
        s.kind == ContactKind::PointTriangle
            ? point_triangle_distance_derivatives(x.col(0), x.col(1), x.col(2), x.col(3))
            : edge_edge_distance_derivatives(x.col(0), x.col(1), x.col(2), x.col(3));
    const Eigen::Matrix<double, 12, 1> gradient =
        kStiffness * barrier_of_distance(distance, kBand).gradient;
    const Vector3d side_force = s.kind == ContactKind::PointTriangle
                                    ? Vector3d(gradient.head<3>())
                                    : Vector3d(gradient.segment<3>(0) + gradient.segment<3>(3));
    const double lambda = normal_force_magnitude(distance.value, kBand, kStiffness);
    EXPECT_GT(lambda, 0);
    EXPECT_NEAR(lambda, side_force.norm(), 1e-10 * lambda);
  }
  EXPECT_EQ(normal_force_magnitude(1.01 * 0.02 * 0.02, kBand, kStiffness), 0);
  EXPECT_NEAR(normal_force_magnitude(1e-6, kBand, kStiffness, 0.25),
              0.25 * normal_force_magnitude(1e-6, kBand, kStiffness), 1e-12);
  EXPECT_THROW(normal_force_magnitude(0, kBand, kStiffness), NumericalError);
}

/// The contact lagged at the stencil's own positions, all four vertices global 0…3.
LaggedFrictionContact lagged(const Stencil& s, double friction = kFriction) {
  return lag_friction_contact(s.kind, {0, 1, 2, 3}, flatten(s.x), kBand, kStiffness, friction);
}

/// A motion of the stencil over the step whose tangential slip is `slip`·ε: a random motion of
/// every vertex, rescaled.
VectorXd motion_with_slip(const LaggedFrictionContact& contact, double slip, unsigned seed) {
  std::mt19937 random(seed);
  const StencilPositions motion = test::random_stencil(random);
  const double y = tangential_displacement(contact.frame, motion).norm();
  return flatten(motion) * (slip * kSlip / y);
}

TEST(FrictionPotential, DerivativesMatchFiniteDifferencesInEverySubCaseOnBothBranches) {
  for (const Stencil& s : contact_stencils()) {
    const LaggedFrictionContact contact = lagged(s);
    const VectorXd start = flatten(s.x);
    const FrictionPotential friction({contact}, start, kSlip);
    const auto value = [&](const VectorXd& x) { return friction.value(x); };
    const auto gradient = [&](const VectorXd& x) {
      VectorXd g = VectorXd::Zero(12);
      friction.add_gradient(x, g);
      return g;
    };
    for (double slip : {0.3, 0.8, 1.7, 30.0}) {
      SCOPED_TRACE(s.name + " slip " + std::to_string(slip));
      const VectorXd x = start + motion_with_slip(contact, slip, 7);
      const double h = 1e-4 * kSlip;
      EXPECT_LT(relative_error(gradient(x), fd_gradient(value, x, h)), 1e-6);
      ElementMatrices blocks;
      friction.hessian(x, blocks);
      const Eigen::MatrixXd hessian = test::dense_hessian(blocks, 12);
      EXPECT_LT(relative_error(hessian, fd_jacobian(gradient, x, h)), 1e-6);
      EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(hessian).eigenvalues().minCoeff(),
                -1e-9 * hessian.norm());
    }
  }
}

TEST(FrictionPotential, SlidingForceIsMuLambdaAndStickingForceIsProportionalToSlip) {
  const Stencil face = contact_stencils().front();
  const LaggedFrictionContact contact = lagged(face);
  const double mu_lambda = kFriction * contact.normal_force;
  const VectorXd start = flatten(face.x);
  const FrictionPotential friction({contact}, start, kSlip);
  const Vector3d along = contact.frame.basis * Eigen::Vector2d(0.6, 0.8);
  const auto force_on_point = [&](double slip) {
    VectorXd x = start;
    x.head<3>() += slip * kSlip * along;
    VectorXd g = VectorXd::Zero(12);
    friction.add_gradient(x, g);
    // Action and reaction: the triangle gets the opposite force.
    EXPECT_LT((g.head<3>() + g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9)).norm(),
              1e-12 * g.norm());
    return Vector3d(-g.head<3>());
  };
  for (double slip : {1.0, 3.0, 100.0}) {
    const Vector3d f = force_on_point(slip);
    EXPECT_NEAR(f.norm(), mu_lambda, 1e-12 * mu_lambda) << slip;
    EXPECT_NEAR(f.normalized().dot(along), -1, 1e-12);  // opposes the slip
  }
  // Below the threshold the contact holds like a spring of stiffness 2μλ/ε at small slip.
  const double small = 1e-4;
  EXPECT_NEAR(force_on_point(small).norm(), 2 * mu_lambda * small, 1e-3 * mu_lambda * small);
  EXPECT_NEAR(force_on_point(2 * small).norm() / force_on_point(small).norm(), 2, 1e-3);
  EXPECT_LT(force_on_point(0.5).norm(), mu_lambda);
}

TEST(FrictionPotential, StoresOnlyContactsThatCanExertFriction) {
  const std::vector<Stencil> stencils = contact_stencils();
  const VectorXd start = flatten(stencils.front().x);
  LaggedFrictionContact out_of_reach = lagged(stencils.front());
  out_of_reach.normal_force = 0;
  const FrictionPotential friction(
      {lagged(stencils.front()), lagged(stencils.front(), 0), out_of_reach}, start, kSlip);
  EXPECT_EQ(friction.contact_count(), 1);
  const FrictionPotential none({lagged(stencils.front(), 0)}, start, kSlip);
  EXPECT_EQ(none.contact_count(), 0);
  EXPECT_EQ(none.value(start + VectorXd::Ones(12)), 0);
  ElementMatrices blocks;
  none.hessian(start, blocks);
  EXPECT_EQ(blocks.element_count(), 0);
}

TEST(FrictionPotential, RejectsABadSlipThresholdAndNonFinitePositions) {
  const Stencil face = contact_stencils().front();
  const VectorXd start = flatten(face.x);
  EXPECT_THROW(FrictionPotential({lagged(face)}, start, 0), InputError);
  const FrictionPotential friction({lagged(face)}, start, kSlip);
  VectorXd x = start;
  x[4] = std::nan("");
  EXPECT_THROW(static_cast<void>(friction.value(x)), NumericalError);
}

}  // namespace
}  // namespace psq
