// Progressive simulation of contact scenes (paper §4.4–4.5): every level steps its own meshes
// with the barrier and the CCD line search, and each refinement starts from a safe
// initialization, so every state of every level must pass the exact intersection check. The
// scenes are CI-sized versions of the library's contact scenes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <string>

#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/sim/quasistatic.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "progressive/reference_runs.hpp"
#include "support/library_scene.hpp"
#include "support/press_scene.hpp"
#include "support/slope.hpp"

namespace psq {
namespace {

/// drape_sphere at a CI size: cloth falling onto a sphere with friction.
constexpr const char* kDrape = R"(
name = "drape"
gravity = [0, 0, -9.81]
[time]
step = 0.04
frames = 8
[solver]
frame_solution = "fixed_step"
[contact]
activation_distance = 2e-3
friction = 0.3
[[shell]]
name = "cloth"
mesh = { generator = "sheet", width = 0.6, height = 0.6, edge_length = 0.04 }
material = { youngs_modulus = 5e5, poisson_ratio = 0.3, density = 300, thickness = 5e-4 }
[[collider]]
name = "ball"
mesh = { generator = "sphere", radius = 0.2, edge_length = 0.05 }
placement = { translation = [0, 0, -0.2025] }
)";

/// twist_wrap at a CI size: a sheet whose ends turn 90° each in opposite directions while they
/// move toward each other, into self-contact at the last frames (the direct run's last frame has
/// 35 active pairs). Its coarsest level twists through the contact-free preview; the refinement
/// then expands a twisted surface, which exposes expansions whose patches fold.
constexpr const char* kTwist = R"(
name = "twist"
gravity = [0, 0, 0]
[time]
step = 0.04
frames = 12
[solver]
frame_solution = "fixed_step"
[contact]
self_contact = true
activation_distance = 2e-3
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 1.0, height = 1.0, edge_length = 0.08 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 500, thickness = 1e-3 }
[[shell.pin]]
name = "left_end"
box = { min = [-0.501, -0.501, -0.001], max = [-0.499, 0.501, 0.001] }
[[shell.pin.motion]]
start = 0.0
end = 0.48
axis_point = [0, 0, 0]
axis = [1, 0, 0]
angle_degrees = 90
translation = [0.0125, 0, 0]
[[shell.pin]]
name = "right_end"
box = { min = [0.499, -0.501, -0.001], max = [0.501, 0.501, 0.001] }
[[shell.pin.motion]]
start = 0.0
end = 0.48
axis_point = [0, 0, 0]
axis = [1, 0, 0]
angle_degrees = -90
translation = [-0.0125, 0, 0]
)";

/// cylinder_crush at a CI size: the plate descends 1 cm onto the can in 6 frames; the wall's
/// rim is squeezed against the plate at gaps near 1e-6 m, so the refinement expands a surface
/// in tight contact, and the preview's folded coarse wall puts some children's anchors nearly
/// on top of each other.
constexpr const char* kCrush = R"(
name = "crush"
gravity = [0, 0, -9.81]
[time]
step = 0.04
frames = 6
[solver]
frame_solution = "fixed_step"
[contact]
self_contact = true
activation_distance = 5e-4
[[shell]]
name = "can"
mesh = { generator = "cylinder", radius = 0.05, height = 0.1, edge_length = 0.01 }
material = { youngs_modulus = 69e9, poisson_ratio = 0.33, density = 2700, thickness = 1e-4 }
[[shell.pin]]
name = "bottom_rim"
box = { min = [-0.06, -0.06, -0.001], max = [0.06, 0.06, 0.001] }
[[collider]]
name = "plate"
mesh = { generator = "sheet", width = 0.16, height = 0.16, edge_length = 0.02 }
placement = { translation = [0, 0, 0.102] }
[[collider.motion]]
start = 0.0
end = 0.24
translation = [0, 0, -0.01]
)";

Scene scene_from(const char* text, const std::string& name) {
  return read_scene_text(text, name + ".toml");
}

/// The intersecting pairs of x on the system's mesh between bodies that may touch, plus its
/// degenerate triangles.
std::size_t intersections(const ShellSystem& system, const Eigen::VectorXd& x) {
  const ContactSurface surface = contact_surface(system, system.scene().contact.self_contact);
  const IntersectionReport report =
      find_intersections(as_positions(x), system.rest_mesh().triangles);
  std::size_t count = report.degenerate_triangles.size();
  for (const auto& [a, b] : report.intersecting_pairs)
    count += surface.may_touch(surface.vertex_body[system.rest_mesh().triangles(a, 0)],
                               surface.vertex_body[system.rest_mesh().triangles(b, 0)]);
  return count;
}

