// The contact scenes of jobs/scenes, simulated at a coarse CI size (larger edges, fewer frames):
// every stored frame passes the exact intersection check, contact actually happens, and the
// skips are counted on frames without anything within reach.

#include <gtest/gtest.h>

#include "engine/scene/scene_reader.hpp"
#include "support/library_scene.hpp"
#include "support/scene_run.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

using test::library_scene;

/// Sets a generated mesh's target edge length (file meshes are left as they are).
void set_edge_length(MeshSource& mesh, double edge) {
  mesh.sheet.edge_length = mesh.cylinder.edge_length = mesh.sphere.edge_length = edge;
}

using test::expect_intersection_free_and_converged;
using test::SceneRun;
using test::simulate;

long most_active_pairs(const SceneRun& run) {
  long most = 0;
  for (const FrameRecord& f : run.frames) most = std::max(most, f.contact.max_active_pairs);
  return most;
}

TEST(ContactScenes, DrapeOverSphereSkipsTheFreeFallAndStaysIntersectionFree) {
  Scene scene = library_scene("drape_sphere");
  EXPECT_DOUBLE_EQ(scene.contact.friction, 0.3);
  EXPECT_EQ(scene.solver.frame_solution, FrameSolution::fixed_step);  // the cloth falls in steps
  set_edge_length(scene.shells[0].mesh, 0.1);
  set_edge_length(scene.colliders[0].mesh, 0.1);
  scene.time.frames = 6;
  const SceneRun run = simulate(scene);
  expect_intersection_free_and_converged(run);
  // The cloth starts 5 cm above the ball and falls Δt² g ≈ 1.6 cm per frame: the first frames
  // have nothing within reach, every evaluation skips the barrier and every step the CCD.
  const ContactStats& first = run.frames.front().contact;
  EXPECT_GT(first.barrier_evaluations, 0);
  EXPECT_EQ(first.barrier_skips, first.barrier_evaluations);
  EXPECT_GT(first.ccd_evaluations, 0);
  EXPECT_EQ(first.ccd_skips, first.ccd_evaluations);
  EXPECT_EQ(first.max_active_pairs, 0);
  // Later the cloth lies on the ball, with friction: at least one re-lag and re-solve.
  const ContactStats& last = run.frames.back().contact;
  EXPECT_GT(last.max_active_pairs, 0);
  EXPECT_GE(run.frames.back().friction_iterations, 2);
  EXPECT_LT(last.barrier_skips, last.barrier_evaluations);
}

TEST(ContactScenes, NapkinDropFallsFreelyThenLandsOnTheDetailedBall) {
  Scene scene = library_scene("napkin_drop");
  set_edge_length(scene.shells[0].mesh, 0.05);
  set_edge_length(scene.colliders[0].mesh, 0.03);
  const SceneRun run = simulate(scene);
  expect_intersection_free_and_converged(run);
  // 35 cm at about 1.6 cm per frame: the first 20 frames fall with nothing within reach.
  for (int f = 0; f < 20; ++f) EXPECT_EQ(run.frames[f].contact.max_active_pairs, 0) << f + 1;
  EXPECT_GT(run.frames.back().contact.max_active_pairs, 0);  // it lies on the ball
}

TEST(ContactScenes, TwistedSheetStaysIntersectionFree) {
  Scene scene = library_scene("twist_wrap");
  ASSERT_TRUE(scene.contact.self_contact);
  set_edge_length(scene.shells[0].mesh, 0.1);
  scene.time.frames = 14;  // 210° per end: the layers first touch around frame 9
  const SceneRun run = simulate(scene);
  expect_intersection_free_and_converged(run);
  EXPECT_GT(most_active_pairs(run), 0);  // the sheet wraps onto itself
}

TEST(ContactScenes, CrushedCylinderStaysIntersectionFree) {
  Scene scene = library_scene("cylinder_crush");
  set_edge_length(scene.shells[0].mesh, 0.02);
  set_edge_length(scene.colliders[0].mesh, 0.08);
  scene.time.frames = 4;  // the plate meets the rim in frame 2 and pushes it 2 mm down
  const SceneRun run = simulate(scene);
  expect_intersection_free_and_converged(run);
  EXPECT_GT(most_active_pairs(run), 0);  // the plate reaches the rim
}

TEST(ContactScenes, BunnyPressStaysIntersectionFree) {
  Scene scene = library_scene("bunny_press");
  set_edge_length(scene.shells[0].mesh, 0.05);
  scene.time.frames = 7;  // the bunny comes down 4 mm per frame and meets the sheet in frame 5
  const SceneRun run = simulate(scene);
  expect_intersection_free_and_converged(run);
  EXPECT_GT(most_active_pairs(run), 0);  // the bunny reaches the sheet
}

}  // namespace
}  // namespace psq
