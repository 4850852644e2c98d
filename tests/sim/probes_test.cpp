// Probes and load scales through QuasistaticSimulation: a pinned set's reaction against the
// total applied force at static equilibrium (engine/sim/probes.hpp derives why they agree), a
// displacement probe against the mean computed here from positions chosen by their rest
// coordinates, and the loads scaled by keyframes.

#include <gtest/gtest.h>

#include <cmath>

#include "engine/core/error.hpp"
#include "engine/sim/quasistatic.hpp"
#include "support/library_scene.hpp"

namespace psq {
namespace {

const ProbeReading& reading(const FrameRecord& record, const std::string& name) {
  for (const ProbeReading& r : record.probes)
    if (r.name == name) return r;
  throw std::invalid_argument("no probe " + name);
}

// The hanging sheet (0.2 m × 0.2 m × 1 mm, ρ = 1000, a 5 % strain limit) hangs from its top
// edge: at equilibrium the edge carries the sheet's weight ρ h A g, computed here from the
// scene's numbers rather than from the lumped masses. The strain-limit barrier holds the top
// rows, so the reaction includes barrier forces.
TEST(Probes, APinnedEdgeCarriesTheWeightOfAHangingSheet) {
  Scene scene = test::library_scene("hanging_sheet");
  scene.shells[0].probes.push_back({.name = "top_force", .kind = ProbeKind::reaction, .pin = "top"});
  QuasistaticSimulation sim(scene);
  FrameRecord last;
  while (sim.frame() < sim.frame_count()) last = sim.step();
  ASSERT_TRUE(last.newton.converged);
  const Material& m = scene.shells[0].material;
  const double weight = m.density * m.thickness * 0.2 * 0.2 * 9.81;
  const Eigen::Vector3d reaction = reading(last, "top_force").value;
  EXPECT_NEAR(reaction.z(), -weight, 1e-4 * weight) << reaction.transpose();
  EXPECT_NEAR(reaction.x(), 0.0, 1e-4 * weight);
  EXPECT_NEAR(reaction.y(), 0.0, 1e-4 * weight);
}

/// The cantilever strip of jobs/scenes (a 1 mN line load at its free end) with the load scaled
/// by keyframes, solved to a tight tolerance, with a reaction probe on its clamp and a
/// displacement probe on its tip.
Scene keyframed_cantilever() {
  Scene scene = test::library_scene("cantilever");
  scene.time = {.step = 0.04, .frames = 4};
  scene.solver.tolerance = 1e-6;  // ‖d‖∞ < 4e-8 m against a 0.7 mm deflection
  // Frames at t = 0.04, 0.08, 0.12, 0.16: s = 0.5, 1, 0.75, 0.5.
  scene.load_scale.keyframes = {{0.0, 0.0}, {0.08, 1.0}, {0.16, 0.5}};
  Probe tip{.name = "tip", .kind = ProbeKind::displacement};
  tip.selector.box_min = {0.099, -0.011, -0.001};
  tip.selector.box_max = {0.101, 0.011, 0.001};
  scene.shells[0].probes = {tip, {.name = "clamp_force", .kind = ProbeKind::reaction,
                                  .pin = "clamp"}};
  return scene;
}

TEST(Probes, AClampCarriesTheKeyframedTipLoadAtEveryFrame) {
  QuasistaticSimulation sim(keyframed_cantilever());
  const double expected_scale[] = {0.5, 1.0, 0.75, 0.5};
  const double force = 1e-3;  // the scene's total line load [N], along −z
  for (double s : expected_scale) {
    const FrameRecord record = sim.step();
    SCOPED_TRACE(record.frame);
    ASSERT_TRUE(record.newton.converged);
    EXPECT_NEAR(record.load_scale, s, 1e-12);
    EXPECT_NEAR(sim.system().external_force().sum(), -s * force, 1e-15);
    const Eigen::Vector3d reaction = reading(record, "clamp_force").value;
    EXPECT_NEAR(reaction.z(), -s * force, 1e-4 * force) << reaction.transpose();
    EXPECT_NEAR(reaction.x(), 0.0, 1e-4 * force);
    EXPECT_NEAR(reaction.y(), 0.0, 1e-4 * force);
  }
}

TEST(Probes, ADisplacementProbeIsTheMeanDisplacementOfItsVertices) {
  QuasistaticSimulation sim(keyframed_cantilever());
  const FrameRecord record = sim.step();
  const TriMesh& rest = sim.system().rest_mesh();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int v = 0; v < rest.vertex_count(); ++v)
    if (rest.vertices(v, 0) > 0.1 - 1e-9) {
      sum += sim.positions().segment<3>(3 * v) - rest.vertices.row(v).transpose();
      ++count;
    }
  ASSERT_EQ(count, 5);  // the tip column of the 0.02 m wide strip at 5 mm cells
  const Eigen::Vector3d tip = reading(record, "tip").value;
  EXPECT_LT((tip - sum / count).norm(), 1e-15) << tip.transpose();
  EXPECT_LT(tip.z(), 0.0);  // it bends down, under the load
  EXPECT_EQ(reading(record, "tip").kind, ProbeKind::displacement);
}

TEST(Probes, APinWhoseComponentsEarlierPinsAllFixHasNoReactionAndIsRefused) {
  Scene scene = keyframed_cantilever();
  PinnedSet shadow = scene.shells[0].pins.at(0);  // the clamp again: every component is taken
  shadow.name = "shadow";
  scene.shells[0].pins.push_back(shadow);
  scene.shells[0].probes = {{.name = "shadow_force", .kind = ProbeKind::reaction, .pin = "shadow"}};
  try {
    QuasistaticSimulation sim(scene);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("probe 'shadow_force' of shell 'strip'"), std::string::npos) << message;
    EXPECT_NE(message.find("probe the pin that fixes them"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace psq
