#include "jobs/job_identity.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "engine/core/error.hpp"
#include "engine/core/checksum.hpp"

namespace psq::jobs {

std::string file_content_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(located_message(file.string(), 0, "cannot read the file"));
  std::stringstream content;
  content << in.rdbuf();
  return fmt::format("fnv1a64:{:016x}", Fnv1a64().update(content.str()).value());
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
