// Finite-difference checks of the whole quasistatic objective (inertia, membrane, bending,
// gravity and loads) on a curved unstructured mesh with either bending model, with the contact
// barrier and lagged friction between two sheets in near contact, and with the strain-limit
// barriers of two stretched sheets, through the solver's own assembly.

#include "engine/sim/incremental_potential.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "engine/sim/contact_term.hpp"
#include "engine/sim/friction_term.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "engine/solver/sparse_assembler.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

/// Replaces each shell's membrane and bending batches (2s, 2s + 1, the potential's layout) with
/// their unprojected Hessians at x, so the assembly is the exact Hessian FD can check.
void unproject_elastics(const ShellSystem& system, const Eigen::VectorXd& x,
                        HessianBlocks& blocks) {
  for (std::size_t s = 0; s < system.shells().size(); ++s) {
    system.membranes()[s].hessian(x, blocks.batches[2 * s], false);
    system.bendings()[s].hessian(x, blocks.batches[2 * s + 1], false);
  }
}

/// The blocks assembled over every DOF of `system` (none fixed), as a dense symmetric matrix.
Eigen::MatrixXd assembled_hessian(const HessianBlocks& blocks, const ShellSystem& system) {
  SparseAssembler assembler;
  assembler.assemble(blocks, DofMap(system.rest_mesh().vertex_count(), {}));
  return Eigen::MatrixXd(assembler.matrix()).selfadjointView<Eigen::Upper>();
}

/// Relative error of the potential's gradient at x against central differences (step h) of
/// its value.
double gradient_error(IncrementalPotential& potential, const Eigen::VectorXd& x, double h) {
  Eigen::VectorXd g;
  potential.gradient(x, g);
  return test::relative_error(
      g, test::fd_gradient([&](const Eigen::VectorXd& y) { return potential.value(y); }, x, h));
}

/// Central differences (step h) of the potential's gradient at x.
Eigen::MatrixXd fd_hessian(IncrementalPotential& potential, const Eigen::VectorXd& x, double h) {
  return test::fd_jacobian(
      [&](const Eigen::VectorXd& y) {
        Eigen::VectorXd g;
        potential.gradient(y, g);
        return g;
      },
      x, h);
}

double smallest_eigenvalue(const Eigen::MatrixXd& symmetric) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(symmetric).eigenvalues().minCoeff();
}

/// An open cylinder (curved rest shape, non-zero rest angles) with gravity and a point load.
Scene curved_scene(BendingModel bending) {
  Scene scene;
  scene.source = "curved-test";
  scene.gravity = {0.0, 0.0, -9.81};
  scene.time.step = 0.01;
  Shell shell;
  shell.name = "tube";
  shell.mesh.kind = MeshSource::Kind::Cylinder;
  shell.mesh.cylinder = {0.05, 0.06, 0.02};
  shell.material = {2e5, 0.35, 500.0, 1e-3};
  shell.bending = bending;
  Load load;
  load.selector.kind = VertexSelector::Kind::List;
  load.selector.indices = {0, 3};
  load.total_force = {0.1, -0.2, 0.05};
  shell.loads.push_back(load);
  scene.shells.push_back(shell);
  return scene;
}

class IncrementalPotentialTest : public ::testing::TestWithParam<BendingModel> {
 protected:
  IncrementalPotentialTest() : system_(curved_scene(GetParam())), potential_(system_, 0.01) {
    const Eigen::VectorXd rest = flat(system_.rest_mesh().vertices);
    std::srand(7);
    potential_.set_previous(rest + 2e-3 * Eigen::VectorXd::Random(rest.size()));
    x_ = rest + 4e-3 * Eigen::VectorXd::Random(rest.size());
  }
  ShellSystem system_;
  IncrementalPotential potential_;
  Eigen::VectorXd x_;
};

TEST_P(IncrementalPotentialTest, GradientMatchesFiniteDifferences) {
  EXPECT_LT(gradient_error(potential_, x_, 1e-7), 1e-6);
}

TEST_P(IncrementalPotentialTest, UnprojectedAssembledHessianMatchesFiniteDifferences) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);  // the diagonal (inertia) and the batch layout
  unproject_elastics(system_, x_, blocks);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_LT(test::relative_error(hessian, fd_hessian(potential_, x_, 1e-7)), 1e-5);
}

