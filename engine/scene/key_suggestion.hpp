#pragma once
// "Did you mean ...?" for misspelt keys in input files.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace psq {

/// Optimal-string-alignment distance (the restricted Damerau–Levenshtein distance): the fewest
/// single-character insertions, deletions, substitutions and swaps of two adjacent characters
/// that turn `a` into `b`, with no substring edited twice. Case-sensitive.
int edit_distance(std::string_view a, std::string_view b);

/// The candidate nearest to `key` by edit_distance (compared case-insensitively), if it is
/// close enough to be a plausible typo: distance ≤ max(1, ⌊|candidate|/3⌋). Ties go to the
/// earlier candidate. Returns nothing when no candidate is that close.
std::optional<std::string> suggest_key(std::string_view key,
                                       const std::vector<std::string>& candidates);

}  // namespace psq
