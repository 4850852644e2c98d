#pragma once
#include <string>
#include <vector>

namespace psq::test {

struct ProcessResult {
  int exit_code = -1;   ///< the exit status, or 128 + signal when killed
  std::string output;   ///< stdout
  std::string errors;   ///< stderr
};

/// Runs a program with arguments (no shell), waits for it and captures stdout and stderr.
ProcessResult run_process(const std::string& program, const std::vector<std::string>& arguments);

/// The psq executable built with the tests (PSQ_EXECUTABLE), run with `arguments`.
ProcessResult run_psq(const std::vector<std::string>& arguments);

}  // namespace psq::test
