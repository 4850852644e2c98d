// Contact in the quasistatic simulation: no accepted Newton iterate intersects (head-on
// collision, a collider driven into a pinned sheet), a frame's predicted start stays
// intersection-free, scripted motion reaches its targets, and the contact surface pairs the
// bodies as documented.

#include <gtest/gtest.h>

#include <algorithm>

#include "engine/contact/intersection_check.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/sim/frame_solver.hpp"
#include "engine/sim/incremental_potential.hpp"
#include "engine/sim/shell_system.hpp"
#include "engine/sim/quasistatic.hpp"

namespace psq {
namespace {

Shell square_sheet(const std::string& name, double width, double edge, double z) {
  Shell shell;
  shell.name = name;
  shell.mesh.kind = MeshSource::Kind::Sheet;
  shell.mesh.sheet.width = shell.mesh.sheet.height = width;
  shell.mesh.sheet.edge_length = edge;
  shell.mesh.sheet.structured = true;
  shell.mesh.translation = {0, 0, z};
  shell.material = {1e6, 0.3, 1000.0, 1e-3};
  return shell;
}

VertexSelector box(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  VertexSelector selector;
  selector.kind = VertexSelector::Kind::Box;
  selector.box_min = min;
  selector.box_max = max;
  return selector;
}

/// Whether the current state of a simulation is free of intersections (exact check).
bool intersection_free(const QuasistaticSimulation& sim) {
  return find_intersections(as_positions(sim.positions()), sim.system().rest_mesh().triangles)
      .clean();
}

/// A small pad 5 mm above a fixed floor, driven into it by a load far beyond what the pad's
/// inertia term balances within one step: without the CCD the first step would pass through.
Scene head_on_scene() {
  Scene scene;
  scene.source = "head-on-test";
  scene.time = {0.04, 3};
  Shell floor = square_sheet("floor", 0.1, 0.02, 0.0);
  floor.pins.push_back({"all", box({-1, -1, -1}, {1, 1, 1}), {}});
  Shell pad = square_sheet("pad", 0.05, 0.0125, 0.005);
  pad.mesh.translation = {0.003, 0.002, 0.005};
  Load push;
  push.selector = box({-1, -1, -1}, {1, 1, 1});
  push.total_force = {0, 0, -50.0};
  pad.loads.push_back(push);
  scene.shells = {floor, pad};
  scene.contact.activation_distance = 1e-3;
  return scene;
}

TEST(ContactSimulation, HeadOnCollisionNeverAcceptsAnIntersectingState) {
  QuasistaticSimulation sim(head_on_scene());
  int checked = 0, intersecting = 0;
  const auto check = [&](int, const NewtonIteration&) {
    ++checked;
    intersecting += !intersection_free(sim);
  };
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step(check);
    EXPECT_TRUE(record.newton.converged) << "frame " << record.frame;
  }
  EXPECT_FALSE(sim.contact()->potential().active_pairs(sim.positions()).empty());
  EXPECT_GT(checked, 3);
  EXPECT_EQ(intersecting, 0);
  // The pad rests on the floor: above it, within the barrier's reach.
  const ShellBlock& pad = sim.system().shells()[1];
  double lowest = 1.0;
  for (int v = pad.first_vertex; v < pad.first_vertex + pad.vertex_count; ++v)
    lowest = std::min(lowest, sim.positions()[3 * v + 2]);
  EXPECT_GT(lowest, 0.0);
  EXPECT_LT(lowest, 1e-3);
}

TEST(ContactSimulation, PredictionMovesTheFreeVerticesAsFarAsTheCcdAllows) {
  const Scene scene = head_on_scene();
  const ShellSystem system(scene);
  IncrementalPotential potential(system, scene.time.step);
  FrameSolver solver(system, potential);
  const Eigen::VectorXd rest = flat(system.rest_mesh().vertices);
  const ShellBlock& floor = system.shells()[0];
  const ShellBlock& pad = system.shells()[1];
  const auto pad_lowest = [&](const Eigen::VectorXd& x) {
    double lowest = 1.0;
    for (int v = pad.first_vertex; v < pad.first_vertex + pad.vertex_count; ++v)
      lowest = std::min(lowest, x[3 * v + 2]);
    return lowest;
  };
  // Every vertex asked to move, the pinned floor too: only the free pad may follow.
  const auto shifted_by = [&](double dz) {
    Eigen::VectorXd motion = Eigen::VectorXd::Zero(rest.size());
    for (Eigen::Index i = 2; i < motion.size(); i += 3) motion[i] = dz;
    return motion;
  };

  // Up, away from the floor: safe, so the whole motion.
  Eigen::VectorXd x = rest;
  ASSERT_TRUE(solver.predict(x, shifted_by(2e-3)));
  EXPECT_NEAR(pad_lowest(x) - pad_lowest(rest), 2e-3, 1e-15);

  // Down 1 cm onto a floor 5 mm below: cut short of the floor by the CCD.
  x = rest;
  ASSERT_TRUE(solver.predict(x, shifted_by(-1e-2)));
  EXPECT_LT(pad_lowest(x), pad_lowest(rest) - 1e-3);
  EXPECT_GT(pad_lowest(x), 0.0);
  EXPECT_TRUE(
      find_intersections(as_positions(x), system.rest_mesh().triangles).clean());
  for (int v = floor.first_vertex; v < floor.first_vertex + floor.vertex_count; ++v)
    EXPECT_EQ(x.segment<3>(3 * v), rest.segment<3>(3 * v)) << "floor vertex " << v;

  // Nothing free to move: no prediction.
  x = rest;
  Eigen::VectorXd floor_only = Eigen::VectorXd::Zero(rest.size());
  floor_only.segment(3 * floor.first_vertex, 3 * floor.vertex_count).setConstant(1e-3);
  EXPECT_FALSE(solver.predict(x, floor_only));
  EXPECT_EQ(x, rest);
}

/// A sphere collider 5 mm above a sheet held at its rim, moving down 1 cm per frame.
Scene pressing_sphere_scene() {
  Scene scene;
  scene.source = "press-test";
  scene.time = {0.04, 3};
  Shell sheet = square_sheet("sheet", 0.2, 0.025, 0.0);
  VertexSelector rim;
  rim.kind = VertexSelector::Kind::BoundaryLoop;
  sheet.pins.push_back({"rim", rim, {}});
  scene.shells = {sheet};
  Collider ball;
  ball.name = "ball";
  ball.mesh.kind = MeshSource::Kind::Sphere;
  ball.mesh.sphere = {0.04, 0.02};
  ball.mesh.translation = {0.0, 0.0, 0.045};
  RigidMotion down;
  down.start_time = 0.0;
  down.end_time = 0.12;
  down.translation = {0, 0, -0.03};
  ball.motions.push_back(down);
  scene.colliders = {ball};
  scene.contact.activation_distance = 1e-3;
  return scene;
}

TEST(ContactSimulation, ColliderIsPulledIntoAPinnedSheetWithoutIntersecting) {
  QuasistaticSimulation sim(pressing_sphere_scene());
  ASSERT_EQ(sim.system().colliders().size(), 1u);
  int checked = 0, intersecting = 0;
  const auto check = [&](int, const NewtonIteration&) {
    ++checked;
    intersecting += !intersection_free(sim);
  };
  int pulled_frames = 0;
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step(check);
    EXPECT_TRUE(record.newton.converged) << "frame " << record.frame;
    EXPECT_TRUE(intersection_free(sim)) << "frame " << record.frame;
    pulled_frames += record.kinematic_rounds > 0;
    EXPECT_EQ(record.kinematic_offset, 0.0) << "frame " << record.frame;
  }
  EXPECT_GT(pulled_frames, 0);  // moving 1 cm toward a sheet 5 mm away is never safe directly
  EXPECT_GT(checked, 0);
  EXPECT_EQ(intersecting, 0);
  // The ball reached its target, 3 cm down, and the sheet went down with it.
  const ColliderBlock& ball = sim.system().colliders()[0];
  double ball_bottom = 1.0, ball_rest_bottom = 1.0;
  for (int v = ball.first_vertex; v < ball.first_vertex + ball.vertex_count; ++v) {
    ball_bottom = std::min(ball_bottom, sim.positions()[3 * v + 2]);
    ball_rest_bottom = std::min(ball_rest_bottom, sim.system().rest_mesh().vertices(v, 2));
  }
  EXPECT_NEAR(ball_bottom - ball_rest_bottom, -0.03, 1e-9);
  double sheet_bottom = 1.0;
  for (int v = 0; v < sim.system().shells()[0].vertex_count; ++v)
    sheet_bottom = std::min(sheet_bottom, sim.positions()[3 * v + 2]);
  EXPECT_LT(sheet_bottom, ball_bottom);
}

