#pragma once
// The command line of the benchmark programs: `--name value` pairs checked against the options
// a program declares, so that a typo, a missing value or a bad number stops the program with a
// message instead of silently running a long benchmark with the defaults.

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace psq::bench {

/// What an option's value must be; checked when the command line is read.
enum class OptionType {
  count,            ///< an integer > 0
  integer,          ///< any integer
  number,           ///< any finite number
  positive_number,  ///< a finite number > 0
  text,             ///< any non-empty string
  count_list,       ///< comma-separated integers > 0
  text_list,        ///< comma-separated non-empty strings
};

/// One `--name value` option a benchmark accepts.
struct OptionSpec {
  std::string name;           ///< without the leading "--"
  OptionType type;            ///< what its value must be
  std::string default_value;  ///< as typed on the command line; empty: no default (see given)
  std::string description;    ///< one line for the usage
};

/// A bad command line; the message names the option and the offending value.
class OptionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws the OptionError for `value` of option `name` that is not `expected` ("an integer").
[[noreturn]] void reject_value(const std::string& name, const std::string& value,
                               const std::string& expected);

/// The options of one benchmark program and, once parsed, their values.
class BenchOptions {
 public:
  /// `program` names the program in the usage; option names must be distinct.
  BenchOptions(std::string program, std::vector<OptionSpec> options);

  /// Reads `arguments` (without the program name). Returns false when --help or -h asks for the
  /// usage. Throws OptionError on an unknown option, a missing or repeated value, or a value that
  /// is not of the option's type.
  bool parse(const std::vector<std::string>& arguments);

  /// The usage: one line per option with its description and default.
  std::string usage() const;
  /// The program name given at construction.
  const std::string& program() const { return program_; }

  /// Whether the option was given on the command line.
  bool given(const std::string& name) const;
  /// The value of a count or integer option (the default when not given).
  int integer(const std::string& name) const;
  /// The value of a number or positive_number option.
  double number(const std::string& name) const;
  /// The value of a text option.
  std::string text(const std::string& name) const;
  /// The items of a count_list option.
  std::vector<int> integers(const std::string& name) const;
  /// The items of a text_list option.
  std::vector<std::string> texts(const std::string& name) const;

 private:
  const OptionSpec& spec(const std::string& name) const;
  /// The given value, else the default; asking for a type the option does not have, or for an
  /// option without a default that was not given, is a programming error (std::logic_error).
  std::string value(const std::string& name, std::initializer_list<OptionType> types) const;

  std::string program_;
  std::vector<OptionSpec> options_;
  std::map<std::string, std::string> values_;
};

/// The frame of a benchmark's main: parses the command line, then runs `body`. --help: the
/// usage on stdout, exit 0. An OptionError (from parsing or from the body's own checks):
/// "<program>: <message>" and the usage on stderr, exit 2. Any other exception: "<program>:
/// <message>" on stderr, exit 1. Otherwise the body's exit code.
int run_benchmark(BenchOptions& options, int argc, char** argv,
                  const std::function<int(const BenchOptions&)>& body);

}  // namespace psq::bench
