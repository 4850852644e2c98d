// The published shell benchmarks (jobs/scenes/verification, docs/verification.md) at CI-sized
// meshes, both bending models. Each case asserts the relative error bench_verification
// measured at that mesh, within a band: the answer at a given mesh is deterministic up to the
// solver tolerance (changing the tolerance 100-fold moves it by less than 0.01 percentage
// points), so a move beyond the band is a change of the discretization, and
// docs/verification.md must be updated with it. Where the model meets the reference, the case
// also bounds the error against it, by the convergence the table shows; where it does not, the
// case records the known deficit (the docs say so) instead of hiding it behind a wide bound.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <optional>

#include "support/verification_benchmarks.hpp"

namespace psq {
namespace {

struct VerificationCase {
  const char* benchmark;
  BendingModel bending;
  double edge_length;
  double measured_error;  ///< bench_verification's relative error at this mesh
  /// |error| bound against the reference where the model meets it; none where it does not.
  std::optional<double> within;
};

/// For test listings: the benchmark, the model and the mesh.
void PrintTo(const VerificationCase& c, std::ostream* out) {
  *out << c.benchmark << (c.bending == BendingModel::hinge ? " hinge" : " midedge") << " edge "
       << c.edge_length;
}

/// Half a percentage point: far above the solver's effect, far below any model change.
constexpr double kBand = 0.005;

const VerificationCase kCases[] = {
    // Mid-edge converges at first order (−4.3, −2.3, −1.2, −0.6 % over the table's halvings).
    {"roll_up", BendingModel::midedge, 0.025, -0.0232, 0.03},
    // Hinges on the checkerboard strip: −19 to −20 % at every mesh (the strip's known 1.27×
    // compliance, docs/bending-calibration.md).
    {"roll_up", BendingModel::hinge, 0.025, -0.1977, std::nullopt},
    // Both models converge to a roof 22 % (hinge) and 25 % (mid-edge) too stiff.
    {"scordelis_lo", BendingModel::hinge, 1.25, -0.2346, std::nullopt},
    {"scordelis_lo", BendingModel::midedge, 1.25, -0.2636, std::nullopt},
    // Hinges converge to the reference (+14.3, +6.8, +2.9 % over the table): 8 % here.
    {"pinched_cylinder", BendingModel::hinge, 12.5, 0.0682, 0.08},
    // Mid-edge passes the reference between 25 and 12.5 and ends at −8.9 % at 6.25: the 5 %
    // met here is not a converged value (docs/verification.md).
    {"pinched_cylinder", BendingModel::midedge, 12.5, -0.0414, 0.05},
    // Both models converge (to 0.2 %) to a hemisphere about twice too stiff.
    {"pinched_hemisphere", BendingModel::hinge, 0.5, -0.5336, std::nullopt},
    {"pinched_hemisphere", BendingModel::midedge, 0.5, -0.4900, std::nullopt},
};

class Verification : public ::testing::TestWithParam<VerificationCase> {};

TEST_P(Verification, ErrorAtTheCiMeshIsTheTablesOne) {
  const VerificationCase& c = GetParam();
  const test::VerificationBenchmark& benchmark = test::verification_benchmark(c.benchmark);
  const test::VerificationRun run = test::run_verification(benchmark, c.bending, c.edge_length);
  ASSERT_TRUE(run.converged) << "a frame did not reach its static equilibrium";
  const double error = run.relative_error(benchmark);
  std::cout << c.benchmark << " (" << (c.bending == BendingModel::hinge ? "hinge" : "midedge")
            << ", edge " << c.edge_length << ", " << run.vertices << " vertices): " << run.value
            << " against " << benchmark.reference << ", error " << 100 * error << " %\n";
  EXPECT_NEAR(error, c.measured_error, kBand);
  if (c.within) {
    EXPECT_LT(std::abs(error), *c.within);
  }
}

INSTANTIATE_TEST_SUITE_P(
    PublishedShellBenchmarks, Verification, ::testing::ValuesIn(kCases),
    [](const ::testing::TestParamInfo<VerificationCase>& info) {
      return std::string(info.param.benchmark) +
             (info.param.bending == BendingModel::hinge ? "_hinge" : "_midedge");
    });

TEST(Verification, RollUpEndsOnTheCircle) {
  // The pin motions place the rigid end on the elastica's arc: at the last frame every free
  // vertex lies near the circle of radius L/(2π) through the clamp. The discrete shape
  // converges to it at first order, as the energy does: the largest radial deviation is 4.8 %
  // at this mesh and 2.4 % at edge 0.0125 (measured with psq sim on the scene).
  const test::VerificationBenchmark& roll = test::verification_benchmark("roll_up");
  QuasistaticSimulation sim(test::verification_scene(roll, BendingModel::midedge, 0.025));
  while (sim.frame() < sim.frame_count()) ASSERT_TRUE(sim.step().newton.converged);
  const double radius = 1.0 / (2 * M_PI);
  const Eigen::Vector2d center(-0.5, radius);  // (x, z)
  const TriMesh& rest = sim.system().rest_mesh();
  for (int v = 0; v < rest.vertex_count(); ++v) {
    if (std::abs(rest.vertices(v, 0)) > 0.5) continue;  // the clamp and the rigid end
    const Eigen::Vector3d p = sim.positions().segment<3>(3 * v);
    const double r = (Eigen::Vector2d(p.x(), p.z()) - center).norm();
    EXPECT_NEAR(r / radius, 1.0, 0.06) << "vertex " << v;
    EXPECT_NEAR(p.y(), rest.vertices(v, 1), 0.01 * radius) << "vertex " << v;
  }
}

}  // namespace
}  // namespace psq
