#include "runner/where_expression.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <regex>

#include "engine/core/error.hpp"

namespace psq::runner {
namespace {

const std::map<std::string, db::Comparison>& comparisons() {
  static const std::map<std::string, db::Comparison> table{
      {"<", db::Comparison::less},         {"<=", db::Comparison::less_equal},
      {">", db::Comparison::greater},      {">=", db::Comparison::greater_equal},
      {"==", db::Comparison::equal},       {"=", db::Comparison::equal},
      {"!=", db::Comparison::not_equal}};
  return table;
}

/// The whole of `text` as a finite number, or nothing.
std::optional<double> whole_number(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

db::Condition parse_term(const std::string& term, const std::string& expression) {
  static const std::regex form(R"(^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(<=|>=|==|!=|<|>|=)\s*(\S+)\s*$)");
  std::smatch match;
  const auto number = std::regex_match(term, match, form) ? whole_number(match[3]) : std::nullopt;
  if (!number)
    throw InputError(fmt::format(
        "--where '{}': '{}' is not a condition; write NAME OP NUMBER with OP one of < <= > >= "
        "== !=, joined by 'and', e.g. --where 'max_displacement > 0.002 and "
        "shell.strip.material.thickness <= 0.001'",
        expression, term));
  return {match[1], comparisons().at(match[2]), *number};
}

}  // namespace

std::vector<db::Condition> parse_where(const std::string& expression) {
  static const std::regex conjunction(R"(\s+and\s+)", std::regex::icase);
  std::vector<db::Condition> conditions;
  for (std::sregex_token_iterator term(expression.begin(), expression.end(), conjunction, -1), end;
       term != end; ++term)
    conditions.push_back(parse_term(*term, expression));
  if (conditions.empty())
    throw InputError("--where needs at least one condition, e.g. --where 'max_displacement > 0.002'");
  return conditions;
}

}  // namespace psq::runner
