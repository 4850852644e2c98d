// The progressive schedule: levels = 1 is QuasistaticSimulation; on the drape, twist and
// cylinder scenes (CI size, nested grids) the finest answer matches a direct fine solve and the
// coarsest preview beats a direct coarse simulation; the step-wise API and resuming.

#include "engine/progressive/progressive_simulation.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "progressive/nested_cases.hpp"
#include "progressive/reference_runs.hpp"
#include "support/library_scene.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

ProgressiveSettings two_levels(const Scene& scene) {
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  return settings;
}

void run_level(ProgressiveSimulation& sim) {
  while (!sim.level_done()) sim.step();
}

TEST(ProgressiveSimulation, OneLevelIsExactlyTheQuasistaticSimulation) {
  const test::NestedCase twist = test::nested_case("twist", 6);
  ProgressiveSettings settings = ProgressiveSettings::from_scene(twist.scene);
  settings.schedule.levels = 1;
  ProgressiveSimulation progressive(twist.scene, settings, {});
  QuasistaticSimulation direct(twist.scene);
  ASSERT_EQ(progressive.level_count(), 1);
  EXPECT_DOUBLE_EQ(progressive.tolerance(), direct.newton_settings().tolerance);
  while (!progressive.finished()) {
    // A frame is its step and then its settling steps, which the direct solver takes in one call.
    ProgressiveStep step = progressive.step();
    EXPECT_FALSE(step.settling);
    int iterations = step.frame.newton.iterations, settle_steps = 0;
    while (!progressive.frame_settled()) {
      step = progressive.step();
      EXPECT_TRUE(step.settling);
      iterations += step.frame.newton.iterations;
      ++settle_steps;
    }
    EXPECT_TRUE(step.equilibrium);
    const FrameRecord expected = direct.step();
    EXPECT_EQ(step.frame.frame, expected.frame);
    EXPECT_EQ(settle_steps, expected.settle_steps);
    EXPECT_EQ(iterations, expected.newton.iterations);
    EXPECT_EQ(step.frame.static_residual, expected.static_residual);
    EXPECT_EQ(step.frame.elastic_energy, expected.elastic_energy);
    ASSERT_TRUE(progressive.positions() == direct.positions()) << "frame " << expected.frame;
    EXPECT_TRUE(progressive.finest_positions() == direct.positions());
  }
  EXPECT_EQ(progressive.frame(), twist.scene.time.frames);
}

/// Runs `sim` (two levels) through, then a direct fine solve and a direct solve of the coarsest
/// mesh with its own elastics; asserts the finest answer within 1e-3 × bbox diagonal of the
/// direct fine one, and the coarsest preview, prolonged, closer to it than `preview_factor` ×
/// the direct coarse answer's error (prolonged by the same P^0). Prints the errors.
void compare_with_direct_solves(const Scene& scene, ProgressiveSimulation& sim,
                                double preview_factor = 1.0) {
  ASSERT_EQ(sim.level_count(), 2);
  run_level(sim);
  EXPECT_TRUE(sim.level_converged());
  EXPECT_EQ(sim.frame(), scene.time.frames);
  const Eigen::VectorXd preview = sim.finest_positions();
  sim.refine();
  run_level(sim);
  ASSERT_TRUE(sim.finished());
  EXPECT_TRUE(sim.level_converged());

  const ShellSystem& fine = sim.finest_system();
  const test::DirectRun direct_fine = test::settled_direct_run(fine, sim.tolerance());
  ASSERT_TRUE(direct_fine.settled);
  const HierarchyLevel& coarsest = sim.hierarchies().at(0).levels[0];
  const ShellSystem coarse(scene, {{coarsest.rest, coarsest.pin_group, fine.shared_pins(0)}});
  const test::DirectRun direct_coarse = test::settled_direct_run(coarse, sim.tolerance());
  ASSERT_TRUE(direct_coarse.settled);
  const ShellProlongation to_finest(coarsest.rest, coarsest.finest, fine.rest_mesh().vertices);
  const Eigen::VectorXd coarse_prolonged =
      flat(to_finest.apply(as_positions(direct_coarse.positions)));

  const double diagonal = bounding_box_diagonal(fine.rest_mesh().vertices);
  const double final_error = test::max_vertex_distance(sim.positions(), direct_fine.positions);
  const double preview_error = test::max_vertex_distance(preview, direct_fine.positions);
  const double coarse_error = test::max_vertex_distance(coarse_prolonged, direct_fine.positions);
  std::cout << scene.name << ": " << fine.rest_mesh().vertex_count() << " fine, "
            << coarse.rest_mesh().vertex_count() << " coarse vertices; errors / bbox diagonal: "
            << "progressive finest " << final_error / diagonal << ", level-0 preview "
            << preview_error / diagonal << ", direct coarse " << coarse_error / diagonal << "\n";
  EXPECT_LT(final_error, 1e-3 * diagonal);
  EXPECT_LT(preview_error, preview_factor * coarse_error);
}

