#include "db/job_records.hpp"

#include <fmt/format.h>

#include <numeric>
#include <stdexcept>

namespace psq::db {
namespace {

constexpr std::array<std::string_view, kAllJobStates.size()> kJobStateNames{
    "queued", "running", "done", "failed", "cancelled", "previewed"};
constexpr std::array<std::string_view, kAllMethods.size()> kMethodNames{
    "direct", "direct_final", "progressive", "coarse_prolonged"};
constexpr std::array<std::string_view, 3> kLevelStatusNames{"running", "done", "failed"};

template <class Enum, std::size_t N>
Enum from_name(const std::array<std::string_view, N>& names, std::string_view name,
               std::string_view what) {
  for (std::size_t i = 0; i < N; ++i)
    if (names[i] == name) return static_cast<Enum>(i);
  throw std::invalid_argument(fmt::format("'{}' is not a {}", name, what));
}

}  // namespace

std::string_view to_string(JobState state) {
  return kJobStateNames[static_cast<std::size_t>(state)];
}

JobState job_state_from_string(std::string_view name) {
  return from_name<JobState>(kJobStateNames, name, "job state");
}

std::string_view to_string(Method method) { return kMethodNames[static_cast<std::size_t>(method)]; }

Method method_from_string(std::string_view name) {
  return from_name<Method>(kMethodNames, name, "method");
}

bool uses_hierarchy(Method method) {
  return method == Method::progressive || method == Method::coarse_prolonged;
}

Method method_of_depth(int depth) { return depth > 1 ? Method::progressive : Method::direct; }

std::string_view to_string(LevelStatus status) {
  return kLevelStatusNames[static_cast<std::size_t>(status)];
}

LevelStatus level_status_from_string(std::string_view name) {
  return from_name<LevelStatus>(kLevelStatusNames, name, "level status");
}

std::int64_t SweepStatus::total() const {
  return std::accumulate(counts.begin(), counts.end(), std::int64_t{0},
                         [](std::int64_t sum, const auto& entry) { return sum + entry.second; });
}

}  // namespace psq::db
