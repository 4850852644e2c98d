#pragma once
// The published shell benchmarks of jobs/scenes/verification (docs/verification.md): each
// scene at a chosen resolution and bending model, solved to its static equilibrium as `psq sim`
// solves it, and the quantity its reference value is for. Shared by tests/verification and
// bench_verification.

#include <functional>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"
#include "engine/sim/quasistatic.hpp"

namespace psq::test {

/// One benchmark: its scene, what is measured and the published value of it.
struct VerificationBenchmark {
  std::string name;       ///< the scene's file stem in jobs/scenes/verification
  std::string quantity;   ///< what `measure` returns, for tables
  double reference = 0;   ///< the published (or analytic) value of that quantity
  std::string source;     ///< where the reference comes from
  /// The published values are linear: the scene's loads (point and line loads, and the weight
  /// through the density) and its solver tolerance (a speed) are scaled by this before the solve and the measured quantity divided by it, so that
  /// PSQ's nonlinear equilibrium is in its linear range. 1 for the roll-up, whose reference
  /// is the exact large-rotation solution.
  double load_scale = 1;
  /// Whether the linear value is extrapolated from the solves at load_scale and twice it
  /// (2 q(s) − q(2s) removes the part of q that grows with the load), for a benchmark that
  /// must be loaded where its nonlinear part is still visible.
  bool extrapolate_in_load = false;
  /// The mesh series of the convergence tables, coarse to fine: generator edge lengths.
  std::vector<double> edge_lengths;
  /// The quantity at the last frame of a finished simulation.
  std::function<double(const QuasistaticSimulation&, const FrameRecord&)> measure;
};

/// roll_up, scordelis_lo, pinched_cylinder, pinched_hemisphere.
const std::vector<VerificationBenchmark>& verification_benchmarks();
/// The benchmark called `name`; std::invalid_argument for another name.
const VerificationBenchmark& verification_benchmark(const std::string& name);

/// The benchmark's scene with its shell's bending model and mesh edge length replaced, and its
/// loads and tolerance scaled by load_scale.
Scene verification_scene(const VerificationBenchmark& benchmark, BendingModel bending,
                         double edge_length);

struct VerificationRun {
  int vertices = 0;
  bool converged = false;  ///< every frame reached its static equilibrium
  double value = 0;        ///< the measured quantity (divided by load_scale)
  double seconds = 0;      ///< wall time of the simulation
  /// value / reference − 1.
  [[nodiscard]] double relative_error(const VerificationBenchmark& benchmark) const {
    return value / benchmark.reference - 1.0;
  }
};

/// Simulates the scene's frames (each settled to its static equilibrium) and measures (twice,
/// and extrapolates, with extrapolate_in_load).
VerificationRun run_verification(const VerificationBenchmark& benchmark, BendingModel bending,
                                 double edge_length);

}  // namespace psq::test
