#include "engine/scene/key_suggestion.hpp"

#include <gtest/gtest.h>

namespace psq {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("", ""), 0);
  EXPECT_EQ(edit_distance("", "abc"), 3);
  EXPECT_EQ(edit_distance("abc", ""), 3);
  EXPECT_EQ(edit_distance("thickness", "thickness"), 0);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);  // k→s, e→i, +g
  EXPECT_EQ(edit_distance("thicknes", "thickness"), 1);
}

TEST(EditDistance, AdjacentSwapCostsOne) {
  EXPECT_EQ(edit_distance("ca", "ac"), 1);
  EXPECT_EQ(edit_distance("desnity", "density"), 1);
  // Restricted variant: "ca" → "ac" → "abc" edits the swapped pair again, which is not
  // allowed, so the distance is 3 (the unrestricted Damerau–Levenshtein distance is 2).
  EXPECT_EQ(edit_distance("ca", "abc"), 3);
}

TEST(EditDistance, IsSymmetric) {
  for (const auto& [a, b] : {std::pair{"gravty", "gravity"}, std::pair{"frames", "fames"},
                             std::pair{"axis_point", "axispoint"}})
    EXPECT_EQ(edit_distance(a, b), edit_distance(b, a)) << a << " " << b;
}

const std::vector<std::string> kMaterialKeys = {"youngs_modulus", "poisson_ratio", "density",
                                                "thickness"};

TEST(SuggestKey, FindsNearMisses) {
  EXPECT_EQ(suggest_key("thicknes", kMaterialKeys), "thickness");
  EXPECT_EQ(suggest_key("desnity", kMaterialKeys), "density");
  EXPECT_EQ(suggest_key("youngs_modulis", kMaterialKeys), "youngs_modulus");
  EXPECT_EQ(suggest_key("Poisson_Ratio", kMaterialKeys), "poisson_ratio");  // case ignored
}

TEST(SuggestKey, StaysSilentWhenNothingIsClose) {
  EXPECT_FALSE(suggest_key("colour", kMaterialKeys));
  EXPECT_FALSE(suggest_key("E", kMaterialKeys));
  EXPECT_FALSE(suggest_key("anything", {}));
}

TEST(SuggestKey, PrefersTheNearestThenTheEarliest) {
  EXPECT_EQ(suggest_key("heigt", {"heights", "height"}), "height");  // distances 2 and 1
  EXPECT_EQ(suggest_key("stat", {"start", "state"}), "start");       // both at distance 1
  EXPECT_EQ(suggest_key("stat", {"state", "start"}), "state");
}

}  // namespace
}  // namespace psq
