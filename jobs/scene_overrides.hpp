#pragma once
// Scene parameters a sweep can vary, by dotted path, and applying them to a parsed Scene. The
// sweep expansion validates every job with apply_overrides; the executor uses it to build the
// scene a job runs.
//
// Paths: time.step, time.frames, solver.tolerance, solver.max_iterations, contact.friction (the
// scene-wide μ; [[contact.pair]] overrides still apply), and for each shell
// shell.<name>.material.{youngs_modulus, poisson_ratio, density, thickness}.

#include <string>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/scene/scene.hpp"
#include "jobs/job_identity.hpp"

namespace psq::jobs {

/// An override that cannot be applied: an unknown path, a value of the wrong type or an
/// impossible value. The message has no file or line (the caller knows where the value came
/// from); path() names the parameter.
class OverrideError : public InputError {
 public:
  OverrideError(std::string path, const std::string& message)
      : InputError(message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Every parameter path of `scene`, in a fixed order (for messages and suggestions).
std::vector<std::string> parameter_paths(const Scene& scene);

/// Throws OverrideError, suggesting the nearest valid path, unless `path` is a parameter of
/// `scene`.
void check_parameter_path(const Scene& scene, const std::string& path);

/// The canonical form of `value` for the parameter `path`: a double for a real parameter
/// (integers written without a decimal point are converted, so 500000 and 5e5 are equal), an
/// integer for an integer parameter. Throws OverrideError for an unknown path (suggesting the
/// nearest one), a value of the wrong type, or a value outside the parameter's rule (the same
/// rules as the scene file: positive moduli, densities, thicknesses and steps; ν ∈ (−1, 0.5);
/// frames and iterations ≥ 1; every real finite).
nlohmann::json canonical_override(const Scene& scene, const std::string& path,
                                  const nlohmann::json& value);

/// `scene` with every override applied. Throws OverrideError as canonical_override does.
Scene apply_overrides(Scene scene, const Overrides& overrides);

}  // namespace psq::jobs
