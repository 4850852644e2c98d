// The hanging sheet of jobs/scenes (a soft membrane under its own heavy weight, pinned along
// its top edge) with and without its 5 % strain limit. The principal stretches are computed
// here from the rest and deformed triangles alone, independently of the engine's kernels.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <iostream>

#include "engine/core/error.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "support/library_scene.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

/// The largest singular value σ₁ over all triangles of F = Ds B⁻¹, where Ds holds a
/// triangle's deformed edge vectors and B its rest edge vectors in an orthonormal basis of the
/// rest triangle's plane.
double largest_principal_stretch(const TriMesh& rest, const Eigen::VectorXd& x) {
  const auto deformed = as_positions(x);
  double largest = 0;
  for (int t = 0; t < rest.triangle_count(); ++t) {
    const auto tri = rest.triangles.row(t);
    Eigen::Matrix<double, 3, 2> rest_edges, deformed_edges;
    for (int k = 0; k < 2; ++k) {
      rest_edges.col(k) = (rest.vertices.row(tri[k + 1]) - rest.vertices.row(tri[0])).transpose();
      deformed_edges.col(k) = (deformed.row(tri[k + 1]) - deformed.row(tri[0])).transpose();
    }
    const Eigen::HouseholderQR<Eigen::Matrix<double, 3, 2>> qr(rest_edges);
    const Eigen::Matrix<double, 3, 2> basis =
        qr.householderQ() * Eigen::Matrix<double, 3, 2>::Identity();
    const Eigen::Matrix2d in_plane = basis.transpose() * rest_edges;
    const Eigen::Matrix<double, 3, 2> F = deformed_edges * in_plane.inverse();
    largest =
        std::max(largest, Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(F).singularValues()[0]);
  }
  return largest;
}

Scene hanging_sheet() { return test::library_scene("hanging_sheet"); }

/// A run of every frame, with σ₁ checked at each stored frame and each accepted Newton iterate.
struct HangingRun {
  Eigen::VectorXd final_positions;
  double largest_frame_stretch = 0;
  double largest_iterate_stretch = 0;
  int iterates = 0;
  bool converged = true;
  double final_gradient_norm = 0;  ///< of the free DOFs, at the last frame's result
  double weight = 0;               ///< ‖external force‖, the gradient's scale
  double final_stiffness = 0;      ///< κ_s at the end (0 without a limit)
};

HangingRun simulate(const Scene& scene) {
  QuasistaticSimulation sim(scene);
  const TriMesh& rest = sim.system().rest_mesh();
  HangingRun run;
  // Newton calls this after each line search: positions() is the iterate it accepted.
  const QuasistaticSimulation::Progress check_iterate = [&](int, const NewtonIteration&) {
    run.largest_iterate_stretch =
        std::max(run.largest_iterate_stretch, largest_principal_stretch(rest, sim.positions()));
    ++run.iterates;
  };
  while (sim.frame() < sim.frame_count()) {
    const FrameRecord record = sim.step(check_iterate);
    run.converged = record.newton.converged && run.converged;
    run.final_gradient_norm = record.newton.gradient_norm;
    run.largest_frame_stretch =
        std::max(run.largest_frame_stretch, largest_principal_stretch(rest, sim.positions()));
  }
  run.final_positions = sim.positions();
  run.weight = sim.system().external_force().norm();
  if (sim.strain_limit()) run.final_stiffness = sim.strain_limit()->energies()[0].stiffness();
  return run;
}

TEST(StrainLimitScene, HangingSheetStaysBelowItsLimitWhereTheFreeSheetStretchesFar) {
  const Scene limited = hanging_sheet();
  ASSERT_TRUE(limited.shells[0].strain_limit.has_value());
  const double limit = limited.shells[0].strain_limit->limit;
  ASSERT_EQ(limit, 1.05);
  Scene free = limited;
  free.shells[0].strain_limit.reset();
  ASSERT_EQ(QuasistaticSimulation(free).strain_limit(), nullptr);  // no limit, no term

  const HangingRun free_run = simulate(free);
  const HangingRun limited_run = simulate(limited);
  std::cout << fmt::format(
      "hanging sheet: largest σ₁ free {:.4f}; limited {:.6f} (frames), {:.6f} (all {} "
      "iterates); final ‖g‖ {:.2e} of weight {:.2e} N; κ_s at the end {:.4g} N/m; largest "
      "displacement between them {:.2f} mm\n",
      free_run.largest_frame_stretch, limited_run.largest_frame_stretch,
      limited_run.largest_iterate_stretch, limited_run.iterates, limited_run.final_gradient_norm,
      limited_run.weight, limited_run.final_stiffness,
      1e3 * (limited_run.final_positions - free_run.final_positions).lpNorm<Eigen::Infinity>());

  EXPECT_TRUE(free_run.converged);
  EXPECT_GT(free_run.largest_frame_stretch, 1.1);

  EXPECT_TRUE(limited_run.converged);
  // Converged by balancing the forces, not by Newton steps shrinking against the barrier.
  EXPECT_LT(limited_run.final_gradient_norm, 1e-4 * limited_run.weight);
  EXPECT_GT(limited_run.iterates, 0);
  EXPECT_LT(limited_run.largest_iterate_stretch, limit);
  EXPECT_LT(limited_run.largest_frame_stretch, limit);
  // The barrier acts only in the band (1, 1.05): the sheet is pulled well into it, not held
  // near its rest length.
  EXPECT_GT(limited_run.largest_frame_stretch, 1.03);
  // Capping the stretch shortens the sheet by centimetres (the free one sags far lower).
  EXPECT_GT((limited_run.final_positions - free_run.final_positions).lpNorm<Eigen::Infinity>(),
            5e-3);
}

TEST(StrainLimitScene, ARestoredStateBeyondTheLimitIsAnInputErrorNamingTheShell) {
  QuasistaticSimulation sim(hanging_sheet());
  Eigen::VectorXd stretched = sim.positions();
  stretched *= 1.1;  // every triangle at σ₁ = σ₂ = 1.1
  try {
    sim.restore(1, stretched, sim.positions());
    FAIL() << "no error for a state stretched 10 %";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("shell 'sheet'"), std::string::npos) << message;
    EXPECT_NE(message.find("1.1"), std::string::npos) << message;
    EXPECT_NE(message.find("strain_limit 1.05"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace psq
