#include "engine/elastic/bending.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "elastic/elastic_test_meshes.hpp"
#include "engine/core/error.hpp"
#include "engine/mesh/topology.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

using test::curved_shell;
using test::CurvedShell;
using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

const double kStiffness = bending_stiffness(test::test_material());

Eigen::VectorXd as_vector(const HingePositions& x) { return x.reshaped(); }
HingePositions as_hinge(const Eigen::VectorXd& v) { return v.reshaped(3, 4); }

/// Rest angles for the single-hinge tests: flat, mildly and strongly curved. Against the folds
/// of test::kFolds they give deviations near 0, of both signs, and some that wrap through ±π.
const double kRestAngles[] = {0.0, 0.4, -2.5};

TEST(BendingStiffness, IsOneSixthOfTheBendingModulus) {
  const Material m = test::test_material();
  const double e = m.youngs_modulus, h = m.thickness, nu = m.poisson_ratio;
  EXPECT_DOUBLE_EQ(bending_stiffness(m), e * h * h * h / (72 * (1 - nu * nu)));
}

TEST(HingeEnergy, ValueFollowsTheDefinition) {
  // W = k (θ − θ̄)² 3|ē|²/(Ā₀ + Ā₁) for the test hinge: |ē| = 1.1, heights 0.8 and 0.9.
  std::mt19937 rng(1);
  const HingeRest rest = hinge_rest(test::folded_hinge(0.4, rng));
  EXPECT_NEAR(rest.angle, 0.4, 1e-12);
  const double weight = 3 * 1.1 * 1.1 / (0.5 * 1.1 * 0.8 + 0.5 * 1.1 * 0.9);
  EXPECT_NEAR(rest.weight, weight, 1e-12 * weight);
  EXPECT_NEAR(hinge_energy(test::folded_hinge(-0.3, rng), rest, 2.0), 2.0 * weight * 0.49,
              1e-12 * weight);
}

TEST(HingeEnergy, AngleDeviationWrapsThroughPi) {
  // Folding past ±π continues smoothly: 3.0 and −3.0 are 2π − 6 apart, not 6.
  std::mt19937 rng(2);
  const HingeRest rest = hinge_rest(test::folded_hinge(-3.0, rng));
  EXPECT_NEAR(hinge_angle_deviation(test::folded_hinge(3.0, rng), rest), 6.0 - 2 * std::numbers::pi,
              1e-12);
}

TEST(HingeEnergy, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  for (double rest_angle : kRestAngles)
    for (double fold : test::kFolds) {
      const HingeRest rest = hinge_rest(test::folded_hinge(rest_angle, rng));
      const HingePositions x = test::folded_hinge(fold, rng);
      const Eigen::VectorXd fd_g = fd_gradient(
          [&](const Eigen::VectorXd& v) { return hinge_energy(as_hinge(v), rest, kStiffness); },
          as_vector(x), 1e-6);
      const HingeVector g = hinge_gradient(x, rest, kStiffness);
      // At θ = θ̄ the gradient vanishes: floor at its scale k·w·|∇θ|·(1 radian) ≈ k.
      EXPECT_LT(relative_error(g, fd_g, kStiffness), 1e-6)
          << "rest " << rest_angle << " fold " << fold;
      const Eigen::MatrixXd fd_h = fd_jacobian(
          [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
            return hinge_gradient(as_hinge(v), rest, kStiffness);
          },
          as_vector(x), 1e-6);
      EXPECT_LT(relative_error(hinge_hessian(x, rest, kStiffness, false), fd_h), 1e-6)
          << "rest " << rest_angle << " fold " << fold;
    }
}