TEST_P(IncrementalPotentialTest, SolverHessianIsPositiveSemiDefinite) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_GE(smallest_eigenvalue(hessian), -1e-9 * hessian.norm());
}

TEST_P(IncrementalPotentialTest, ExternalForceIsGravityPlusLoads) {
  const Eigen::VectorXd& f = system_.external_force();
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (Eigen::Index v = 0; v < f.size() / 3; ++v) total += f.segment<3>(3 * v);
  const double mass = system_.dof_masses().sum() / 3.0;
  const Eigen::Vector3d expected =
      mass * Eigen::Vector3d(0, 0, -9.81) + Eigen::Vector3d(0.1, -0.2, 0.05);
  EXPECT_LT((total - expected).norm(), 1e-12);
  // Lumped mass is ρ·h·area: the cylinder's area is 2πrH up to its polygonal approximation.
  EXPECT_NEAR(mass / (500.0 * 1e-3 * 2 * M_PI * 0.05 * 0.06), 1.0, 0.02);
}

TEST_P(IncrementalPotentialTest, BendingIsTheScenesModel) {
  EXPECT_EQ(system_.bendings()[0].model(), GetParam());
  EXPECT_GT(potential_.elastic_energy(x_), system_.membranes()[0].value(x_));
}

INSTANTIATE_TEST_SUITE_P(BendingModels, IncrementalPotentialTest,
                         ::testing::Values(BendingModel::hinge, BendingModel::midedge),
                         [](const ::testing::TestParamInfo<BendingModel>& info) {
                           return info.param == BendingModel::hinge ? "hinge" : "midedge";
                         });

/// Two 3 cm sheets (1 cm structured edges), the upper one 0.6 d̂ above the lower and shifted
/// sideways, with a fixed barrier stiffness. The upper one bends with the mid-edge model, so the
/// assembly holds both models' blocks side by side.
Scene stacked_sheets_scene() {
  Scene scene;
  scene.source = "contact-test";
  scene.time.step = 0.01;
  for (int k = 0; k < 2; ++k) {
    Shell shell;
    shell.name = k == 0 ? "lower" : "upper";
    shell.mesh.kind = MeshSource::Kind::Sheet;
    shell.mesh.sheet = {0.03, 0.03, 0.01, {}, true};
    shell.mesh.translation = k == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.003, 0.004, 6e-4);
    shell.material = {1e5, 0.3, 500.0, 1e-3};
    shell.bending = k == 0 ? BendingModel::hinge : BendingModel::midedge;
    scene.shells.push_back(shell);
  }
  scene.contact.activation_distance = 1e-3;
  scene.contact.stiffness = 1e5;
  return scene;
}

class ContactPotentialTest : public ::testing::Test {
 protected:
  ContactPotentialTest()
      : system_(stacked_sheets_scene()), potential_(system_, 0.01), contact_(system_) {
    potential_.add_term(contact_);
    const Eigen::VectorXd rest = flat(system_.rest_mesh().vertices);
    std::srand(5);
    potential_.set_previous(rest);
    x_ = rest;
    // Out-of-plane noise of 0.15 d̂: every distance sub-case, nearly parallel edges included.
    for (Eigen::Index v = 0; v < x_.size() / 3; ++v)
      x_[3 * v + 2] += 1.5e-4 * Eigen::VectorXd::Random(1)[0];
  }
  ShellSystem system_;
  IncrementalPotential potential_;
  ContactTerm contact_;
  Eigen::VectorXd x_;
};

TEST_F(ContactPotentialTest, ContactIsASignificantPartOfTheGradient) {
  ASSERT_GT(contact_.potential().active_pairs(x_).size(), 10u);
  Eigen::VectorXd base, full;
  potential_.base_gradient(x_, base);
  potential_.gradient(x_, full);
  EXPECT_GT((full - base).norm(), 0.1 * base.norm());
}

TEST_F(ContactPotentialTest, GradientMatchesFiniteDifferences) {
  EXPECT_LT(gradient_error(potential_, x_, 1e-9), 1e-5);
}

