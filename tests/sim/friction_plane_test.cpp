// A stiff patch resting on a plane tilted by α (jobs/scenes/tilted_plane.toml), under gravity,
// with lagged IPC friction in QuasistaticSimulation's outer friction loop. A rigid block's
// quasistatic step (inertia-like term m/(2Δt²)‖x − xᵗ‖², weight, Coulomb friction μN) moves it
// down the slope by Δt² g (sin α − μ cos α) per frame when μ < tan α, and not at all when
// μ > tan α — up to the smoothed friction's creep, below ε = ε_v Δt per frame
// (docs/friction-and-strain-limiting.md). Every frame must also be intersection-free.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "engine/scene/scene_reader.hpp"
#include "support/library_scene.hpp"
#include "support/scene_run.hpp"
#include "support/slope.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

constexpr int kFrames = 5;

Scene tilted_plane() {
  Scene scene = test::library_scene("tilted_plane");
  scene.time.frames = kFrames;
  return scene;
}

/// A run on the slope: the patch's mean displacement down the slope after each frame.
struct SlopeRun {
  test::SceneRun run;
  std::vector<double> downhill;  ///< [m], after frames 1..N
  double slip_threshold = 0;     ///< ε of the friction term [m] (0 without friction)
  bool has_friction_term = false;
};

SlopeRun run_on_slope(const Scene& scene) {
  const Eigen::Vector3d downhill = test::downhill(scene);
  SlopeRun out;
  Eigen::VectorXd start;
  out.run = test::simulate(scene, [&](const QuasistaticSimulation& sim) {
    const int patch_vertices = sim.system().shells()[0].vertex_count;
    if (start.size() == 0) start = flat(sim.system().rest_mesh().vertices);
    double sum = 0;
    for (int v = 0; v < patch_vertices; ++v)
      sum += (sim.positions() - start).segment<3>(3 * v).dot(downhill);
    out.downhill.push_back(sum / patch_vertices);
    out.has_friction_term = sim.friction() != nullptr;
    if (sim.friction()) out.slip_threshold = sim.friction()->slip_threshold();
  });
  return out;
}

/// The patch's displacement in frame k (1-based).
double frame_step(const SlopeRun& slope, int k) {
  return slope.downhill[k - 1] - (k == 1 ? 0.0 : slope.downhill[k - 2]);
}

void expect_friction_loop_ran(const test::SceneRun& run) {
  test::expect_intersection_free_and_converged(run);
  for (const FrameRecord& f : run.frames) {
    EXPECT_GT(f.contact.max_active_pairs, 0) << "frame " << f.frame;  // resting on the slope
    EXPECT_GE(f.friction_iterations, 2) << "frame " << f.frame;       // lag, solve, re-lag
    EXPECT_LE(f.friction_iterations, 5) << "frame " << f.frame;
  }
}

TEST(FrictionOnSlope, PatchSticksWhenMuExceedsTanAlpha) {
  Scene scene = tilted_plane();
  // Through the per-pair override: the scene-wide μ alone would let the patch slide.
  scene.contact.friction = 0;
  scene.contact.pair_friction.push_back(
      {{"patch", "slope"}, 1.3 * std::tan(test::slope_angle(scene))});
  const SlopeRun slope = run_on_slope(scene);
  expect_friction_loop_ran(slope.run);
  ASSERT_TRUE(slope.has_friction_term);
  // The mollifier's creep when sticking is ε(1 − √(1 − tan α/μ)) ≈ 0.52 ε per frame (the point
  // test in tests/contact/friction_slope_test.cpp), so below ε per frame.
  const double bound = kFrames * slope.slip_threshold;
  fmt::print(
      "sticking: ε = {:.3g} m, displacement down the slope after {} frames {:.3g} m "
      "(bound {:.3g} m)\n",
      slope.slip_threshold, kFrames, slope.downhill.back(), bound);
  for (double d : slope.downhill) EXPECT_LT(std::abs(d), bound);
}

TEST(FrictionOnSlope, PatchSlidesByTheCoulombStepWhenMuIsBelowTanAlpha) {
  Scene scene = tilted_plane();
  const double mu = 0.7 * std::tan(test::slope_angle(scene));
  scene.contact.friction = mu;
  const SlopeRun slope = run_on_slope(scene);
  expect_friction_loop_ran(slope.run);
  const double expected = test::coulomb_step(scene, mu);
  // Sticking contacts creep by less than ε per frame, so steps beyond 10 ε are real sliding.
  ASSERT_GT(expected, 10 * slope.slip_threshold);
  for (int k = 1; k <= kFrames; ++k) {
    fmt::print("sliding: frame {} step {:.4g} m, Coulomb step {:.4g} m, {} friction iterations\n",
               k, frame_step(slope, k), expected, slope.run.frames[k - 1].friction_iterations);
    EXPECT_NEAR(frame_step(slope, k), expected, 0.05 * expected) << "frame " << k;
  }
}

TEST(FrictionOnSlope, WithoutFrictionThereIsNoTermAndThePatchSlidesFreely) {
  Scene scene = tilted_plane();
  scene.contact.friction = 0;
  const SlopeRun slope = run_on_slope(scene);
  test::expect_intersection_free_and_converged(slope.run);
  EXPECT_FALSE(slope.has_friction_term);
  for (const FrameRecord& f : slope.run.frames) EXPECT_EQ(f.friction_iterations, 0);
  const double expected = test::coulomb_step(scene, 0);
  for (int k = 1; k <= kFrames; ++k)
    EXPECT_NEAR(frame_step(slope, k), expected, 0.05 * expected) << "frame " << k;
}

}  // namespace
}  // namespace psq
