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

}  // namespace
}  // namespace psq
