// Pins that fix chosen Cartesian components (`components` of [[shell.pin]]): which DOFs the
// system fixes, the rule for a vertex several sets pin, that a solve moves the free components
// and holds the fixed ones exactly, and that a half model with a symmetry-plane pin reproduces
// the full model.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <iostream>
#include <string>

#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "engine/sim/shell_system.hpp"

namespace psq {
namespace {

/// A 1 × 1 structured sheet of 2 × 2 cells (vertex (i, j) is 3 j + i at x = −0.5 + i/2,
/// y = −0.5 + j/2) with two pinned sets: the column x = −0.5 in z only, moving by
/// (1, 2, 3); the row y = −0.5 in x and z, moving by (10, 20, 30). They share vertex 0.
constexpr const char* kTwoSets = R"(
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 1, height = 1, edge_length = 0.5, structured = true }
material = { youngs_modulus = 1e6, poisson_ratio = 0.3, density = 100, thickness = 1e-3 }

[[shell.pin]]
name = "column"
box = { min = [-0.5, -0.5, 0], max = [-0.5, 0.5, 0] }
components = ["z"]
[[shell.pin.motion]]
translation = [1, 2, 3]

[[shell.pin]]
name = "row"
box = { min = [-0.5, -0.5, 0], max = [0.5, -0.5, 0] }
components = ["x", "z"]
[[shell.pin.motion]]
translation = [10, 20, 30]
)";

/// `text` with every `marker` replaced by `value`.
std::string replaced(std::string text, const std::string& marker, const std::string& value) {
  for (auto at = text.find(marker); at != std::string::npos; at = text.find(marker, at))
    text.replace(at, marker.size(), value);
  return text;
}

/// Per vertex, which components `system` fixes (all false for a free vertex).
std::vector<PinComponents> fixed_components(const ShellSystem& system) {
  const std::vector<bool> fixed = system.fixed_dofs();
  std::vector<PinComponents> out(fixed.size() / 3);
  for (std::size_t v = 0; v < out.size(); ++v)
    out[v] = {fixed[3 * v], fixed[3 * v + 1], fixed[3 * v + 2]};
  return out;
}

TEST(ComponentPins, SharedVertexFixesTheUnionEachComponentByTheFirstSetFixingIt) {
  const ShellSystem system(read_scene_text(kTwoSets, "two_sets.toml"));
  const std::vector<PinComponents> fixed = fixed_components(system);
  const PinComponents none{false, false, false}, z{false, false, true}, xz{true, false, true};
  EXPECT_EQ(fixed, (std::vector<PinComponents>{xz, xz, xz, z, none, none, z, none, none}));

  // Groups: the column's own vertices 0 ("column"), the row's 1 ("row"), vertex 0 a shared
  // condition (x from the row, z from the column), numbered after the two sets.
  EXPECT_EQ(system.pin_groups(0), (std::vector<int>{2, 1, 1, 0, -1, -1, 0, -1, -1}));
  ASSERT_EQ(system.shared_pins(0).size(), 1u);
  EXPECT_EQ(system.shared_pins(0)[0], (PinSources{1, -1, 0}));

  Eigen::VectorXd x = flat(system.rest_mesh().vertices);
  const Eigen::VectorXd rest = x;
  x.array() += 0.25;  // free components keep whatever they hold
  system.apply_pins(x, 1.0);
  const auto moved = [&](int v) {
    return Eigen::Vector3d(x.segment<3>(3 * v) - rest.segment<3>(3 * v));
  };
  const auto expect_moved = [&](int v, const Eigen::Vector3d& expected) {
    EXPECT_LT((moved(v) - expected).norm(), 1e-12) << "vertex " << v << ": " << moved(v).transpose();
  };
  expect_moved(0, {10, 0.25, 3});  // x by the row, z by the column
  expect_moved(1, {10, 0.25, 30});
  expect_moved(3, {0.25, 0.25, 3});
  expect_moved(4, {0.25, 0.25, 0.25});
}

TEST(ComponentPins, LevelSystemRebuildsEveryConditionFromItsGroups) {
  const ShellSystem finest(read_scene_text(kTwoSets, "two_sets.toml"));
  const ShellSystem level(finest.scene(), {{finest.shell_rest_mesh(0), finest.pin_groups(0),
                                            finest.shared_pins(0)}});
  EXPECT_EQ(fixed_components(level), fixed_components(finest));
  Eigen::VectorXd a = Eigen::VectorXd::Zero(27), b = a;
  finest.apply_pins(a, 0.5);
  level.apply_pins(b, 0.5);
  EXPECT_EQ(a, b);
  EXPECT_THROW(ShellSystem(finest.scene(), {{finest.shell_rest_mesh(0), finest.pin_groups(0), {}}}),
               std::invalid_argument);  // group 2 needs its shared condition
}

/// A 1 × 0.4 m strip of 5 mm plastic sheet (structured, 20 × 8 cells), clamped along
/// x = −0.5; the edge x = +0.5 is lifted by 0.2 m with only its z prescribed (a roller on a
/// vertical wall that rises). The sliding end makes the solve nearly inextensible bending,
/// which Newton resolves to about 1e-6 m/s here; 1e-5 keeps it clear of round-off.
constexpr const char* kLiftedStrip = R"(
[time]
step = 0.04
frames = 2
[solver]
tolerance = 1e-5

[[shell]]
name = "strip"
mesh = { generator = "sheet", width = 1, height = 0.4, edge_length = 0.05, structured = true }
material = { youngs_modulus = 1e8, poisson_ratio = 0.3, density = 500, thickness = 5e-3 }
bending = "@BENDING@"

[[shell.pin]]
name = "clamp"
box = { min = [-0.5, -0.2, 0], max = [-0.45, 0.2, 0] }

