// Benchmark (prints, never fails on a slow machine): cost per element of the two bending
// models, hinge (BendingEnergy) and mid-edge (MidedgeBendingEnergy), on a bent Delaunay sheet:
// value, gradient and solver Hessian (Gauss–Newton blocks, as Newton asks for them), and the
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

/// Seconds of one value, one add_gradient and one solver Hessian, each the best of `repeats`.
struct EvaluationSeconds {
  double value = INFINITY, gradient = INFINITY, hessian = INFINITY;
  [[nodiscard]] double total() const { return value + gradient + hessian; }
};

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

template <class Energy>
EvaluationSeconds seconds_per_evaluation(const Energy& energy, const Eigen::VectorXd& x,
                                         int repeats, std::size_t& hessian_values) {
  EvaluationSeconds best;
  psq::ElementMatrices blocks;
  for (int r = 0; r < repeats; ++r) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
    auto start = Clock::now();
    const double value = energy.value(x);
    best.value = std::min(best.value, seconds_since(start));
    start = Clock::now();
    energy.add_gradient(x, g);
    best.gradient = std::min(best.gradient, seconds_since(start));
    start = Clock::now();
    energy.hessian(x, blocks, true);
    best.hessian = std::min(best.hessian, seconds_since(start));
    if (!std::isfinite(value) || !g.allFinite()) throw std::runtime_error("non-finite result");
  }
  hessian_values = blocks.values.size();
  return best;
}

void print_row(const char* model, std::size_t elements, const EvaluationSeconds& t,
               std::size_t hessian_values) {
  fmt::print("{:>8} {:>9} {:>9.2f} {:>9.2f} {:>9.2f} {:>12.3f} {:>14}\n", model, elements,
             1e3 * t.value, 1e3 * t.gradient, 1e3 * t.hessian, 1e6 * t.total() / elements,
             hessian_values);
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
  const EvaluationSeconds hinge = seconds_per_evaluation(hinges, x, repeats, hinge_values);
  const EvaluationSeconds face = seconds_per_evaluation(faces, x, repeats, face_values);
  fmt::print("bending models on a Delaunay sheet of {} vertices (serial, best of {})\n",
             sheet.vertex_count(), repeats);
  fmt::print("{:>8} {:>9} {:>9} {:>9} {:>9} {:>12} {:>14}\n", "model", "elements", "value ms",
             "grad ms", "hess ms", "us/element", "Hessian values");
  print_row("hinge", hinges.hinge_count(), hinge, hinge_values);
  print_row("midedge", faces.element_count(), face, face_values);
  fmt::print("mid-edge / hinge time per mesh: {:.2f}x\n", face.total() / hinge.total());
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