TEST_F(ContactPotentialTest, UnprojectedAssembledHessianMatchesFiniteDifferences) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);  // the diagonal and the batch layout
  unproject_elastics(system_, x_, blocks);
  contact_.potential().hessian(x_, blocks.batches[4], false);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_LT(test::relative_error(hessian, fd_hessian(potential_, x_, 1e-9)), 1e-4);
}

TEST_F(ContactPotentialTest, SolverHessianWithContactIsPositiveSemiDefinite) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_GE(smallest_eigenvalue(hessian), -1e-9 * hessian.norm());
}

/// The stacked sheets with friction (μ = 0.4, ε = ε_v Δt = 1e-5 m), lagged at the contact state
/// x for a step from xᵗ = x minus tangential slips of up to 2ε: contacts on both sides of ε.
class FrictionObjectiveTest : public ::testing::Test {
 protected:
  static Scene scene() {
    Scene s = stacked_sheets_scene();
    s.contact.friction = 0.4;
    s.contact.friction_slip_velocity = 1e-3;
    return s;
  }
  FrictionObjectiveTest()
      : system_(scene()), potential_(system_, 0.01), contact_(system_), friction_(system_, 0.01) {
    const Eigen::VectorXd rest = flat(system_.rest_mesh().vertices);
    std::srand(11);
    x_ = rest;
    Eigen::VectorXd previous = rest;
    for (Eigen::Index v = 0; v < x_.size() / 3; ++v) {
      x_[3 * v + 2] += 1.5e-4 * Eigen::VectorXd::Random(1)[0];
      previous.segment<2>(3 * v) -= 2e-5 * Eigen::Vector2d::Random();
    }
    potential_.set_previous(previous);
    potential_.add_term(contact_);
    potential_.add_term(friction_);
    friction_.lag(contact_.potential(), x_, previous);
  }
  ShellSystem system_;
  IncrementalPotential potential_;
  ContactTerm contact_;
  FrictionTerm friction_;
  Eigen::VectorXd x_;
};

TEST_F(FrictionObjectiveTest, FrictionIsASignificantPartOfTheGradient) {
  ASSERT_GT(friction_.contact_count(), 10);
  Eigen::VectorXd without_friction = Eigen::VectorXd::Zero(x_.size());
  Eigen::VectorXd friction_only = Eigen::VectorXd::Zero(x_.size());
  potential_.base_gradient(x_, without_friction);
  contact_.add_gradient(x_, without_friction);
  friction_.add_gradient(x_, friction_only);
  EXPECT_GT(friction_only.norm(), 0.01 * without_friction.norm());
}

TEST_F(FrictionObjectiveTest, GradientMatchesFiniteDifferences) {
  EXPECT_LT(gradient_error(potential_, x_, 1e-9), 1e-5);
}

TEST_F(FrictionObjectiveTest, UnprojectedAssembledHessianMatchesFiniteDifferences) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);  // the diagonal, the friction blocks and the batch layout
  unproject_elastics(system_, x_, blocks);
  contact_.potential().hessian(x_, blocks.batches[4], false);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_LT(test::relative_error(hessian, fd_hessian(potential_, x_, 1e-9)), 1e-4);
}

/// Two 3 cm sheets (1 cm structured edges) side by side, limited to stretches of 1.05 and 1.08,
/// with a κ_s that makes the barrier dominate the membrane at a few percent of stretch.
Scene limited_sheets_scene() {
  Scene scene = stacked_sheets_scene();
  scene.shells[1].mesh.translation = {0.05, 0.0, 0.0};
  scene.shells[0].strain_limit = StrainLimitSettings{.limit = 1.05, .stiffness = 1.0};
  scene.shells[1].strain_limit = StrainLimitSettings{.limit = 1.08, .stiffness = 1.0};
  return scene;
}

/// rest with every x coordinate scaled by `stretch`: a uniform stretch of every triangle.
Eigen::VectorXd stretched_along_x(const ShellSystem& system, double stretch) {
  Eigen::VectorXd x = flat(system.rest_mesh().vertices);
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) x[3 * v] *= stretch;
  return x;
}

