// Benchmark (prints, never fails on a slow machine): time per Newton iteration of the drape
// scene at about 1k, 10k and 50k vertices, split into assembly, factorization, solve and line
// search, and the peak memory. Target (issue 2): assembly + line search < 25% of the
// factorization time at 50k vertices.
//
// Usage: bench_drape [--scene SCENE] [--frames N] [--sizes 1000,10000,50000]

#include <fmt/format.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdio>

#include "bench/bench_options.hpp"
#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"

namespace {

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

/// Prints the phase split per size; the command line is read by run_benchmark.
int bench_drape(const psq::bench::BenchOptions& options) {
  const std::string scene_path = options.text("scene");
  const int frames = options.integer("frames");
  const std::vector<int> sizes = options.integers("sizes");
  fmt::print("{:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}\n", "vertices",
             "iters", "ms/iter", "assembly", "factor", "solve", "l.search", "(asm+ls)", "/factor",
             "peakMiB");
  for (int target : sizes) {
    psq::Scene scene = psq::read_scene(scene_path);
    psq::SheetGenerator& sheet = scene.shells.at(0).mesh.sheet;
    // A Delaunay sheet has about area / (√3/4 · e²) / 2 vertices for edge length e.
    sheet.edge_length = std::sqrt(2.0 * sheet.width * sheet.height / (std::sqrt(3.0) * target));
    scene.time.frames = frames;
    psq::QuasistaticSimulation sim(scene);
    psq::PhaseTimes total;
    int iterations = 0;
    for (int f = 0; f < frames; ++f) {
      const psq::FrameRecord record = sim.step();
      total += record.newton.times;
      iterations += static_cast<int>(record.newton.history.size());
    }
    const double per = 1e3 / iterations;
    fmt::print(
        "{:>8} {:>6} {:>10.1f} {:>10.1f} {:>10.1f} {:>10.1f} {:>10.1f} {:>10.1f} {:>8.1f}% "
        "{:>9.0f}\n",
        sim.system().rest_mesh().vertex_count(), iterations, total.total() * per,
        total.assembly * per, total.factorization * per, total.solve * per, total.line_search * per,
        (total.assembly + total.line_search) * per,
        100.0 * (total.assembly + total.line_search) / total.factorization, peak_rss_mib());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_drape",
      {{"scene", OptionType::text, PSQ_SOURCE_DIR "/jobs/scenes/drape.toml",
        "scene file; its first shell's sheet is resized"},
       {"frames", OptionType::count, "3", "frames per size"},
       {"sizes", OptionType::count_list, "1000,10000,50000", "target vertex counts"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_drape);
}
