#pragma once
// Exceptions thrown by the engine. The CLI catches them and turns them into exit codes;
// the engine itself never terminates the process.

#include <stdexcept>
#include <string>

namespace psq {

/// Base of every PSQ error.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad user input: a file, a parameter or a value the user must fix. The message names
/// the file, line and key or parameter involved.
class InputError : public Error {
 public:
  using Error::Error;
};

/// The numerics failed: NaN or infinite values, divergence, a non-descent direction or a
/// matrix that cannot be factorized. Never silently written out.
class NumericalError : public Error {
 public:
  using Error::Error;
};

/// Builds "file:line: message" (line omitted when 0), the format of every InputError.
std::string located_message(const std::string& file, long line, const std::string& message);

}  // namespace psq
