// Benchmark (prints, never fails on a slow machine): building a decimation hierarchy
// (build_hierarchy: collapses, quality filter, intrinsic map) on a sphere and on the bunny, and
// building the direct prolongation of every level; per level the vertex count and the rest
// error (largest |finest rest − P^l(level rest)| / bounding-box diagonal).
//
// Usage: bench_hierarchy [--vertices N] [--levels L]

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "bench/bench_options.hpp"
#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/shell_prolongation.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_io.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void report(const std::string& name, const psq::TriMesh& finest, int levels) {
  psq::HierarchySettings settings;
  settings.levels = levels;
  const auto start = Clock::now();
  const psq::MeshHierarchy hierarchy = psq::build_hierarchy(finest, {}, settings);
  const double build_seconds = seconds_since(start);
  const double diagonal = psq::bounding_box_diagonal(finest.vertices);
  fmt::print("{}: {} vertices, {} levels built in {:.2f} s\n", name, finest.vertex_count(),
             hierarchy.level_count(), build_seconds);
  for (int l = 0; l < hierarchy.level_count(); ++l) {
    const auto prolongation_start = Clock::now();
    const psq::ShellProlongation p = psq::direct_prolongation(hierarchy, l);
    const double prolongation_seconds = seconds_since(prolongation_start);
    const psq::Positions prolonged = p.apply(hierarchy.levels[l].rest.vertices);
    const double rest_error = (prolonged - finest.vertices).rowwise().norm().maxCoeff() / diagonal;
    fmt::print("  level {}: {:>7} vertices, P^l built in {:.3f} s, rest error {:.1e}\n", l,
               hierarchy.levels[l].rest.vertex_count(), prolongation_seconds, rest_error);
  }
}

/// Reports the hierarchies of a sphere and of the bunny; the command line is read by
/// run_benchmark.
int bench_hierarchy(const psq::bench::BenchOptions& options) {
  const int vertices = options.integer("vertices"), levels = options.integer("levels");
  psq::SphereGenerator sphere;
  // A geodesic sphere has about 4πr² / (√3/4 e²) / 2 vertices for edge length e.
  sphere.edge_length =
      std::sqrt(8 * M_PI * sphere.radius * sphere.radius / (std::sqrt(3.0) * vertices));
  report("sphere", psq::make_sphere(sphere), levels);
  report("bunny", psq::read_mesh(PSQ_SHARED_DIR "/data/meshes/bunny.obj"), levels);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_hierarchy", {{"vertices", OptionType::count, "40000", "vertices of the sphere"},
                          {"levels", OptionType::count, "4", "hierarchy levels"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_hierarchy);
}
