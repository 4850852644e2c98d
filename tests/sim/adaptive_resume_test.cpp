// Resuming a contact or strain-limited simulation between frames: with the adaptive state of
// the moment (κ and its range, κ_s and the last slack), the resumed run ends exactly where the
// uninterrupted one does.

#include <gtest/gtest.h>

#include <cmath>

#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "support/library_scene.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

using test::library_scene;

/// Runs `scene` to its end, stopping after frame `cut` to continue in a fresh simulation from
/// what a checkpoint stores (positions, xᵗ, adaptive state); returns the final positions.
/// cut = 0 runs without stopping.
Eigen::VectorXd run_with_cut(const Scene& scene, int cut) {
  QuasistaticSimulation first(scene);
  while (first.frame() < (cut > 0 ? cut : first.frame_count())) first.step();
  if (cut == 0) return first.positions();
  QuasistaticSimulation resumed(scene);
  resumed.restore(first.frame(), first.positions(), first.previous(), 0, first.adaptive_state());
  EXPECT_EQ(resumed.adaptive_state(), first.adaptive_state());
  while (resumed.frame() < resumed.frame_count()) resumed.step();
  return resumed.positions();
}

// Here κ at the cut happens to equal the next frame's initial κ, so positions alone would not
// show a lost κ; the restored state itself is compared in run_with_cut.
TEST(AdaptiveResume, ContactSceneResumedBetweenFramesEndsAsTheUninterruptedRun) {
  Scene scene = library_scene("drape_sphere");  // with friction
  scene.shells[0].mesh.sheet.edge_length = 0.1;
  scene.colliders[0].mesh.sphere.edge_length = 0.1;
  scene.time.frames = 6;
  const Eigen::VectorXd uninterrupted = run_with_cut(scene, 0);
  for (const int cut : {5}) {  // the cloth lies on the ball from frame 4
    SCOPED_TRACE(cut);
    EXPECT_LE((run_with_cut(scene, cut) - uninterrupted).lpNorm<Eigen::Infinity>(), 1e-12);
  }
}

// After a frame with nothing within reach (the cloth still falling toward the ball) the last
// smallest distance is infinite: the adaptive state must hold finite values only, as every
// checkpoint does (a snapshot of such a frame was refused: docs/stress.md), and resume exactly.
TEST(AdaptiveResume, ContactSceneResumedAfterAContactFreeFrameEndsAsTheUninterruptedRun) {
  Scene scene = library_scene("drape_sphere");
  scene.shells[0].mesh.sheet.edge_length = 0.1;
  scene.colliders[0].mesh.sphere.edge_length = 0.1;
  scene.time.frames = 5;
  {
    QuasistaticSimulation probe(scene);
    probe.step();
    for (const auto& [name, value] : probe.adaptive_state())
      EXPECT_TRUE(std::isfinite(value)) << name << " = " << value;
  }
  const Eigen::VectorXd uninterrupted = run_with_cut(scene, 0);
  EXPECT_LE((run_with_cut(scene, 1) - uninterrupted).lpNorm<Eigen::Infinity>(), 1e-12);
}

TEST(AdaptiveResume, StrainLimitedSceneResumedBetweenFramesEndsAsTheUninterruptedRun) {
  Scene scene = library_scene("hanging_sheet");
  // A weak start for κ_s, so that it must grow and the grown value has to be restored.
  scene.shells[0].strain_limit->stiffness = 1e-7;
  {
    QuasistaticSimulation probe(scene);
    probe.step();
    ASSERT_GT(probe.adaptive_state().at("strain_limit.sheet.stiffness"), 1e-7);
  }
  const Eigen::VectorXd uninterrupted = run_with_cut(scene, 0);
  for (int cut = 1; cut < scene.time.frames; ++cut) {
    SCOPED_TRACE(cut);
    EXPECT_LE((run_with_cut(scene, cut) - uninterrupted).lpNorm<Eigen::Infinity>(), 1e-12);
  }
}

}  // namespace
}  // namespace psq