TEST(ContactSimulation, SurfacePairsShellsAndCollidersButNotCollidersWithEachOther) {
  Scene scene = pressing_sphere_scene();
  Collider second = scene.colliders[0];
  second.name = "second";
  second.mesh.translation = {0.0, 0.0, 0.2};
  scene.colliders.push_back(second);
  const ShellSystem system(scene);
  for (bool self_contact : {false, true}) {
    const ContactSurface surface = contact_surface(system, self_contact);
    ASSERT_EQ(surface.vertex_body.size(),
              static_cast<std::size_t>(system.rest_mesh().vertex_count()));
    EXPECT_EQ(surface.vertex_body.front(), 0);
    EXPECT_EQ(surface.vertex_body.back(), 2);
    EXPECT_EQ(surface.may_touch(0, 0), self_contact);
    EXPECT_TRUE(surface.may_touch(0, 1));
    EXPECT_TRUE(surface.may_touch(2, 0));
    EXPECT_FALSE(surface.may_touch(1, 2));
    EXPECT_FALSE(surface.may_touch(1, 1));
  }
}

TEST(ContactSimulation, ContactIsOnForSeveralBodiesOrSelfContactUnlessDisabled) {
  Scene scene = pressing_sphere_scene();
  EXPECT_TRUE(contact_enabled(scene));
  scene.contact.enabled = false;
  EXPECT_FALSE(contact_enabled(scene));
  scene.colliders.clear();
  scene.contact.enabled.reset();
  EXPECT_FALSE(contact_enabled(scene));
  scene.contact.self_contact = true;
  EXPECT_TRUE(contact_enabled(scene));
}

}  // namespace
}  // namespace psq
