// Frames are static equilibria (scene [solver] frame_solution = "equilibrium", the default): a
// frame's answer balances the elastic forces against the loads, checked independently of the
// solver's own measure by summing the elastic gradients and the external force at the answer.
// A fixed-step frame of the same scene is a transient that does not.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "engine/sim/quasistatic.hpp"
#include "support/library_scene.hpp"

namespace psq {
namespace {

/// The library drape (a soft cloth held at two corners under gravity) on a coarse mesh over
/// `frames` frames: each fixed Δt step moves the cloth by Δt²g ≈ 1.6 cm at most, far from its
/// hanging equilibrium.
Scene coarse_drape(FrameSolution solution, int frames) {
  Scene scene = test::library_scene("drape");
  scene.shells[0].mesh.sheet.edge_length = 0.1;
  scene.time.frames = frames;
  scene.solver.frame_solution = solution;
  scene.solver.max_iterations = 400;
  return scene;
}

/// max over free DOFs of |∇(Ψ − f·x)|: the force the state leaves unbalanced [N], from the
/// system's energies directly (not from the solver's incremental potential).
double unbalanced_force(const ShellSystem& system, const Eigen::VectorXd& x) {
  Eigen::VectorXd g = -system.external_force();
  for (const auto& m : system.membranes()) m.add_gradient(x, g);
  for (const auto& b : system.bendings()) b.add_gradient(x, g);
  const std::vector<bool> fixed = system.fixed_dofs();
  for (Eigen::Index i = 0; i < g.size(); ++i)
    if (fixed[i]) g[i] = 0.0;
  return g.lpNorm<Eigen::Infinity>();
}

/// The largest load on one DOF [N]: the scale of the forces a state must balance.
double largest_load(const ShellSystem& system) {
  return system.external_force().lpNorm<Eigen::Infinity>();
}

TEST(EquilibriumFrames, EveryFrameBalancesItsLoads) {
  QuasistaticSimulation sim(coarse_drape(FrameSolution::equilibrium, 2));
  for (int frame = 1; frame <= 2; ++frame) {
    const FrameRecord record = sim.step();
    ASSERT_TRUE(record.newton.converged) << "frame " << frame;
    EXPECT_GT(record.settle_steps, 0) << "frame " << frame;
    ASSERT_TRUE(std::isfinite(record.static_residual));
    EXPECT_LT(record.static_residual, sim.newton_settings().tolerance);
    EXPECT_LT(unbalanced_force(sim.system(), sim.positions()), 1e-3 * largest_load(sim.system()))
        << "frame " << frame;
  }
}

TEST(EquilibriumFrames, AFixedStepFrameIsATransient) {
  QuasistaticSimulation fixed(coarse_drape(FrameSolution::fixed_step, 1));
  const FrameRecord record = fixed.step();
  ASSERT_TRUE(record.newton.converged);
  EXPECT_EQ(record.settle_steps, 0);
  EXPECT_TRUE(std::isnan(record.static_residual));
  // Far from balanced: the cloth has fallen one step, not hung.
  EXPECT_GT(unbalanced_force(fixed.system(), fixed.positions()), 0.1 * largest_load(fixed.system()));

  QuasistaticSimulation settled(coarse_drape(FrameSolution::equilibrium, 1));
  ASSERT_TRUE(settled.step().newton.converged);
  const double diagonal = bounding_box_diagonal(settled.system().rest_mesh().vertices);
  EXPECT_GT((settled.positions() - fixed.positions()).lpNorm<Eigen::Infinity>(), 0.05 * diagonal);
}

/// A state a snapshot would store after a Newton record that took a step.
struct Cut {
  Eigen::VectorXd positions, previous;
  std::map<std::string, double> state;
  int iterations = 0;
  bool ends_a_solve = false;  ///< the next record is its solve's judged final one (no step)
};

TEST(EquilibriumFrames, ResumingInsideTheStepOrItsSettlingEndsExactlyLikeTheUninterruptedRun) {
  const Scene scene = coarse_drape(FrameSolution::equilibrium, 1);
  QuasistaticSimulation reference(scene);
  std::vector<Cut> cuts;
  ASSERT_TRUE(reference
                  .step([&](int, const NewtonIteration& it) {
                    if (it.step_length <= 0.0) {
                      if (!cuts.empty()) cuts.back().ends_a_solve = true;
                      return;
                    }
                    cuts.push_back({reference.positions(), reference.previous(),
                                    reference.adaptive_state(), it.iteration + 1});
                  })
                  .newton.converged);
  // Cut inside the frame's step and inside a settling step, and right after the last step of
  // solves, where a resumed solve has nothing left to do: the settling schedule must go on as
  // if it had not stopped.
  std::vector<const Cut*> chosen;
  int solve_ends = 0;
  for (const Cut& cut : cuts)
    if ((cut.ends_a_solve && solve_ends++ < 4) || &cut == &cuts[1] ||
        (cut.state.contains("settling.growth") && cut.state.at("settling.growth") == 2 &&
         !cut.ends_a_solve))
      chosen.push_back(&cut);
  ASSERT_GE(chosen.size(), 4u);
  for (const Cut* cut : chosen) {
    SCOPED_TRACE(testing::Message() << "cut after " << cut->iterations << " iterations");
    QuasistaticSimulation resumed(scene);
    resumed.restore(1, cut->positions, cut->previous, cut->iterations, cut->state);
    const FrameRecord record = resumed.step();
    EXPECT_TRUE(record.newton.converged);
    EXPECT_EQ(resumed.positions(), reference.positions());
  }
}

TEST(Settling, TimeStepGrowsFourfoldToItsLargestAndJumpsThereWhenNothingMoves) {
  EXPECT_EQ(settling_time_step(0.5, 0), 0.5);
  EXPECT_EQ(settling_time_step(0.5, 2), 8.0);
  EXPECT_EQ(settling_time_step(0.5, kSettlingGrowthSteps + 3), 0.5 * 4096.0);
  EXPECT_EQ(next_settling_growth(2, false), 3);
  EXPECT_EQ(next_settling_growth(2, true), kSettlingGrowthSteps);
  EXPECT_EQ(next_settling_growth(kSettlingGrowthSteps, true), kSettlingGrowthSteps + 1);
  EXPECT_FALSE(settling_done(kSettlingGrowthSteps - 1, 0.0, 1.0));
  EXPECT_FALSE(settling_done(kSettlingGrowthSteps, 1.0, 1.0));
  EXPECT_TRUE(settling_done(kSettlingGrowthSteps, 0.5, 1.0));
}

TEST(EquilibriumFrames, SceneKeyChoosesTheFrameSolution) {
  EXPECT_EQ(test::library_scene("drape").solver.frame_solution, FrameSolution::equilibrium);
  EXPECT_EQ(test::library_scene("tilted_plane").solver.frame_solution, FrameSolution::fixed_step);
}

}  // namespace
}  // namespace psq
