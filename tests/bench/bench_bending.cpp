// Benchmark (prints, never fails on a slow machine): cost per element of the two bending
// models, hinge (BendingEnergy) and mid-edge (MidedgeBendingEnergy), on a bent Delaunay sheet:
// value + gradient + solver Hessian (Gauss–Newton blocks, as Newton asks for them), and the
// number of Hessian values each writes. Serial (one TBB thread) so that per-element figures do
// not depend on the core count.
//
// Usage: bench_bending [--vertices N] [--repeats R]

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bench/bench_options.hpp"
#include "engine/core/element_matrices.hpp"
#include "engine/elastic/bending.hpp"
#include "engine/elastic/midedge_bending.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"

namespace {

using Clock = std::chrono::steady_clock;

/// Seconds per call of value + add_gradient + hessian, the best of `repeats` runs.
template <class Energy>
double seconds_per_evaluation(const Energy& energy, const Eigen::VectorXd& x, int repeats,
                              std::size_t& hessian_values) {
  double best = INFINITY;
  psq::ElementMatrices blocks;
  for (int r = 0; r < repeats; ++r) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
    const auto start = Clock::now();
    const double value = energy.value(x);
    energy.add_gradient(x, g);
    energy.hessian(x, blocks, true);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
    if (!std::isfinite(value) || !g.allFinite()) throw std::runtime_error("non-finite result");
  }
  hessian_values = blocks.values.size();
  return best;
}

/// Prints the bending models' costs; the command line is read by run_benchmark.
int bench_bending(const psq::bench::BenchOptions& options) {
  const int vertices = options.integer("vertices"), repeats = options.integer("repeats");
  const tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
  psq::SheetGenerator spec;
  spec.edge_length = std::sqrt(2.0 / (std::sqrt(3.0) * vertices));
  const psq::TriMesh sheet = psq::make_sheet(spec);
  const psq::MeshTopology topology = psq::MeshTopology::build(sheet);
  const psq::Material material;
  // A gentle cylindrical bend, so that every element has a non-zero angle change.
  Eigen::VectorXd x(3 * sheet.vertex_count());
  for (int v = 0; v < sheet.vertex_count(); ++v) {
    const double u = sheet.vertices(v, 0), radius = 1.0;
    x.segment<3>(3 * v) << radius * std::sin(u / radius), sheet.vertices(v, 1),
        radius * (1 - std::cos(u / radius));
  }
  const psq::BendingEnergy hinges(sheet, topology, material);
  const psq::MidedgeBendingEnergy faces(sheet, topology, material);
  std::size_t hinge_values = 0, face_values = 0;
  const double hinge_seconds = seconds_per_evaluation(hinges, x, repeats, hinge_values);
  const double face_seconds = seconds_per_evaluation(faces, x, repeats, face_values);
  fmt::print("bending models on a Delaunay sheet of {} vertices (serial, best of {})\n",
             sheet.vertex_count(), repeats);
  fmt::print("{:>8} {:>9} {:>12} {:>12} {:>14}\n", "model", "elements", "ms/eval", "us/element",
             "Hessian values");
  fmt::print("{:>8} {:>9} {:>12.2f} {:>12.3f} {:>14}\n", "hinge", hinges.hinge_count(),
             1e3 * hinge_seconds, 1e6 * hinge_seconds / hinges.hinge_count(), hinge_values);
  fmt::print("{:>8} {:>9} {:>12.2f} {:>12.3f} {:>14}\n", "midedge", faces.element_count(),
             1e3 * face_seconds, 1e6 * face_seconds / faces.element_count(), face_values);
  fmt::print("mid-edge / hinge time per mesh: {:.2f}x\n", face_seconds / hinge_seconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_bending", {{"vertices", OptionType::count, "10000", "vertices of the bent sheet"},
                        {"repeats", OptionType::count, "5", "runs per model; the best is shown"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_bending);
}
