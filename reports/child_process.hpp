#pragma once
// Running a helper program (gnuplot) as a child process, waiting for it and reading the files
// it wrote.

#include <filesystem>
#include <string>
#include <vector>

namespace psq::reports {

/// How a child process ended.
struct ChildExit {
  int status = 0;      ///< exit status, or 128 + signal number if a signal ended it
  std::string errors;  ///< what it wrote to stderr
};

/// Runs `program` (looked up in PATH unless it contains a '/') with `arguments`, stdin on
/// /dev/null, stdout into `output_file` (/dev/null when empty), stderr captured through the
/// file `error_file`, and waits for it. Throws InputError naming the program if it cannot be
/// started (not found, not executable).
ChildExit run_child(const std::string& program, const std::vector<std::string>& arguments,
                    const std::filesystem::path& error_file,
                    const std::filesystem::path& output_file = {});

/// The bytes a child process wrote to `file`; empty if the file is missing.
std::string read_child_output(const std::filesystem::path& file);

}  // namespace psq::reports
