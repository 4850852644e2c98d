// Benchmark (prints, never fails): the convergence tables of the published shell benchmarks
// of jobs/scenes/verification against mesh refinement, for both bending models, and the
// coarsest tabulated mesh from which each model stays within 5 % and 2 % of the reference
// (docs/verification.md reproduces its figures).
//
// Usage: bench_verification [--benchmarks roll_up,scordelis_lo,...] [--models hinge,midedge]
//                           [--refinements N]

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench_options.hpp"
#include "engine/core/error.hpp"
#include "support/verification_benchmarks.hpp"

namespace {

using psq::test::VerificationBenchmark;
using psq::test::VerificationRun;

psq::BendingModel bending_model(const std::string& name) {
  if (name == "hinge") return psq::BendingModel::hinge;
  if (name == "midedge") return psq::BendingModel::midedge;
  psq::bench::reject_value("models", name, "'hinge' or 'midedge'");
}

/// The coarsest of `runs` (coarse to fine) from which every finer run is converged and within
/// `bound` of the reference, or nothing.
std::optional<std::size_t> coarsest_within(const VerificationBenchmark& benchmark,
                                           const std::vector<VerificationRun>& runs,
                                           double bound) {
  std::optional<std::size_t> from;
  for (std::size_t k = runs.size(); k-- > 0;) {
    if (!runs[k].converged || std::abs(runs[k].relative_error(benchmark)) > bound) break;
    from = k;
  }
  return from;
}

std::string needs(const VerificationBenchmark& benchmark, const std::vector<VerificationRun>& runs,
                  double bound) {
  const std::optional<std::size_t> k = coarsest_within(benchmark, runs, bound);
  return k ? fmt::format("edge {:g} ({} vertices)", benchmark.edge_lengths[*k], runs[*k].vertices)
           : std::string("not within the table");
}

void report(const VerificationBenchmark& benchmark, const std::string& model, int refinements) {
  fmt::print("{}, bending {}: {} = {:g} ({})\n", benchmark.name, model, benchmark.quantity,
             benchmark.reference, benchmark.source);
  fmt::print("  {:>10} {:>9} {:>14} {:>10} {:>9} {:>9}\n", "edge", "vertices", "value", "error",
             "seconds", "status");
  std::vector<VerificationRun> runs;
  for (int k = 0; k < refinements; ++k) {
    const double edge = benchmark.edge_lengths[k];
    VerificationRun run;
    try {
      run = psq::test::run_verification(benchmark, bending_model(model), edge);
    } catch (const psq::NumericalError& error) {
      fmt::print("  {:>10g} failed: {}\n", edge, error.what());
      runs.push_back(run);  // not converged
      continue;
    }
    fmt::print("  {:>10g} {:>9} {:>14.6g} {:>9.2f}% {:>9.2f} {:>9}\n", edge, run.vertices,
               run.value, 100 * run.relative_error(benchmark), run.seconds,
               run.converged ? "settled" : "NOT SETTLED");
    std::fflush(stdout);
    runs.push_back(run);
  }
  fmt::print("  within 5 %: {}; within 2 %: {}\n\n", needs(benchmark, runs, 0.05),
             needs(benchmark, runs, 0.02));
}

int bench_verification(const psq::bench::BenchOptions& options) {
  const int refinements = options.integer("refinements");
  for (const std::string& name : options.texts("benchmarks")) {
    std::vector<std::string> known;
    for (const VerificationBenchmark& b : psq::test::verification_benchmarks())
      known.push_back(b.name);
    if (std::find(known.begin(), known.end(), name) == known.end())
      psq::bench::reject_value("benchmarks", name, fmt::format("one of {}", fmt::join(known, ", ")));
    const VerificationBenchmark& benchmark = psq::test::verification_benchmark(name);
    if (refinements > static_cast<int>(benchmark.edge_lengths.size()))
      psq::bench::reject_value("refinements", std::to_string(refinements),
                               fmt::format("at most {} (the meshes {} tabulates)",
                                           benchmark.edge_lengths.size(), name));
    for (const std::string& model : options.texts("models")) report(benchmark, model, refinements);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using psq::bench::OptionType;
  psq::bench::BenchOptions options(
      "bench_verification",
      {{"benchmarks", OptionType::text_list,
        "roll_up,scordelis_lo,pinched_cylinder,pinched_hemisphere", "benchmarks to tabulate"},
       {"models", OptionType::text_list, "hinge,midedge", "bending models"},
       {"refinements", OptionType::count, "4", "meshes per table, coarsest first"}});
  return psq::bench::run_benchmark(options, argc, argv, bench_verification);
}