void compare_with_direct_solves(const test::NestedCase& c, double preview_factor = 1.0) {
  ProgressiveSimulation sim(c.scene, two_levels(c.scene), {c.hierarchy});
  compare_with_direct_solves(c.scene, sim, preview_factor);
}

/// The flat drape's preview is only as close as the direct coarse simulation: here the two
/// errors agree to 0.2 % (which is ahead moves with the solver's rounding), and on decimated
/// hierarchies at 5k and 20k vertices the preview is behind (bench_progressive; issue 4 notes).
/// Prolonged linearly across a flat coarse mesh, the fine hinges see the coarse creases whole,
/// so the preview bends stiffer than the cloth. The bound is a tie, not a win.
constexpr double kDrapePreviewTie = 1.01;

TEST(ProgressiveSimulation, DrapeMatchesDirectFineAndPreviewTiesDirectCoarse) {
  compare_with_direct_solves(test::nested_case("drape", 10), kDrapePreviewTie);
}

TEST(ProgressiveSimulation, TwistMatchesDirectFineAndPreviewBeatsDirectCoarse) {
  compare_with_direct_solves(test::nested_case("twist", 10));
}

TEST(ProgressiveSimulation, MidedgeDrapeMatchesDirectFineAndPreviewTiesDirectCoarse) {
  // Every level's system bends with the scene's model: the coarse level's mid-edge faces in the
  // preview and Hessian, the finest level's in the proxy's energy and gradient.
  test::NestedCase drape = test::nested_case("drape", 10);
  drape.scene.shells[0].bending = BendingModel::midedge;
  compare_with_direct_solves(drape, kDrapePreviewTie);
}

TEST(ProgressiveSimulation, CylinderMatchesDirectFineAndPreviewBeatsDirectCoarse) {
  // The decimated hierarchy (build_hierarchy) of the library's can at ~400 fine vertices.
  Scene scene = test::library_scene("cylinder_compress");
  scene.shells[0].mesh.cylinder.edge_length = 0.01;
  scene.time.step = 0.2;
  scene.time.frames = 5;
  ProgressiveSimulation sim(scene, two_levels(scene));
  compare_with_direct_solves(scene, sim);
}

