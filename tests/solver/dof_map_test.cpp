#include <gtest/gtest.h>

#include "engine/solver/dof_map.hpp"

namespace psq {
namespace {

TEST(DofMap, PinnedVerticesHaveNoFreeDofsAndRoundTrip) {
  const DofMap dofs(4, {1, 3});
  EXPECT_EQ(dofs.full_size(), 12);
  EXPECT_EQ(dofs.free_size(), 6);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(dofs.reduced(3 + c), -1);
    EXPECT_EQ(dofs.reduced(9 + c), -1);
    EXPECT_EQ(dofs.reduced(6 + c), 3 + c);
  }
  const Eigen::VectorXd full = Eigen::VectorXd::LinSpaced(12, 1, 12);
  const Eigen::VectorXd back = dofs.extend(dofs.restrict(full));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(back[i], dofs.reduced(i) >= 0 ? full[i] : 0.0);
}

TEST(DofMap, FixesChosenComponentsOnly) {
  // Vertex 0: z fixed; vertex 1: x and y fixed; vertex 2: all fixed; vertex 3: free.
  const DofMap dofs({false, false, true, true, true, false, true, true, true, false, false, false});
  EXPECT_EQ(dofs.full_size(), 12);
  EXPECT_EQ(dofs.free_size(), 6);
  const std::vector<int> expected = {0, 1, -1, -1, -1, 2, -1, -1, -1, 3, 4, 5};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(dofs.reduced(i), expected[i]) << "DOF " << i;
  const Eigen::VectorXd full = Eigen::VectorXd::LinSpaced(12, 1, 12);
  const Eigen::VectorXd back = dofs.extend(dofs.restrict(full));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(back[i], dofs.reduced(i) >= 0 ? full[i] : 0.0);
}

// The contact Hessian projects its blocks over the points that move and treats a fixed vertex as
// a constant: a vertex with one free component moves, so it must not count as fixed.
TEST(DofMap, VertexIsFixedOnlyWhenAllItsComponentsAre) {
  const DofMap dofs({false, false, true, true, true, false, true, true, true, false, false, false});
  EXPECT_EQ(dofs.fixed_vertices(), (std::vector<bool>{false, false, true, false}));
  EXPECT_EQ(DofMap(3, {1}).fixed_vertices(), (std::vector<bool>{false, true, false}));
}

TEST(DofMap, RefusesFlagsThatAreNotThreePerVertex) {
  EXPECT_THROW(DofMap(std::vector<bool>{true, false}), std::invalid_argument);
}

}  // namespace
}  // namespace psq
