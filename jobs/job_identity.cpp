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
                                    int depth) {
  nlohmann::json by_path = nlohmann::json::object();
  for (const auto& [path, value] : overrides) by_path[path] = value;
  return {{"depth", depth}, {"overrides", by_path}, {"scene", scene_hash}};
}

std::string job_id(const nlohmann::json& canonical) {
  return fmt::format("{:016x}", Fnv1a64().update(canonical.dump()).value());
}

}  // namespace psq::jobs
