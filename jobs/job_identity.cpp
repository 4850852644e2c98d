#include "jobs/job_identity.hpp"

#include <fmt/format.h>

#include "engine/core/checksum.hpp"
#include "engine/core/error.hpp"

namespace psq::jobs {

std::string file_content_hash(const std::filesystem::path& file) {
  const std::optional<std::uint64_t> checksum = file_fnv1a64(file);
  if (!checksum) throw InputError(located_message(file.string(), 0, "cannot read the file"));
  return checksum_text(*checksum);
}

nlohmann::json canonical_parameters(const std::string& scene_hash, const Overrides& overrides,
                                    int depth, db::Method method) {
  nlohmann::json by_path = nlohmann::json::object();
  for (const auto& [path, value] : overrides) by_path[path] = value;
  nlohmann::json parameters = {{"depth", depth}, {"overrides", by_path}, {"scene", scene_hash}};
  if (method != db::method_of_depth(depth)) parameters["method"] = db::to_string(method);
  return parameters;
}

int hierarchy_depth(const db::Job& job) { return job.parameters.value("depth", job.depth); }

std::string job_id(const nlohmann::json& canonical) {
  return fmt::format("{:016x}", Fnv1a64().update(canonical.dump()).value());
}

}  // namespace psq::jobs