struct ProgressiveRun {
  Eigen::VectorXd finest;
  bool converged = false;
  std::size_t states = 0;        ///< states checked
  std::size_t intersecting = 0;  ///< of those, states with an intersection
  std::vector<RefinementStats> refinements;
};

/// Runs `scene` progressively over `levels` levels, checking every state of every level (every
/// step's result and every refinement's initializer) with the exact intersection check.
ProgressiveRun run_checked(const Scene& scene, int levels) {
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = levels;
  ProgressiveSimulation sim(scene, settings);
  ProgressiveRun run;
  const auto check = [&] {
    ++run.states;
    run.intersecting += intersections(sim.level_system(), sim.positions()) > 0;
  };
  check();
  test::run_to_end(sim, check);
  run.converged = sim.level_converged();
  run.finest = sim.positions();
  run.refinements = sim.refinements();
  return run;
}

/// Runs `sim` to its end and returns the steps its finest level took.
std::vector<ProgressiveStep> finest_steps_to_the_end(ProgressiveSimulation& sim) {
  std::vector<ProgressiveStep> finest_steps;
  for (;;) {
    while (!sim.level_done()) {
      ProgressiveStep step = sim.step();
      if (sim.finest_level()) finest_steps.push_back(std::move(step));
    }
    if (sim.finished()) return finest_steps;
    sim.refine();
  }
}

void print_refinements(const std::string& name, const ProgressiveRun& run) {
  std::cout << name << ": " << run.states << " states checked, " << run.refinements.size()
            << " refinements, finest level " << (run.converged ? "converged" : "NOT converged")
            << "\n";
  for (const RefinementStats& r : run.refinements)
    std::cout << "  level " << r.level << ": " << r.expansions << " expansions in " << r.batches
              << " batches, " << r.perturbation_retries << " retries, " << r.ccd_rounds
              << " CCD rounds, gap " << r.smallest_gap << " m, final gap " << r.final_gap
              << " m, target distance max " << r.max_target_distance << " mean "
              << r.mean_target_distance << " m, relaxed " << r.relaxed_vertices << " vertices in "
              << r.relax_iterations << " iterations (" << r.relax_seconds << " s), CCD "
              << r.ccd_seconds << " s, " << r.seconds << " s in all\n";
}

/// Every state intersection-free, one safe initialization per refinement.
void expect_safe(const std::string& name, const ProgressiveRun& run, int levels) {
  print_refinements(name, run);
  EXPECT_EQ(run.intersecting, 0u) << name;
  EXPECT_EQ(run.refinements.size(), static_cast<std::size_t>(levels - 1));
  for (const RefinementStats& r : run.refinements) {
    EXPECT_GT(r.expansions, 0);
    EXPECT_GT(r.final_gap, 0.0);
  }
}

TEST(ProgressiveContact, PressIsIntersectionFreeAtEveryLevelAndConverges) {
  const ProgressiveRun run = run_checked(scene_from(test::kPressScene, "press"), 3);
  expect_safe("press", run, 3);
  EXPECT_TRUE(run.converged);
}

TEST(ProgressiveContact, DrapeWithFrictionIsIntersectionFreeAtEveryLevelAndConverges) {
  const ProgressiveRun run = run_checked(scene_from(kDrape, "drape"), 2);
  expect_safe("drape", run, 2);
  EXPECT_TRUE(run.converged);
}

TEST(ProgressiveContact, TwistWithSelfContactIsIntersectionFreeAtEveryLevelAndConverges) {
  const ProgressiveRun run = run_checked(scene_from(kTwist, "twist"), 2);
  expect_safe("twist", run, 2);
  EXPECT_TRUE(run.converged);
  // The coarse twist is contact-free, so the expansion has room: no split may leave its vertex
  // at rounding distance from another element (folded flat onto its neighbours, which the exact
  // check cannot see), where the CCD advances stall short of their targets.
  for (const RefinementStats& r : run.refinements) {
    EXPECT_GT(r.smallest_gap, 1e-9);
    EXPECT_LT(r.max_target_distance, 1e-2);
  }
}