[[shell.pin]]
name = "lift"
box = { min = [0.5, -0.2, 0], max = [0.5, 0.2, 0] }
components = ["z"]
[[shell.pin.motion]]
end = 0.08
translation = [0, 0, 0.2]
)";

TEST(ComponentPins, ZOnlyPinSlidesInXAndHoldsZExactly) {
  for (const char* bending : {"hinge", "midedge"}) {
    SCOPED_TRACE(bending);
    QuasistaticSimulation sim(
        read_scene_text(replaced(kLiftedStrip, "@BENDING@", bending), "lifted.toml"));
    for (int f = 0; f < sim.frame_count(); ++f) ASSERT_TRUE(sim.step().newton.converged);
    const TriMesh& rest = sim.system().rest_mesh();
    const Eigen::VectorXd& x = sim.positions();
    int lifted = 0;
    for (int v = 0; v < rest.vertex_count(); ++v) {
      if (rest.vertices(v, 0) < 0.5 - 1e-12) continue;
      ++lifted;
      EXPECT_EQ(x[3 * v + 2], 0.2) << "vertex " << v;  // prescribed: exact
      // A nearly inextensible strip bent up by 0.2 over 0.95 m pulls its end in by ~2 cm.
      EXPECT_LT(x[3 * v], 0.5 - 0.005) << "vertex " << v;
    }
    EXPECT_EQ(lifted, 9);
  }
}

/// An in-plane problem, symmetric about y = 0: a 1 × 0.8 m sheet clamped along x = −0.5 and
/// pulled by a line load along x = +0.5 (@FORCE@ N); @MESH@ stands for the mesh and more pins.
constexpr const char* kPulledSheet = R"(
[time]
step = 0.04
frames = 1
[solver]
tolerance = 1e-9

[[shell]]
name = "sheet"
material = { youngs_modulus = 1e5, poisson_ratio = 0.4, density = 100, thickness = 1e-3 }
@MESH@
[[shell.pin]]
name = "clamp"
box = { min = [-0.5, -0.4, 0], max = [-0.5, 0.4, 0] }

[[shell.load]]
kind = "line"
box = { min = [0.5, -0.4, 0], max = [0.5, 0.4, 0] }
force = [@FORCE@, 0, 0]
)";

// The full sheet's mesh (16 × 16 cells, checkerboard diagonals) is mirror-symmetric about
// y = 0 because its cell rows are even in number, and its upper half is cell for cell the half
// model's mesh (8 rows, an even number, so the checkerboard phase agrees). In-plane, a symmetry
// plane normal to y asks exactly u_y = 0 there (the shear traction vanishes naturally), so the
// half model with y pinned on its cut is the full model's upper half, not an approximation of
// it: the two agree to the solver tolerance.
TEST(ComponentPins, HalfModelWithSymmetryPlanePinMatchesTheFullModel) {
  constexpr double kForce = 2.0;  // N on the full edge: 25 N/m, a 2.5 % stretch
  const auto scene = [](const std::string& mesh, double force, const char* name) {
    return read_scene_text(
        replaced(replaced(kPulledSheet, "@MESH@", mesh), "@FORCE@", fmt::format("{}", force)),
        name);
  };
  const Scene full = scene(
      R"(mesh = { generator = "sheet", width = 1, height = 0.8, edge_length = 0.05, structured = true })",
      kForce, "full.toml");
  // The half model's cut y = 0 carries half of the full edge's load at its end vertex, as a
  // line load does on its own: the full model's energy is twice the half model's.
  const Scene half = scene(
      R"(mesh = { generator = "sheet", width = 1, height = 0.4, edge_length = 0.05, structured = true }
placement = { translation = [0, 0.2, 0] }
[[shell.pin]]
name = "symmetry"
box = { min = [-0.5, 0, 0], max = [0.5, 0, 0] }
components = ["y"])",
      kForce / 2, "half.toml");
  QuasistaticSimulation full_sim(full), half_sim(half);
  ASSERT_TRUE(full_sim.step().newton.converged);
  ASSERT_TRUE(half_sim.step().newton.converged);

  const TriMesh& full_rest = full_sim.system().rest_mesh();
  const TriMesh& half_rest = half_sim.system().rest_mesh();
  ASSERT_EQ(half_rest.vertex_count(), 21 * 9);
  double largest_move = 0.0, largest_gap = 0.0;
  for (int h = 0; h < half_rest.vertex_count(); ++h) {
    int match = -1;
    for (int f = 0; f < full_rest.vertex_count(); ++f)
      if ((full_rest.vertices.row(f) - half_rest.vertices.row(h)).norm() < 1e-9) match = f;
    ASSERT_GE(match, 0) << "half-model vertex " << h << " is not a full-model vertex";
    const Eigen::Vector3d u_half = half_sim.positions().segment<3>(3 * h) -
                                   half_rest.vertices.row(h).transpose();
    const Eigen::Vector3d u_full = full_sim.positions().segment<3>(3 * match) -
                                   full_rest.vertices.row(match).transpose();
    largest_move = std::max(largest_move, u_full.norm());
    largest_gap = std::max(largest_gap, (u_half - u_full).norm());
  }
  std::cout << "half against full model: largest displacement " << largest_move
            << " m, largest difference " << largest_gap << " m\n";
  EXPECT_GT(largest_move, 0.01);  // the load does stretch the sheet by centimetres
  // Both solves stop within ‖Δx‖∞ < tolerance·Δt = 4e-11 m of their common discrete answer
  // (measured: 2e-16 m, Newton's last step is quadratic).
  EXPECT_LT(largest_gap, 1e-10);
}

}  // namespace
}  // namespace psq
