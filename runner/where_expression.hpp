#pragma once
// `psq promote --where EXPR`: conditions on a previewed job's outputs and parameters, such as
// "max_displacement > 0.002 and shell.strip.material.thickness <= 0.001".

#include <string>
#include <vector>

#include "db/refine_rule.hpp"

namespace psq::runner {

/// Parses `NAME OP NUMBER [and NAME OP NUMBER ...]`, OP one of < <= > >= == != (= means ==).
/// Throws InputError quoting the term that is not of that form. Names are checked later, against
/// the jobs (db::select_points).
std::vector<db::Condition> parse_where(const std::string& expression);

}  // namespace psq::runner