TEST(ProgressiveSimulation, ScheduleStepsPreviewFramesThenSettlesThenRefines) {
  const test::NestedCase twist = test::nested_case("twist", 4);
  ProgressiveSettings settings = two_levels(twist.scene);
  settings.schedule.refine_frame = 2;
  ProgressiveSimulation sim(twist.scene, settings, {twist.hierarchy});
  EXPECT_THROW(sim.refine(), std::logic_error);
  EXPECT_EQ(sim.level_rest_mesh().vertex_count(), twist.hierarchy.levels[0].rest.vertex_count());
  for (int frame = 1; frame <= 2; ++frame) {
    const ProgressiveStep step = sim.step();
    EXPECT_FALSE(step.settling);
    EXPECT_EQ(step.frame.frame, frame);
    EXPECT_LE(step.frame.newton.iterations, settings.schedule.preview_iterations);
  }
  const auto growth = [&] { return sim.schedule_state().at("progressive.settle_growth"); };
  int settling_steps = 0;
  double last_growth = 0;
  while (!sim.level_done()) {
    last_growth = growth();
    const ProgressiveStep step = sim.step();
    EXPECT_TRUE(step.settling);
    EXPECT_EQ(step.frame.frame, 2);
    ++settling_steps;
    // A settling step with nothing to solve jumps to the largest time step (growing 4× per step
    // would take up to 5 more steps there).
    if (step.frame.newton.iterations == 0 && !sim.level_done()) {
      EXPECT_EQ(growth(), kSettlingGrowthSteps);
    }
  }
  EXPECT_GE(settling_steps, 1);
  // Only a step at the largest time step ends the settling.
  EXPECT_GE(last_growth, kSettlingGrowthSteps);
  EXPECT_LT((sim.positions() - sim.previous()).lpNorm<Eigen::Infinity>() / twist.scene.time.step,
            sim.tolerance());
  EXPECT_THROW(sim.step(), std::logic_error);

  sim.refine();
  EXPECT_EQ(sim.level(), 1);
  EXPECT_TRUE(sim.positions() == sim.previous());
  // The pinned vertices sit exactly at their scripted positions after refinement.
  Eigen::VectorXd pinned = sim.positions();
  sim.finest_system().apply_pins(pinned, 2 * twist.scene.time.step);
  EXPECT_TRUE(pinned == sim.positions());
  run_level(sim);
  EXPECT_TRUE(sim.finished());
  EXPECT_EQ(sim.frame(), 4);
}

TEST(ProgressiveSimulation, ASettlingWithoutAnEquilibriumStopsAndSaysWhy) {
  // An unpinned sheet under gravity has no static equilibrium: at the largest pseudo time step
  // every settling step moves it by g·(Δt·4⁶)² again, and the change never falls.
  const Scene scene = read_scene_text(R"(
name = "falling"
gravity = [0, 0, -9.81]
[time]
step = 0.04
frames = 2
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 0.2, height = 0.2, edge_length = 0.04 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 1000, thickness = 1e-3 }
)",
                                      "falling.toml");
  ProgressiveSimulation sim(scene, two_levels(scene));
  ProgressiveStep last;
  std::vector<std::string> failures;
  for (;;) {
    while (!sim.level_done()) {
      last = sim.step();
      if (!last.settling_failure.empty()) failures.push_back(last.settling_failure);
    }
    if (sim.finished()) break;
    sim.refine();
  }
  EXPECT_TRUE(last.judged);
  EXPECT_FALSE(last.converged);
  EXPECT_FALSE(sim.level_converged());
  // The preview's settling and the finest level's each end with their reason, once.
  ASSERT_EQ(failures.size(), 2u);
  EXPECT_EQ(failures.back(), last.settling_failure);
  for (int level = 0; level < 2; ++level) {
    const std::string& message = failures[static_cast<std::size_t>(level)];
    EXPECT_NE(message.find(fmt::format(
                  "level {} frame 2: the settling to a static equilibrium stalled", level)),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("check that its pins, colliders and friction support it"),
              std::string::npos)
        << message;
  }
}