TEST(HingeEnergy, SolverHessianIsTheGaussNewtonTermAndPsd) {
  // The solver's block drops (θ − θ̄)∇²θ: it must be PSD even where the full Hessian is not,
  // and differ from the full Hessian exactly by that term.
  std::mt19937 rng(4);
  int indefinite = 0;
  for (double rest_angle : kRestAngles)
    for (double fold : test::kFolds) {
      const HingeRest rest = hinge_rest(test::folded_hinge(rest_angle, rng));
      const HingePositions x = test::folded_hinge(fold, rng);
      const HingeMatrix full = hinge_hessian(x, rest, kStiffness, false);
      const HingeMatrix solver = hinge_hessian(x, rest, kStiffness, true);
      EXPECT_GE(test::min_eigenvalue(solver), -1e-12 * full.norm());
      const HingeMatrix dropped =
          2 * kStiffness * rest.weight * hinge_angle_deviation(x, rest) * dihedral_angle_hessian(x);
      EXPECT_LT(relative_error(solver + dropped, full), 1e-10);
      if (test::min_eigenvalue(full) < -1e-12 * full.norm()) ++indefinite;
    }
  EXPECT_GT(indefinite, 0) << "no test state has an indefinite full Hessian";
}

TEST(HingeEnergy, AtRestTheHessianIsTheRankOneGaussNewtonTerm) {
  // θ = θ̄: ∇²W = 2 k w ∇θ∇θᵀ, already PSD, so projection must not change it.
  std::mt19937 rng(5);
  for (double fold : test::kFolds) {
    const HingePositions x = test::folded_hinge(fold, rng);
    const HingeRest rest = hinge_rest(x);
    const HingeVector g = dihedral_angle_gradient(x);
    const HingeMatrix expected = 2 * kStiffness * rest.weight * g * g.transpose();
    EXPECT_LT(relative_error(hinge_hessian(x, rest, kStiffness, true), expected), 1e-10);
  }
}

TEST(HingeEnergy, DegenerateStateHasInfiniteEnergyAndNoDerivatives) {
  std::mt19937 rng(6);
  const HingeRest rest = hinge_rest(test::folded_hinge(0.2, rng));
  HingePositions x = test::folded_hinge(0.2, rng);
  x.col(2) = 0.5 * (x.col(0) + x.col(1));
  EXPECT_EQ(hinge_energy(x, rest, kStiffness), std::numeric_limits<double>::infinity());
  EXPECT_THROW(hinge_gradient(x, rest, kStiffness), NumericalError);
  EXPECT_THROW(hinge_hessian(x, rest, kStiffness, true), NumericalError);
}

// ---------------------------------------------------------------------------------------------
// Whole meshes.

TEST(BendingEnergy, CurvedRestStateHasZeroEnergyAndGradient) {
  std::mt19937 rng(7);
  const CurvedShell shell = curved_shell(6, rng);
  const BendingEnergy energy(shell.rest, shell.topology, test::test_material());
  ASSERT_EQ(energy.hinge_count(), static_cast<int>(shell.topology.hinges.size()));
  const Eigen::VectorXd x = flat(shell.rest.vertices);
  EXPECT_EQ(energy.value(x), 0.0);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  energy.add_gradient(x, g);
  EXPECT_EQ(g.lpNorm<Eigen::Infinity>(), 0.0);
  // The rest shape is curved, so a flat state costs energy.
  Positions flattened = shell.rest.vertices;
  flattened.col(2).setZero();
  EXPECT_GT(energy.value(flat(flattened)), 0.0);
}

TEST(BendingEnergy, GradientAndHessianMatchFiniteDifferencesOnACurvedMesh) {
  std::mt19937 rng(8);
  const CurvedShell shell = curved_shell(4, rng);
  const BendingEnergy energy(shell.rest, shell.topology, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(y.size());
    energy.add_gradient(y, g);
    return g;
  };
  const Eigen::VectorXd fd_g =
      fd_gradient([&](const Eigen::VectorXd& y) { return energy.value(y); }, x, 1e-6);
  EXPECT_LT(relative_error(gradient(x), fd_g), 1e-6);

  ElementMatrices blocks;
  energy.hessian(x, blocks, false);
  EXPECT_LT(relative_error(test::dense_hessian(blocks, x.size()), fd_jacobian(gradient, x, 1e-6)),
            1e-6);

  energy.hessian(x, blocks, true);
  const Eigen::MatrixXd projected = test::dense_hessian(blocks, x.size());
  EXPECT_GE(test::min_eigenvalue(projected), -1e-12 * projected.norm());
}

