// The strain-limit correction of a refinement's initializer (paper §4.4.5): its objective's
// derivatives against finite differences, the correction itself on stretched sheets, and the
// strain-limited hanging sheet run progressively, every state of every level strictly within
// the limit, against the direct solve.

#include <gtest/gtest.h>

#include <iostream>
#include <string>

#include "engine/core/error.hpp"
#include "engine/progressive/progressive_simulation.hpp"
#include "engine/progressive/strain_limit_correction.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "engine/sim/strain_limit_term.hpp"
#include "progressive/reference_runs.hpp"
#include "support/derivative_check.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// A 0.1 m structured sheet (2 cm edges, 6 × 6 vertices) with a 5 % strain limit, its top edge
/// pinned.
constexpr const char* kSheet = R"(
name = "limited_sheet"
[time]
step = 0.04
frames = 1
[[shell]]
name = "sheet"
mesh = { generator = "sheet", width = 0.1, height = 0.1, edge_length = 0.02, structured = true }
material = { youngs_modulus = 1e4, poisson_ratio = 0.3, density = 1000, thickness = 1e-3, strain_limit = 1.05 }
[[shell.pin]]
name = "top"
box = { min = [-0.051, 0.049, -0.001], max = [0.051, 0.051, 0.001] }
)";

constexpr double kLimit = 1.05;

Scene sheet_scene(const std::string& text = kSheet) {
  return read_scene_text(text, "limited_sheet.toml");
}

/// The smallest slack s̄ − σ₁ of the system's limited triangles at x.
double min_slack(const ShellSystem& system, const Eigen::VectorXd& x) {
  const StrainLimitTerm term(system);
  double slack = std::numeric_limits<double>::infinity();
  for (const StrainLimitEnergy& energy : term.energies()) slack = std::min(slack, energy.min_slack(x));
  return slack;
}

/// The rest state stretched by `factor` along x about the sheet's centre.
Eigen::VectorXd stretched(const ShellSystem& system, double factor) {
  Positions p = system.rest_mesh().vertices;
  p.col(0) *= factor;
  return flat(p);
}

/// Interior vertices of the structured 6 × 6 sheet at even grid positions: no two share a
/// triangle, so each can be put back alone.
std::vector<bool> isolated_interior_vertices(const ShellSystem& system) {
  const Positions& p = system.rest_mesh().vertices;
  std::vector<bool> marked(p.rows(), false);
  for (int v = 0; v < p.rows(); ++v) {
    const long i = std::lround((p(v, 0) + 0.05) / 0.02);
    const long j = std::lround((p(v, 1) + 0.05) / 0.02);
    marked[v] = i > 0 && i < 5 && j > 0 && j < 5 && i % 2 == 0 && j % 2 == 0;
  }
  return marked;
}

TEST(StretchExcess, GradientMatchesFiniteDifferences) {
  const ShellSystem system(sheet_scene());
  const Eigen::VectorXd start = flat(system.rest_mesh().vertices);
  StretchExcess excess(system, start, nullptr);
  Eigen::VectorXd x = stretched(system, 1.07);
  std::srand(3);
  x += 2e-3 * Eigen::VectorXd::Random(x.size());
  ASSERT_FALSE(excess.tightest(x).acceptable);
  Eigen::VectorXd analytic;
  excess.gradient(x, analytic);
  const Eigen::VectorXd numeric =
      test::fd_gradient([&](const Eigen::VectorXd& y) { return excess.value(y); }, x, 1e-7);
  EXPECT_LT(test::relative_error(analytic, numeric), 1e-6);
}

TEST(StretchExcess, HessianIsTheGaussNewtonPartOfTheFiniteDifferenceHessian) {
  // Just above s_c = s̄ − 0.2δ = 1.04 the excess e is 1e-6, so the dropped term 2Ā e ∇²σ₁ is a
  // millionth of the Gauss–Newton one and the finite-difference Hessian must match it.
  const ShellSystem system(sheet_scene());
  StretchExcess excess(system, flat(system.rest_mesh().vertices), nullptr);
  Eigen::VectorXd x = stretched(system, 1.04 + 2e-6);
  std::srand(5);
  x += 1e-8 * Eigen::VectorXd::Random(x.size());
  HessianBlocks H;
  excess.hessian(x, H);
  ASSERT_EQ(H.batches.size(), 1u);
  ASSERT_GT(H.batches[0].element_count(), 0u);
  Eigen::MatrixXd analytic = test::dense_hessian(H.batches[0], x.size());
  analytic.diagonal() += H.diagonal;
  const Eigen::MatrixXd numeric = test::fd_jacobian(
      [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
        Eigen::VectorXd g;
        excess.gradient(y, g);
        return g;
      },
      x, 1e-10);
  EXPECT_LT(test::relative_error(analytic, numeric), 1e-3);
}

