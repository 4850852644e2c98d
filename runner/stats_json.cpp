#include "runner/stats_json.hpp"

namespace psq::runner {

nlohmann::json phase_times_json(const PhaseTimes& t) {
  return {{"assembly", t.assembly},
          {"factorization", t.factorization},
          {"solve", t.solve},
          {"line_search", t.line_search}};
}

nlohmann::json frame_json(const FrameRecord& r) {
  nlohmann::json step_norms = nlohmann::json::array();
  nlohmann::json gradient_norms = nlohmann::json::array();
  for (const NewtonIteration& it : r.newton.history) {
    step_norms.push_back(it.step_norm);
    gradient_norms.push_back(it.gradient_norm);
  }
  return {{"frame", r.frame},
          {"time", r.time},
          {"converged", r.newton.converged},
          {"iterations", r.newton.iterations},
          {"energy", r.newton.energy},
          {"elastic_energy", r.elastic_energy},
          {"step_norm", r.newton.step_norm},
          {"gradient_norm", r.newton.gradient_norm},
          {"step_norm_history", step_norms},
          {"gradient_norm_history", gradient_norms},
          {"friction_iterations", r.friction_iterations},
          {"seconds", r.newton.wall_seconds},
          {"phase_seconds", phase_times_json(r.newton.times)}};
}

}  // namespace psq::runner
