// Pins of chosen components in a progressive solve: every coarse level holds each pinned vertex
// by exactly the components the finest mesh holds it by (a vertex two sets share included), its
// fixed components at their scripted values and its free ones moving.

#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include "engine/progressive/progressive_simulation.hpp"
#include "engine/scene/scene_reader.hpp"

namespace psq {
namespace {

// A 1 × 0.5 m Delaunay sheet clamped along x = −0.5, its edge x = +0.5 lifted by 0.1 m in z
// only, its edge y = −0.25 on a roller normal to y. The corner (0.5, −0.25) is held in y by
// the roller and in z by the lift: a condition of its own.
constexpr const char* kScene = R"(
[time]
step = 0.05
frames = 2
[hierarchy]
levels = 3

[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 1, height = 0.5, edge_length = 0.04 }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 200, thickness = 2e-3 }

[[shell.pin]]
name = "clamp"
box = { min = [-0.5, -0.25, 0], max = [-0.5, 0.25, 0] }

[[shell.pin]]
name = "roller"
box = { min = [-0.5, -0.25, 0], max = [0.5, -0.25, 0] }
components = ["y"]

[[shell.pin]]
name = "lift"
box = { min = [0.5, -0.25, 0], max = [0.5, 0.25, 0] }
components = ["z"]
[[shell.pin.motion]]
end = 0.1
translation = [0, 0, 0.1]
)";

using Point = std::tuple<double, double, double>;

/// Per pinned vertex of `system`, keyed by its rest position: which components it fixes.
std::map<Point, PinComponents> pinned_components(const ShellSystem& system) {
  std::map<Point, PinComponents> out;
  for (const PinnedVertex& p : system.pinned())
    out[{p.rest.x(), p.rest.y(), p.rest.z()}] = {p.fixes(0), p.fixes(1), p.fixes(2)};
  return out;
}

/// Checks the level's state: the fixed components at their scripted values, exactly.
void expect_pins_held(const ShellSystem& system, const Eigen::VectorXd& x, double time) {
  Eigen::VectorXd scripted = x;
  system.apply_pins(scripted, time);
  EXPECT_EQ(scripted, x);
}

TEST(ProgressiveComponentPins, EveryLevelHoldsTheFinestConditions) {
  const Scene scene = read_scene_text(kScene, "component_pins.toml");
  ProgressiveSimulation sim(scene, ProgressiveSettings::from_scene(scene));
  ASSERT_EQ(sim.level_count(), 3);
  const std::map<Point, PinComponents> finest = pinned_components(sim.finest_system());
  const PinComponents corner{false, true, true};
  // The clamp fixes all of its corner with the roller: only the lifted corner is shared.
  ASSERT_EQ(sim.finest_system().shared_pins(0).size(), 1u);

  for (int level = 0;; ++level) {
    SCOPED_TRACE(level);
    const ShellSystem& system = sim.level_system();
    const std::map<Point, PinComponents> here = pinned_components(system);
    int corners = 0;
    for (const auto& [point, fixed] : here) {
      const auto it = finest.find(point);
      ASSERT_NE(it, finest.end()) << "a coarse pinned vertex is not at a finest pinned vertex";
      EXPECT_EQ(fixed, it->second);
      if (fixed == corner) ++corners;
    }
    EXPECT_EQ(corners, 1);
    while (!sim.level_done()) sim.step();
    ASSERT_TRUE(sim.level_converged());
    const Eigen::VectorXd& x = sim.positions();
    expect_pins_held(system, x, scene.time.frames * scene.time.step);
    // The lifted edge hangs free in x: the sheet bent up by 0.1 m pulls it in.
    double lifted_x = 0.0;
    for (const PinnedVertex& p : system.pinned())
      if (p.rest.x() > 0.5 - 1e-12)
        lifted_x = std::max(lifted_x, x[3 * p.vertex]);
    EXPECT_LT(lifted_x, 0.5 - 1e-3);
    if (sim.finished()) break;
    sim.refine();
  }
}

}  // namespace
}  // namespace psq