TEST(StrainLimitCorrection, MovesOnlyTheInsertedVerticesBelowTheLimit) {
  const ShellSystem system(sheet_scene());
  const std::vector<bool> inserted = isolated_interior_vertices(system);
  Eigen::VectorXd x = flat(system.rest_mesh().vertices);
  std::srand(11);
  int moved = 0;
  for (std::size_t v = 0; v < inserted.size(); ++v)
    if (inserted[v]) {
      x.segment<3>(3 * v) += 6e-3 * Eigen::Vector3d::Random();  // 30 % of an edge
      ++moved;
    }
  ASSERT_EQ(moved, 4);
  const Eigen::VectorXd before = x;
  ASSERT_LT(min_slack(system, x), 0.0);
  const StrainCorrectionStats stats = correct_strain_limits(system, inserted, 1, x);
  std::cout << "correction: " << stats.iterations << " iterations, σ₁/s̄ " << stats.stretch_before
            << " -> " << stats.stretch_after << "\n";
  EXPECT_GT(stats.iterations, 0);
  EXPECT_FALSE(stats.freed_old_vertices);
  EXPECT_GT(stats.stretch_before, 1.0);
  // Every triangle keeps at least a tenth of the band (δ = 0.05) as slack.
  EXPECT_GE(min_slack(system, x), 0.1 * (kLimit - 1) * (1 - 1e-9));
  for (std::size_t v = 0; v < inserted.size(); ++v) {
    if (inserted[v]) continue;
    EXPECT_EQ((x.segment<3>(3 * v) - before.segment<3>(3 * v)).norm(), 0.0) << v;
  }
}

TEST(StrainLimitCorrection, LeavesAFeasibleStateAlone) {
  const ShellSystem system(sheet_scene());
  Eigen::VectorXd x = stretched(system, 1.02);
  const Eigen::VectorXd before = x;
  const StrainCorrectionStats stats =
      correct_strain_limits(system, isolated_interior_vertices(system), 1, x);
  EXPECT_EQ(stats.iterations, 0);
  EXPECT_EQ((x - before).norm(), 0.0);
}

TEST(StrainLimitCorrection, FreesTheOldVerticesWhenTheNewOnesCannotRestoreTheLimit) {
  // Stretched 8 % everywhere: triangles of old vertices only are beyond the limit, and only the
  // unpinned vertices moving together can bring them back.
  const ShellSystem system(sheet_scene());
  Eigen::VectorXd x = stretched(system, 1.08);
  system.apply_pins(x, 0.0);
  const StrainCorrectionStats stats =
      correct_strain_limits(system, isolated_interior_vertices(system), 1, x);
  EXPECT_TRUE(stats.freed_old_vertices);
  EXPECT_GE(min_slack(system, x), 0.1 * (kLimit - 1) * (1 - 1e-9));
  for (const PinnedVertex& pin : system.pinned())
    EXPECT_EQ((x.segment<3>(3 * pin.vertex) - pin.rest).norm(), 0.0);
}

TEST(StrainLimitCorrection, ThrowsNamingTheLevelAndShellWhenNothingCanMove) {
  std::string text = kSheet;
  // Every vertex pinned: the pinned stretch cannot be corrected.
  text.replace(text.find("[-0.051, 0.049, -0.001]"), 23, "[-0.2, -0.2, -0.001]   ");
  const ShellSystem system(sheet_scene(text));
  Eigen::VectorXd x = stretched(system, 1.08);
  try {
    correct_strain_limits(system, isolated_interior_vertices(system), 2, x);
    FAIL() << "an uncorrectable stretch was accepted";
  } catch (const NumericalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("level 2"), std::string::npos) << message;
    EXPECT_NE(message.find("shell 'sheet'"), std::string::npos) << message;
    EXPECT_NE(message.find("1.08"), std::string::npos) << message;
  }
}

TEST(ProgressiveStrainLimit, HangingSheetStaysWithinTheLimitAtEveryLevelAndMatchesTheDirectSolve) {
  const Scene scene = read_scene(test::source_dir() / "jobs/scenes/hanging_sheet.toml");
  ProgressiveSettings settings = ProgressiveSettings::from_scene(scene);
  settings.schedule.levels = 3;
  ProgressiveSimulation sim(scene, settings);
  std::size_t states = 0;
  double smallest_slack = std::numeric_limits<double>::infinity();
  const auto check = [&] {
    ++states;
    smallest_slack = std::min(smallest_slack, min_slack(sim.level_system(), sim.positions()));
  };
  check();
  test::run_to_end(sim, check);
  ASSERT_TRUE(sim.level_converged());
  ASSERT_EQ(sim.strain_corrections().size(), 2u);
  for (const StrainCorrectionStats& c : sim.strain_corrections())
    std::cout << "correction: " << c.iterations << " iterations, σ₁/s̄ " << c.stretch_before
              << " -> " << c.stretch_after << (c.freed_old_vertices ? " (old vertices freed)" : "")
              << "\n";
  std::cout << states << " states, smallest slack " << smallest_slack << "\n";
  EXPECT_GT(smallest_slack, 0.0);

  QuasistaticSimulation direct(scene);
  while (direct.frame() < direct.frame_count()) ASSERT_TRUE(direct.step().newton.converged);
  const double diagonal = bounding_box_diagonal(direct.system().rest_mesh().vertices);
  const double distance = test::max_vertex_distance(sim.positions(), direct.positions());
  std::cout << "hanging sheet: progressive vs direct " << distance / diagonal
            << " of the diagonal\n";
  EXPECT_LT(distance, 1e-3 * diagonal);
}

}  // namespace
}  // namespace psq