class StrainLimitPotentialTest : public ::testing::Test {
 protected:
  StrainLimitPotentialTest()
      : system_(limited_sheets_scene()), potential_(system_, 0.01), strain_limit_(system_) {
    potential_.add_term(strain_limit_);
    std::srand(3);
    potential_.set_previous(flat(system_.rest_mesh().vertices));
    // A 3 % stretch with noise of 2e-5 m (0.2 % of an edge): every triangle inside both bands.
    x_ = stretched_along_x(system_, 1.03) +
         2e-5 * Eigen::VectorXd::Random(system_.dof_masses().size());
  }
  ShellSystem system_;
  IncrementalPotential potential_;
  StrainLimitTerm strain_limit_;
  Eigen::VectorXd x_;
};

TEST_F(StrainLimitPotentialTest,
       EveryLimitedShellHasItsBarrierAndItIsASignificantPartOfTheGradient) {
  ASSERT_EQ(strain_limit_.energies().size(), 2u);
  EXPECT_GT(strain_limit_.value(x_), 0.0);
  Eigen::VectorXd base, full;
  potential_.base_gradient(x_, base);
  potential_.gradient(x_, full);
  EXPECT_GT((full - base).norm(), 0.1 * base.norm());
}

TEST_F(StrainLimitPotentialTest, GradientMatchesFiniteDifferences) {
  EXPECT_LT(gradient_error(potential_, x_, 1e-8), 1e-6);
}

// The barrier's Hessian is PSD as it stands (docs/friction-and-strain-limiting.md), so the
// term's own (projected) blocks are its exact Hessian; membrane and bending are unprojected.
TEST_F(StrainLimitPotentialTest, AssembledHessianMatchesFiniteDifferences) {
  HessianBlocks blocks;
  potential_.hessian(x_, blocks);
  ASSERT_EQ(blocks.batches[4].element_count(),
            static_cast<std::size_t>(system_.rest_mesh().triangle_count()));
  unproject_elastics(system_, x_, blocks);
  const Eigen::MatrixXd hessian = assembled_hessian(blocks, system_);
  EXPECT_LT(test::relative_error(hessian, fd_hessian(potential_, x_, 1e-8)), 1e-5);
}

TEST_F(StrainLimitPotentialTest, FeasibleStepStopsShortOfTheTightestShellsLimit) {
  // Stretching on by 5 % more: shell 0 reaches 1.05 at α = 0.4, shell 1 reaches 1.08 at 1. The
  // step stops at 0.9 × 0.4, where shell 0 keeps a tenth of its slack.
  const Eigen::VectorXd x = stretched_along_x(system_, 1.03);
  const Eigen::VectorXd dx = stretched_along_x(system_, 1.08) - x;
  const double step = potential_.max_feasible_step(x, dx);
  EXPECT_NEAR(step, 0.9 * (1.05 - 1.03) / (1.08 - 1.03), 1e-9);
  EXPECT_NEAR(strain_limit_.energies()[0].min_slack(x + step * dx), 0.1 * (1.05 - 1.03), 1e-9);
  // A step that reaches no limit is not cut.
  EXPECT_EQ(potential_.max_feasible_step(x, 0.3 * dx), 1.0);
}

TEST_F(StrainLimitPotentialTest, StiffnessDoublesOnlyForAShellHeldAtItsLimit) {
  // 2e-6 below shell 0's limit, under its doubling slack 1e-4 δ = 5e-6; far from shell 1's.
  const Eigen::VectorXd tight = stretched_along_x(system_, 1.05 - 2e-6);
  strain_limit_.update_stiffness(tight);  // the first call has no previous slack
  EXPECT_EQ(strain_limit_.energies()[0].stiffness(), 1.0);
  strain_limit_.update_stiffness(tight);
  strain_limit_.update_stiffness(tight);
  EXPECT_EQ(strain_limit_.energies()[0].stiffness(), 4.0);
  EXPECT_EQ(strain_limit_.energies()[1].stiffness(), 1.0);
  // Once the slack opens again the stiffness stays.
  strain_limit_.update_stiffness(stretched_along_x(system_, 1.03));
  EXPECT_EQ(strain_limit_.energies()[0].stiffness(), 4.0);
}

}  // namespace
}  // namespace psq
