#include "runner/stats_json.hpp"

#include <cmath>

namespace psq::runner {

nlohmann::json phase_times_json(const PhaseTimes& t) {
  return {{"assembly", t.assembly},
          {"factorization", t.factorization},
          {"solve", t.solve},
          {"line_search", t.line_search}};
}

nlohmann::json contact_json(const FrameRecord& r) {
  const ContactStats& c = r.contact;
  return {{"barrier_stiffness", r.barrier_stiffness},
          {"kinematic_rounds", r.kinematic_rounds},
          {"kinematic_offset", r.kinematic_offset},
          {"max_active_pairs", c.max_active_pairs},
          {"barrier_evaluations", c.barrier_evaluations},
          {"barrier_skips", c.barrier_skips},
          {"barrier_certified", c.barrier_certified},
          {"ccd_evaluations", c.ccd_evaluations},
          {"ccd_skips", c.ccd_skips},
          {"ccd_certified", c.ccd_certified},
          {"certificate_renewals", c.certificate_renewals},
          {"state_reuses", c.state_reuses},
          {"ccd_reuses", c.ccd_reuses},
          {"ccd_pair_queries", c.ccd_pair_queries},
          {"broad_phase_seconds", c.broad_phase_seconds},
          {"barrier_seconds", c.barrier_seconds},
          {"ccd_seconds", c.ccd_seconds}};
}

nlohmann::json probes_json(const std::vector<ProbeReading>& readings) {
  nlohmann::json out = nlohmann::json::array();
  for (const ProbeReading& reading : readings)
    out.push_back({{"name", reading.name},
                   {"kind", reading.kind == ProbeKind::displacement ? "displacement" : "reaction"},
                   {"value", {reading.value.x(), reading.value.y(), reading.value.z()}},
                   {"magnitude", reading.value.norm()}});
  return out;
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
          {"stagnated", r.newton.stagnated},
          {"iterations", r.newton.iterations},
          {"energy", r.newton.energy},
          {"elastic_energy", r.elastic_energy},
          {"step_norm", r.newton.step_norm},
          {"gradient_norm", r.newton.gradient_norm},
          {"step_norm_history", step_norms},
          {"gradient_norm_history", gradient_norms},
          {"settle_steps", r.settle_steps},
          {"predicted", r.predicted},
          {"static_residual", std::isnan(r.static_residual) ? nlohmann::json(nullptr)
                                                            : nlohmann::json(r.static_residual)},
          {"friction_iterations", r.friction_iterations},
          {"load_scale", r.load_scale},
          {"probes", probes_json(r.probes)},
          {"contact", contact_json(r)},
          {"seconds", r.newton.wall_seconds},
          {"phase_seconds", phase_times_json(r.newton.times)}};
}

}  // namespace psq::runner