TEST(ProgressiveSimulation, RestoreResumesWhereTheStoredStateLeftOff) {
  const test::NestedCase twist = test::nested_case("twist", 4);
  const ProgressiveSettings settings = two_levels(twist.scene);
  ProgressiveSimulation original(twist.scene, settings, {twist.hierarchy});
  original.step();
  original.step();
  ProgressiveSimulation resumed(twist.scene, settings, {twist.hierarchy});
  resumed.restore(0, original.frame(), original.positions(), original.previous());
  EXPECT_EQ(resumed.frame(), 2);
  const ProgressiveStep a = original.step();
  const ProgressiveStep b = resumed.step();
  EXPECT_EQ(a.frame.frame, b.frame.frame);
  EXPECT_TRUE(original.positions() == resumed.positions());

  EXPECT_THROW(resumed.restore(2, 4, original.positions(), original.previous()),
               std::invalid_argument);
  EXPECT_THROW(resumed.restore(0, 5, original.positions(), original.previous()),
               std::invalid_argument);
  EXPECT_THROW(resumed.restore(1, 4, original.positions(), original.previous()),
               std::invalid_argument);  // level 1 has the fine mesh's unknowns
}

/// What a checkpoint stores of a progressive run.
struct StoredState {
  int level = 0, frame = 0, iterations_in_frame = 0;
  Eigen::VectorXd positions, previous;
  std::map<std::string, double> schedule;
};

StoredState store(const ProgressiveSimulation& sim, int frame, int iterations_in_frame) {
  return {sim.level(),     frame,          iterations_in_frame,
          sim.positions(), sim.previous(), sim.schedule_state()};
}

struct Interrupted {};

TEST(ProgressiveSimulation, ResumingAnyStoredIterateEndsExactlyLikeTheUninterruptedRun) {
  const test::NestedCase twist = test::nested_case("twist", 4);
  ProgressiveSettings settings = two_levels(twist.scene);
  settings.schedule.refine_frame = 2;
  ProgressiveSimulation uninterrupted(twist.scene, settings, {twist.hierarchy});
  int steps_taken = 0;  // Newton iterations that moved the iterate, over the whole run
  std::vector<StoredState> between_steps;
  while (true) {
    while (!uninterrupted.level_done()) {
      uninterrupted.step(
          [&](int, int, const NewtonIteration& it) { steps_taken += it.step_length > 0; });
      between_steps.push_back(store(uninterrupted, uninterrupted.frame(), 0));
    }
    if (uninterrupted.finished()) break;
    uninterrupted.refine();
    between_steps.push_back(store(uninterrupted, uninterrupted.frame(), 0));
  }
  ASSERT_GT(steps_taken, 8);

  const auto expect_resumed_run_ends_as_uninterrupted = [&](const StoredState& stored) {
    ProgressiveSimulation resumed(twist.scene, settings, {twist.hierarchy});
    resumed.restore(stored.level, stored.frame, stored.positions, stored.previous,
                    stored.iterations_in_frame, stored.schedule);
    test::run_to_end(resumed);
    EXPECT_LE((resumed.positions() - uninterrupted.positions()).lpNorm<Eigen::Infinity>(), 1e-12);
  };
  // Inside steps: preview frames, settling at the refine frame, the finest level's frames.
  for (const int cut :
       {1, steps_taken / 4, steps_taken / 2, 3 * steps_taken / 4, steps_taken - 1}) {
    SCOPED_TRACE(cut);
    ProgressiveSimulation interrupted(twist.scene, settings, {twist.hierarchy});
    int taken = 0;
    std::optional<StoredState> stored;
    try {
      while (true) {
        while (!interrupted.level_done())
          interrupted.step([&](int, int frame, const NewtonIteration& it) {
            if (it.step_length <= 0 || ++taken < cut) return;
            stored = store(interrupted, frame, it.iteration + 1);
            throw Interrupted{};
          });
        if (interrupted.finished()) break;
        interrupted.refine();
      }
    } catch (const Interrupted&) {
    }
    ASSERT_TRUE(stored);
    expect_resumed_run_ends_as_uninterrupted(*stored);
  }
  // Between steps, including a level done at the refine frame (no extra settling step).
  for (const std::size_t k : {std::size_t{0}, between_steps.size() / 2, between_steps.size() - 2}) {
    SCOPED_TRACE(k);
    expect_resumed_run_ends_as_uninterrupted(between_steps[k]);
  }
}

}  // namespace
}  // namespace psq
