#include "bench/bench_options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

namespace psq::bench {
namespace {

bool is_help(const std::string& argument) { return argument == "--help" || argument == "-h"; }

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) items.push_back(item);
  // getline drops a trailing empty item ("1,2,"); keep it so that it is rejected.
  if (!text.empty() && text.back() == ',') items.emplace_back();
  return items;
}

/// The whole of `text` as a number of type T; false on trailing characters or out of range.
template <class T>
bool parse_whole(const std::string& text, T& out) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, out);
  return error == std::errc() && stop == end && !text.empty();
}

int parse_count(const std::string& name, const std::string& text) {
  int count = 0;
  if (!parse_whole(text, count) || count <= 0) reject_value(name, text, "a positive integer");
  return count;
}

/// Rejects `text` unless it is a value of `type`; reading it back uses the same parsers.
void check_value(const OptionSpec& spec, const std::string& text) {
  switch (spec.type) {
    case OptionType::count:
      parse_count(spec.name, text);
      return;
    case OptionType::integer: {
      int integer = 0;
      if (!parse_whole(text, integer)) reject_value(spec.name, text, "an integer");
      return;
    }
    case OptionType::number:
    case OptionType::positive_number: {
      const bool positive = spec.type == OptionType::positive_number;
      double number = 0;
      if (!parse_whole(text, number) || !std::isfinite(number) || (positive && number <= 0))
        reject_value(spec.name, text, positive ? "a positive number" : "a finite number");
      return;
    }
    case OptionType::text:
      if (text.empty()) reject_value(spec.name, text, "a non-empty value");
      return;
    case OptionType::count_list:
      for (const std::string& item : split_list(text))
        if (int count = 0; !parse_whole(item, count) || count <= 0)
          reject_value(spec.name, text, "a comma-separated list of positive integers");
      return;
    case OptionType::text_list:
      for (const std::string& item : split_list(text))
        if (item.empty()) reject_value(spec.name, text, "a comma-separated list of names");
      return;
  }
}

std::string placeholder(OptionType type) {
  switch (type) {
    case OptionType::count:
    case OptionType::integer:
      return "N";
    case OptionType::number:
    case OptionType::positive_number:
      return "X";
    case OptionType::text:
      return "S";
    case OptionType::count_list:
      return "N,N,...";
    case OptionType::text_list:
      return "S,S,...";
  }
  return "";
}

}  // namespace

void reject_value(const std::string& name, const std::string& value, const std::string& expected) {
  throw OptionError(fmt::format("option --{}: expected {}, got '{}'", name, expected, value));
}

BenchOptions::BenchOptions(std::string program, std::vector<OptionSpec> options)
    : program_(std::move(program)), options_(std::move(options)) {
  for (const OptionSpec& option : options_)
    if (!option.default_value.empty()) check_value(option, option.default_value);
}

bool BenchOptions::parse(const std::vector<std::string>& arguments) {
  if (std::any_of(arguments.begin(), arguments.end(), is_help)) return false;
  values_.clear();
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string& argument = arguments[i];
    const auto found = std::find_if(options_.begin(), options_.end(),
                                    [&](const OptionSpec& o) { return argument == "--" + o.name; });
    if (found == options_.end()) {
      std::string valid;
      for (const OptionSpec& option : options_) valid += " --" + option.name;
      throw OptionError(fmt::format("unknown option '{}' (valid:{} --help)", argument, valid));
    }
    // A following "--name" is the next option, not this one's value.
    if (i + 1 == arguments.size() || arguments[i + 1].starts_with("--"))
      throw OptionError(fmt::format("option {}: missing value", argument));
    if (values_.contains(found->name))
      throw OptionError(fmt::format("option {} given twice", argument));
    check_value(*found, arguments[i + 1]);
    values_[found->name] = arguments[++i];
  }
  return true;
}

std::string BenchOptions::usage() const {
  std::string text = fmt::format("Usage: {} [options]\n", program_);
  for (const OptionSpec& option : options_) {
    const std::string left = fmt::format("--{} {}", option.name, placeholder(option.type));
    const std::string fallback =
        option.default_value.empty() ? "" : fmt::format(" (default {})", option.default_value);
    text += fmt::format("  {:<28} {}{}\n", left, option.description, fallback);
  }
  text += fmt::format("  {:<28} {}\n", "-h, --help", "print this usage and exit");
  return text;
}

bool BenchOptions::given(const std::string& name) const {
  spec(name);
  return values_.contains(name);
}

int BenchOptions::integer(const std::string& name) const {
  int out = 0;
  parse_whole(value(name, {OptionType::count, OptionType::integer}), out);
  return out;
}

double BenchOptions::number(const std::string& name) const {
  double out = 0;
  parse_whole(value(name, {OptionType::number, OptionType::positive_number}), out);
  return out;
}

std::string BenchOptions::text(const std::string& name) const {
  return value(name, {OptionType::text});
}

std::vector<int> BenchOptions::integers(const std::string& name) const {
  std::vector<int> out;
  for (const std::string& item : split_list(value(name, {OptionType::count_list})))
    out.push_back(parse_count(name, item));
  return out;
}

std::vector<std::string> BenchOptions::texts(const std::string& name) const {
  return split_list(value(name, {OptionType::text_list}));
}

const OptionSpec& BenchOptions::spec(const std::string& name) const {
  const auto found = std::find_if(options_.begin(), options_.end(),
                                  [&](const OptionSpec& o) { return o.name == name; });
  if (found == options_.end())
    throw std::logic_error(fmt::format("{} declares no option --{}", program_, name));
  return *found;
}

std::string BenchOptions::value(const std::string& name,
                                std::initializer_list<OptionType> types) const {
  const OptionSpec& option = spec(name);
  if (std::find(types.begin(), types.end(), option.type) == types.end())
    throw std::logic_error(fmt::format("option --{} read as the wrong type", name));
  const auto found = values_.find(name);
  if (found != values_.end()) return found->second;
  if (option.default_value.empty())
    throw std::logic_error(fmt::format("option --{} has no default; ask given() first", name));
  return option.default_value;
}

int run_benchmark(BenchOptions& options, int argc, char** argv,
                  const std::function<int(const BenchOptions&)>& body) {
  try {
    if (!options.parse(std::vector<std::string>(argv + 1, argv + argc))) {
      std::cout << options.usage();
      return 0;
    }
    return body(options);
  } catch (const OptionError& e) {
    std::cerr << options.program() << ": " << e.what() << '\n' << options.usage();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << options.program() << ": " << e.what() << '\n';
    return 1;
  }
}

}  // namespace psq::bench
