// Finite-difference checks of the whole quasistatic objective (inertia, membrane, bending,
// gravity and loads) on a curved unstructured mesh, through the solver's own assembly.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "engine/sim/incremental_potential.hpp"
#include "engine/solver/sparse_assembler.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

/// An open cylinder (curved rest shape, non-zero rest angles) with gravity and a point load.
Scene curved_scene() {
  Scene scene;
  scene.source = "curved-test";
  scene.gravity = {0.0, 0.0, -9.81};
  scene.time.step = 0.01;
  Shell shell;
  shell.name = "tube";
  shell.mesh.kind = MeshSource::Kind::Cylinder;
  shell.mesh.cylinder = {0.05, 0.06, 0.02};
  shell.material = {2e5, 0.35, 500.0, 1e-3};
  Load load;
  load.selector.kind = VertexSelector::Kind::List;
  load.selector.indices = {0, 3};
  load.total_force = {0.1, -0.2, 0.05};
  shell.loads.push_back(load);
  scene.shells.push_back(shell);
  return scene;
}

class IncrementalPotentialTest : public ::testing::Test {
 protected:
  IncrementalPotentialTest() : system_(curved_scene()), potential_(system_, 0.01) {
    const Eigen::VectorXd rest = flat(system_.rest_mesh().vertices);
    std::srand(7);
    potential_.set_previous(rest + 2e-3 * Eigen::VectorXd::Random(rest.size()));
    x_ = rest + 4e-3 * Eigen::VectorXd::Random(rest.size());
  }
  ShellSystem system_;
  IncrementalPotential potential_;
  Eigen::VectorXd x_;
};

TEST_F(IncrementalPotentialTest, GradientMatchesFiniteDifferences) {
  Eigen::VectorXd g;
  potential_.gradient(x_, g);
  const Eigen::VectorXd fd = test::fd_gradient([&](const Eigen::VectorXd& y) { return potential_.value(y); },
                                               x_, 1e-7);
  EXPECT_LT(test::relative_error(g, fd), 1e-6);
}

TEST_F(IncrementalPotentialTest, UnprojectedAssembledHessianMatchesFiniteDifferences) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);  // the diagonal (inertia) and the batch layout
  system_.membranes()[0].hessian(x_, blocks.batches[0], false);
  system_.bendings()[0].hessian(x_, blocks.batches[1], false);
  const DofMap all_free(system_.rest_mesh().vertex_count(), {});
  SparseAssembler assembler;
  assembler.assemble(blocks, all_free);
  const Eigen::MatrixXd upper = Eigen::MatrixXd(assembler.matrix());
  const Eigen::MatrixXd hessian = upper.selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd fd = test::fd_jacobian(
      [&](const Eigen::VectorXd& y) {
        Eigen::VectorXd g;
        potential_.gradient(y, g);
        return g;
      },
      x_, 1e-7);
  EXPECT_LT(test::relative_error(hessian, fd), 1e-5);
}

TEST_F(IncrementalPotentialTest, SolverHessianIsPositiveSemiDefinite) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);
  SparseAssembler assembler;
  assembler.assemble(blocks, DofMap(system_.rest_mesh().vertex_count(), {}));
  const Eigen::MatrixXd hessian = Eigen::MatrixXd(assembler.matrix()).selfadjointView<Eigen::Upper>();
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(hessian).eigenvalues().minCoeff();
  EXPECT_GE(smallest, -1e-9 * hessian.norm());
}

TEST_F(IncrementalPotentialTest, ExternalForceIsGravityPlusLoads) {
  const Eigen::VectorXd& f = system_.external_force();
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (Eigen::Index v = 0; v < f.size() / 3; ++v) total += f.segment<3>(3 * v);
  const double mass = system_.dof_masses().sum() / 3.0;
  const Eigen::Vector3d expected = mass * Eigen::Vector3d(0, 0, -9.81) + Eigen::Vector3d(0.1, -0.2, 0.05);
  EXPECT_LT((total - expected).norm(), 1e-12);
  // Lumped mass is ρ·h·area: the cylinder's area is 2πrH up to its polygonal approximation.
  EXPECT_NEAR(mass / (500.0 * 1e-3 * 2 * M_PI * 0.05 * 0.06), 1.0, 0.02);
}

}  // namespace
}  // namespace psq
