#include "engine/sim/solver_tolerance.hpp"

#include <fmt/format.h>

#include "engine/core/error.hpp"

namespace psq {

double solver_tolerance(const Scene& scene, double diagonal) {
  return scene.solver.tolerance.value_or(1e-4 * diagonal);
}

void check_convergence_resolution(const Scene& scene, double diagonal) {
  const double tolerance = solver_tolerance(scene, diagonal);
  const double step = scene.time.step;
  const double largest_move = kLargestConvergedMoveFraction * diagonal;
  if (tolerance * step <= largest_move) return;
  throw InputError(fmt::format(
      "{}: time.step = {:g} s with solver.tolerance = {:.3g} m/s{} would accept a frame whose "
      "last Newton step still moves {:.3g} m, {:.2g} of the scene's size ({:.3g} m): lower "
      "time.step to at most {:.3g} s or solver.tolerance to at most {:.3g} m/s",
      scene.source.string(), step, tolerance,
      scene.solver.tolerance ? "" : " (its default, 1e-4 × the scene's size per second)",
      tolerance * step, tolerance * step / diagonal, diagonal, largest_move / tolerance,
      largest_move / step));
}

}  // namespace psq