TEST(BendingEnergy, RigidMotionsChangeNeitherEnergyNorForceMagnitudes) {
  std::mt19937 rng(9);
  const CurvedShell shell = curved_shell(5, rng);
  const BendingEnergy energy(shell.rest, shell.topology, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  const Eigen::Matrix3d r = test::random_rotation(rng);
  const Eigen::VectorXd y = test::rigidly_moved(x, r, Eigen::Vector3d(-2.0, 0.5, 4.0));
  const double e = energy.value(x);
  EXPECT_GT(e, 0.0);
  EXPECT_NEAR(energy.value(y), e, 1e-12 * e);
  Eigen::VectorXd gx = Eigen::VectorXd::Zero(x.size()), gy = Eigen::VectorXd::Zero(x.size());
  energy.add_gradient(x, gx);
  energy.add_gradient(y, gy);
  EXPECT_LT(relative_error(gy, test::rigidly_moved(gx, r, Eigen::Vector3d::Zero())), 1e-10);
}

TEST(BendingEnergy, WorksAtAVertexOffsetAndReusesHessianStorage) {
  std::mt19937 rng(10);
  const CurvedShell shell = curved_shell(3, rng);
  const int offset = 7, n = shell.rest.vertex_count();
  const BendingEnergy alone(shell.rest, shell.topology, test::test_material());
  const BendingEnergy shifted(shell.rest, shell.topology, test::test_material(), offset);
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  Eigen::VectorXd scene = Eigen::VectorXd::Random(3 * (n + offset + 3));
  scene.segment(3 * offset, 3 * n) = x;

  EXPECT_EQ(shifted.value(scene), alone.value(x));
  Eigen::VectorXd g_alone = Eigen::VectorXd::Zero(x.size());
  Eigen::VectorXd g_scene = Eigen::VectorXd::Zero(scene.size());
  alone.add_gradient(x, g_alone);
  shifted.add_gradient(scene, g_scene);
  EXPECT_EQ(g_scene.segment(3 * offset, 3 * n), g_alone);
  EXPECT_EQ(g_scene.head(3 * offset).norm() + g_scene.tail(9).norm(), 0.0);

  ElementMatrices blocks;
  shifted.hessian(scene, blocks);
  ASSERT_EQ(blocks.stencil_size, 4);
  ASSERT_EQ(blocks.element_count(), shell.topology.hinges.size());
  for (std::size_t h = 0; h < shell.topology.hinges.size(); ++h) {
    const Hinge& hinge = shell.topology.hinges[h];
    EXPECT_EQ(blocks.vertices[4 * h + 0], offset + hinge.v0);
    EXPECT_EQ(blocks.vertices[4 * h + 1], offset + hinge.v1);
    EXPECT_EQ(blocks.vertices[4 * h + 2], offset + hinge.opposite0);
    EXPECT_EQ(blocks.vertices[4 * h + 3], offset + hinge.opposite1);
  }
  const double* storage = blocks.values.data();
  shifted.hessian(scene, blocks);
  EXPECT_EQ(blocks.values.data(), storage);
}

TEST(BendingEnergy, RejectsDegenerateRestHingesAndNonFinitePositions) {
  TriMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0.5, 0, 0, 0.5, -1, 0;  // vertex 2 on the shared edge
  mesh.triangles.resize(2, 3);
  mesh.triangles << 0, 1, 2, 1, 0, 3;
  const MeshTopology topology = MeshTopology::build(mesh);
  ASSERT_EQ(topology.hinges.size(), 1u);
  EXPECT_THROW(BendingEnergy(mesh, topology, test::test_material()), InputError);

  mesh.vertices(2, 1) = 1.0;
  const BendingEnergy energy(mesh, topology, test::test_material());
  Eigen::VectorXd x = flat(mesh.vertices);
  x[7] = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)energy.value(x), NumericalError);
}

}  // namespace
}  // namespace psq
