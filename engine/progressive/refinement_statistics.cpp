#include "engine/progressive/refinement_statistics.hpp"

#include <cmath>

namespace psq {

std::map<std::string, double> named_refinement_statistics(
    const std::optional<RefinementStats>& safe_initialization,
    const std::optional<StrainCorrectionStats>& strain_correction, double seconds) {
  std::map<std::string, double> named{{"seconds", seconds}};
  if (const auto& s = safe_initialization) {
    named.insert({{"expansions", s->expansions},
                  {"batches", s->batches},
                  {"perturbation_retries", s->perturbation_retries},
                  {"ccd_rounds", s->ccd_rounds},
                  {"folded_advances", s->folded_advances},
                  {"relaxed_vertices", s->relaxed_vertices},
                  {"relax_iterations", s->relax_iterations},
                  {"smallest_gap", s->smallest_gap},
                  {"final_gap", s->final_gap},
                  {"max_target_distance", s->max_target_distance},
                  {"mean_target_distance", s->mean_target_distance},
                  {"gap_seconds", s->gap_seconds},
                  {"perturb_seconds", s->perturb_seconds},
                  {"ccd_seconds", s->ccd_seconds},
                  {"relax_seconds", s->relax_seconds},
                  {"check_seconds", s->check_seconds},
                  {"safe_initialization_seconds", s->seconds}});
  }
  if (const auto& c = strain_correction) {
    named.insert({{"strain_iterations", c->iterations},
                  {"stretch_before", c->stretch_before},
                  {"stretch_after", c->stretch_after},
                  {"strain_freed_old_vertices", c->freed_old_vertices ? 1.0 : 0.0},
                  {"strain_seconds", c->seconds}});
  }
  std::erase_if(named, [](const auto& entry) { return !std::isfinite(entry.second); });
  return named;
}

}  // namespace psq
