#include "jobs/test_hooks.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>
#include <string>

#include "engine/core/error.hpp"

namespace psq::jobs {
namespace {

struct Trigger {
  long pass = 0;
  int signal = SIGKILL;
};

/// The triggers of PSQ_TEST_PAUSE_AT by point name.
std::map<std::string, Trigger, std::less<>> parse_triggers(const char* text) {
  std::map<std::string, Trigger, std::less<>> triggers;
  if (!text || !*text) return triggers;
  std::stringstream items(text);
  for (std::string item; std::getline(items, item, ',');) {
    const auto fail = [&] {
      return InputError(
          fmt::format("PSQ_TEST_PAUSE_AT: '{}' is not <point>:<n>[:kill|:stop] "
                      "with n ≥ 1",
                      item));
    };
    std::stringstream fields(item);
    std::string point, count, action;
    std::getline(fields, point, ':');
    std::getline(fields, count, ':');
    std::getline(fields, action);
    char* end = nullptr;
    const long pass = std::strtol(count.c_str(), &end, 10);
    if (point.empty() || count.empty() || *end != '\0' || pass < 1) throw fail();
    if (action != "" && action != "kill" && action != "stop") throw fail();
    triggers[point] = {pass, action == "stop" ? SIGSTOP : SIGKILL};
  }
  return triggers;
}

}  // namespace

void test_point(std::string_view point) {
  static const auto triggers = parse_triggers(std::getenv("PSQ_TEST_PAUSE_AT"));
  if (triggers.empty()) return;
  const auto trigger = triggers.find(point);
  if (trigger == triggers.end()) return;
  static std::mutex mutex;  // points are passed by the worker and its heartbeat thread
  static std::map<std::string, long, std::less<>> passes;
  std::lock_guard lock(mutex);
  long& count = passes[std::string(point)];
  if (++count == trigger->second.pass) ::kill(::getpid(), trigger->second.signal);
}

}  // namespace psq::jobs