TEST(ProgressiveContact, AFixedStepScenesFirstFinestStepHasTheBudgetOfSeveralFrames) {
  // That step starts from the initializer, not from the previous frame, and corrects the whole
  // difference between the prolonged coarse answer and the fine one: the CI twist's takes about
  // 47 iterations, so with the budget of one frame (20 here) it would stop unconverged.
  Scene scene = scene_from(kTwist, "twist");
  scene.solver.max_iterations = 20;
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  ProgressiveSimulation sim(scene, settings);
  const std::vector<ProgressiveStep> finest_steps = finest_steps_to_the_end(sim);
  ASSERT_EQ(finest_steps.size(), 1u);  // the refine frame is the last frame
  const ProgressiveStep& step = finest_steps.front();
  EXPECT_TRUE(step.settling);
  EXPECT_TRUE(step.converged);
  EXPECT_GT(step.frame.newton.iterations, scene.solver.max_iterations);
  EXPECT_TRUE(sim.level_converged());
  EXPECT_EQ(intersections(sim.level_system(), sim.positions()), 0u);
}

TEST(ProgressiveContact, AFixedStepFinestStepThatDoesNotConvergeLeavesTheLevelNotConverged) {
  // Five frames of 5 iterations are too few for the CI twist's first finest step (about 47).
  Scene scene = scene_from(kTwist, "twist");
  scene.solver.max_iterations = 5;
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  ProgressiveSimulation sim(scene, settings);
  const std::vector<ProgressiveStep> finest_steps = finest_steps_to_the_end(sim);
  ASSERT_FALSE(finest_steps.empty());
  EXPECT_FALSE(finest_steps.back().converged);
  EXPECT_FALSE(sim.level_converged());
  // A level restored from its schedule state keeps the verdict.
  ProgressiveSimulation resumed(scene, settings);
  resumed.restore(1, sim.frame(), sim.positions(), sim.positions(), 0, sim.schedule_state());
  EXPECT_FALSE(resumed.level_converged());
}

TEST(ProgressiveContact, CrushIsIntersectionFreeAtEveryLevelAndConverges) {
  const ProgressiveRun run = run_checked(scene_from(kCrush, "crush"), 2);
  expect_safe("crush", run, 2);
  EXPECT_TRUE(run.converged);
  // The expansion keeps the safe gap of the coarse state: no pair ends far closer than the
  // closest pair the level-0 solve left.
  for (const RefinementStats& r : run.refinements) EXPECT_GT(r.final_gap, 1e-2 * r.smallest_gap);
}

TEST(ProgressiveContact, AFixedStepSceneIsSteppedAtItsRefineFrameNotSettled) {
  // The patch sliding down tilted_plane's slope (μ < tan α) has no equilibrium: settling it at
  // growing pseudo time steps only slides it farther with every step. A fixed-step scene's
  // finest level instead takes the refine frame's one step of Δt from its initializer, which
  // for a rigid block is Δt² g (sin α − μ cos α) down the slope (tests/support/slope.hpp).
  const Scene scene = test::library_scene("tilted_plane");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  ProgressiveSimulation sim(scene, settings);
  const Eigen::Vector3d downhill = test::downhill(scene);
  std::vector<ProgressiveStep> finest_steps;
  Eigen::VectorXd initializer;
  for (;;) {
    while (!sim.level_done()) {
      ProgressiveStep step = sim.step();
      EXPECT_TRUE(step.settling_failure.empty()) << step.settling_failure;
      if (sim.finest_level()) finest_steps.push_back(std::move(step));
    }
    if (sim.finished()) break;
    sim.refine();
    initializer = sim.positions();
  }
  EXPECT_TRUE(sim.level_converged());
  ASSERT_EQ(finest_steps.size(), 1u);  // the refine frame is the last frame
  const ProgressiveStep& step = finest_steps.front();
  EXPECT_TRUE(step.settling);
  EXPECT_FALSE(step.equilibrium);
  EXPECT_TRUE(step.judged);
  EXPECT_TRUE(step.converged);
  EXPECT_EQ(step.frame.frame, scene.time.frames);
  EXPECT_EQ(intersections(sim.level_system(), sim.positions()), 0u);
  const int patch_vertices = sim.level_system().shells()[0].vertex_count;
  double slide = 0.0;
  for (int v = 0; v < patch_vertices; ++v)
    slide += (sim.positions() - initializer).segment<3>(3 * v).dot(downhill);
  slide /= patch_vertices;
  const double coulomb_step = test::coulomb_step(scene, scene.contact.friction);
  EXPECT_NEAR(slide, coulomb_step, 0.05 * coulomb_step);
}

