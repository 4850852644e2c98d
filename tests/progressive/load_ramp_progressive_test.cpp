// A ramped load through a progressive solve: every level's external force is the finest
// system's at the frame's load scale, so the finest level's equilibrium carries the ramped
// load into the clamp.

#include <gtest/gtest.h>

#include "engine/progressive/progressive_simulation.hpp"
#include "support/library_scene.hpp"

namespace psq {
namespace {

TEST(ProgressiveLoadRamp, TheFinestLevelsClampCarriesTheRampedLoad) {
  Scene scene = test::library_scene("cantilever");
  scene.time = {.step = 0.04, .frames = 4};
  scene.solver.tolerance = 1e-7;
  scene.hierarchy.levels = 2;
  scene.load_scale.keyframes = {{0.0, 0.0}, {0.32, 1.0}};  // s = t / 0.32: 0.5 at the last frame
  scene.shells[0].probes = {{.name = "clamp_force", .kind = ProbeKind::reaction, .pin = "clamp"}};
  ProgressiveSimulation sim(scene, ProgressiveSettings::from_scene(scene));
  ASSERT_EQ(sim.level_count(), 2);
  ProgressiveStep last;
  for (;;) {
    while (!sim.level_done()) {
      last = sim.step();
      EXPECT_DOUBLE_EQ(last.frame.load_scale, last.frame.frame * 0.04 / 0.32);
      // Probes are read on the finest mesh only.
      EXPECT_EQ(last.frame.probes.empty(), !sim.finest_level());
    }
    if (sim.finished()) break;
    sim.refine();
  }
  ASSERT_TRUE(sim.level_converged());
  ASSERT_EQ(last.frame.frame, 4);
  const double carried = 0.5 * 1e-3;  // half the scene's 1 mN tip load, along −z
  ASSERT_EQ(last.frame.probes.size(), 1u);
  EXPECT_NEAR(last.frame.probes[0].value.z(), -carried, 1e-4 * carried);
}

}  // namespace
}  // namespace psq