TEST(ProgressiveContact, AFixedStepScenesCoarseLevelSolvesItsRefineFrameToTheTolerance) {
  // Nothing settles a fixed-step scene's coarse level, so the refine frame's step is the state
  // the refinement prolongs: it is solved to the level's tolerance with the scene's budget, while
  // the preview steps before it stop at preview_iterations.
  const Scene scene = scene_from(kTwist, "twist");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  ProgressiveSimulation sim(scene, settings);
  std::vector<ProgressiveStep> coarse_steps;
  while (!sim.level_done()) coarse_steps.push_back(sim.step());
  ASSERT_EQ(coarse_steps.size(), static_cast<std::size_t>(scene.time.frames));
  const ProgressiveStep& refine_step = coarse_steps.back();
  EXPECT_EQ(refine_step.frame.frame, scene.time.frames);
  EXPECT_TRUE(refine_step.frame.newton.converged);
  EXPECT_LT(refine_step.frame.newton.step_norm, sim.tolerance());
  EXPECT_GT(refine_step.frame.newton.iterations, settings.schedule.preview_iterations);
  const auto capped = std::count_if(coarse_steps.begin(), coarse_steps.end() - 1,
                                    [&](const ProgressiveStep& step) {
                                      return !step.frame.newton.converged &&
                                             step.frame.newton.iterations ==
                                                 settings.schedule.preview_iterations;
                                    });
  EXPECT_GT(capped, 0);
}

TEST(ProgressiveContact, CollidersAreDecimatedAndEndAtTheirScriptedPlaces) {
  // Paper §4.6: the pressing ball has a hierarchy like the sheet's. Its coarse levels keep a
  // subset of its own vertices (so one rigid motion places every level alike), its refinements
  // expand it with the sheet, and at the finest level every one of its vertices is where the
  // script puts it, while every state stays free of intersections.
  const Scene scene = scene_from(test::kPressScene, "press");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 3;
  ProgressiveSimulation sim(scene, settings);
  const ShellSystem& finest = sim.finest_system();
  ASSERT_EQ(finest.colliders().size(), 1u);
  const ColliderBlock& ball = finest.colliders().front();
  const Positions finest_ball = finest.collider_rest_mesh(0).vertices;
  std::vector<int> ball_vertices;
  std::size_t intersecting = 0;
  const auto check = [&] {
    const ShellSystem& system = sim.level_system();
    intersecting += intersections(system, sim.positions()) > 0;
    if (ball_vertices.empty() || ball_vertices.back() != system.colliders().front().vertex_count)
      ball_vertices.push_back(system.colliders().front().vertex_count);
  };
  check();
  const Positions coarse_ball = sim.level_system().collider_rest_mesh(0).vertices;
  for (Eigen::Index v = 0; v < coarse_ball.rows(); ++v) {
    const double nearest = (finest_ball.rowwise() - coarse_ball.row(v)).rowwise().norm().minCoeff();
    EXPECT_EQ(nearest, 0.0) << "coarse ball vertex " << v << " is not a vertex of the ball";
  }
  test::run_to_end(sim, check);
  ASSERT_TRUE(sim.finished());
  EXPECT_TRUE(sim.level_converged());
  EXPECT_EQ(intersecting, 0u);
  ASSERT_EQ(ball_vertices.size(), 3u);
  EXPECT_LT(ball_vertices[0], ball_vertices[1]);
  EXPECT_LT(ball_vertices[1], ball.vertex_count);
  EXPECT_EQ(ball_vertices[2], ball.vertex_count);
  Eigen::VectorXd scripted = sim.positions();
  finest.apply_pins(scripted, sim.frame() * scene.time.step);
  const Eigen::Index first = 3 * Eigen::Index(ball.first_vertex);
  const Eigen::Index count = 3 * Eigen::Index(ball.vertex_count);
  EXPECT_LT((sim.positions().segment(first, count) - scripted.segment(first, count))
                .lpNorm<Eigen::Infinity>(),
            1e-12);
  std::cout << "press: ball vertices per level " << ball_vertices[0] << ", " << ball_vertices[1]
            << ", " << ball_vertices[2] << "\n";
}

TEST(ProgressiveContact, PressMatchesTheDirectFineEquilibrium) {
  // The pressed sheet's equilibrium is unique: the progressive finest answer and a direct solve
  // of the same frames must agree within 1e-3 of the bounding-box diagonal.
  const Scene scene = scene_from(test::kPressScene, "press");
  const ProgressiveRun progressive = run_checked(scene, 2);
  QuasistaticSimulation direct(scene);
  bool converged = true;
  while (direct.frame() < direct.frame_count())
    converged = direct.step().newton.converged && converged;
  ASSERT_TRUE(converged);
  const double diagonal = bounding_box_diagonal(direct.system().rest_mesh().vertices);
  const double distance = test::max_vertex_distance(progressive.finest, direct.positions());
  std::cout << "press: progressive vs direct fine equilibrium " << distance << " m, "
            << distance / diagonal << " of the diagonal\n";
  EXPECT_LT(distance, 1e-3 * diagonal);
}

TEST(ProgressiveContact, ResumingBetweenStepsEndsExactlyLikeTheUninterruptedRun) {
  // κ travels with the schedule state, and the safe initialization is deterministic (its random
  // retries are seeded), so a run restored between any two steps, before a refinement included,
  // ends bit-exactly where the uninterrupted one does.
  const Scene scene = scene_from(test::kPressScene, "press");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  struct Stored {
    int level, frame;
    Eigen::VectorXd positions, previous;
    std::map<std::string, double> schedule;
  };
  const auto store = [](const ProgressiveSimulation& sim) {
    return Stored{sim.level(), sim.frame(), sim.positions(), sim.previous(), sim.schedule_state()};
  };
  ProgressiveSimulation uninterrupted(scene, settings);
  std::vector<Stored> between_steps;
  std::size_t level_zero_done = 0;
  for (;;) {
    while (!uninterrupted.level_done()) {
      uninterrupted.step();
      between_steps.push_back(store(uninterrupted));
    }
    if (uninterrupted.finished()) break;
    level_zero_done = between_steps.size() - 1;
    uninterrupted.refine();
  }
  ASSERT_GT(between_steps.size(), 6u);
  for (const std::size_t k :
       {std::size_t{2}, level_zero_done, level_zero_done + 1, between_steps.size() - 2}) {
    SCOPED_TRACE(k);
    const Stored& stored = between_steps[k];
    ProgressiveSimulation resumed(scene, settings);
    resumed.restore(stored.level, stored.frame, stored.positions, stored.previous, 0,
                    stored.schedule);
    test::run_to_end(resumed);
    EXPECT_EQ((resumed.positions() - uninterrupted.positions()).lpNorm<Eigen::Infinity>(), 0.0);
  }
}

TEST(ProgressiveContact, AnIntersectingRestStateIsRefusedNamingTheTriangles) {
  std::string text = test::kPressScene;
  // The ball starts through the sheet.
  text.replace(text.find("0.1011]"), 7, "0.05]  ");
  try {
    run_checked(scene_from(text.c_str(), "press"), 2);
    FAIL() << "an intersecting rest state was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("not free of intersections"), std::string::npos) << message;
    EXPECT_NE(message.find("shell 'sheet' triangle"), std::string::npos) << message;
    EXPECT_NE(message.find("collider 'ball' triangle"), std::string::npos) << message;
  }
}

TEST(ProgressiveContact, AStrainLimitedPressIsCorrectedWithinTheLimitAndStaysFreeOfIntersections) {
  // The press with a soft sheet under a 3 % strain limit: prolonged against the sphere, the
  // level-1 initializer stretches triangles past the limit, and only moving old vertices too
  // brings them back (paper §4.4.5).
  std::string text = test::kPressScene;
  text.replace(text.find("youngs_modulus = 1e7"), 20, "youngs_modulus = 2e5");
  text.replace(text.find("thickness = 1e-3 }"), 18, "thickness = 1e-3, strain_limit = 1.03 }");
  const Scene scene = scene_from(text.c_str(), "limited_press");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 2;
  ProgressiveSimulation sim(scene, settings);
  std::size_t states = 0, intersecting = 0;
  double smallest_slack = std::numeric_limits<double>::infinity();
  const auto check = [&] {
    ++states;
    intersecting += intersections(sim.level_system(), sim.positions()) > 0;
    const StrainLimitTerm limits(sim.level_system());
    for (const StrainLimitEnergy& energy : limits.energies())
      smallest_slack = std::min(smallest_slack, energy.min_slack(sim.positions()));
  };
  check();
  test::run_to_end(sim, check);
  EXPECT_TRUE(sim.level_converged());
  EXPECT_EQ(intersecting, 0u) << "of " << states << " states";
  EXPECT_GT(smallest_slack, 0.0);
  ASSERT_EQ(sim.strain_corrections().size(), 1u);
  const StrainCorrectionStats& correction = sim.strain_corrections().front();
  std::cout << "limited press: " << states << " states, smallest slack " << smallest_slack
            << ", correction " << correction.iterations << " iterations, σ₁/s̄ "
            << correction.stretch_before << " -> " << correction.stretch_after
            << (correction.freed_old_vertices ? " (old vertices freed)" : "") << ", "
            << correction.seconds << " s\n";
  EXPECT_GT(correction.stretch_before, 1.0);
  EXPECT_LT(correction.stretch_after, 1.0);
  EXPECT_GT(correction.iterations, 0);
  EXPECT_TRUE(correction.freed_old_vertices);
}

}  // namespace
}  // namespace psq
