#include "engine/elastic/element_loop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/core/error.hpp"

namespace psq {
namespace {

/// Many elements over few vertices, so parallel tasks share vertices heavily.
constexpr int kVertices = 50;
constexpr std::size_t kElements = 20000;

std::vector<int> random_stencils(int stencil_size) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> vertex(0, kVertices - 1);
  std::vector<int> stencils(kElements * stencil_size);
  for (int& v : stencils) v = vertex(rng);
  return stencils;
}

Eigen::Matrix<double, 9, 1> element_gradient(std::size_t e) {
  Eigen::Matrix<double, 9, 1> g;
  for (int i = 0; i < 9; ++i) g[i] = std::sin(0.37 * e + 1.3 * i) / (1.0 + e % 7);
  return g;
}

TEST(ElementLoop, SumIsReproducibleAndMatchesTheSerialSum) {
  const auto term = [](std::size_t e) { return std::exp(std::sin(0.1 * e)) * 1e-3 * (e % 13); };
  double serial = 0;
  for (std::size_t e = 0; e < kElements; ++e) serial += term(e);
  const double first = parallel_element_sum(kElements, term);
  EXPECT_NEAR(first, serial, 1e-12 * std::abs(serial));
  for (int run = 0; run < 5; ++run) EXPECT_EQ(parallel_element_sum(kElements, term), first);
}

TEST(ElementLoop, GradientScatterEqualsTheSerialScatterBitForBit) {
  const std::vector<int> stencils = random_stencils(3);
  Eigen::VectorXd serial = Eigen::VectorXd::Zero(3 * kVertices);
  for (std::size_t e = 0; e < kElements; ++e) {
    const Eigen::Matrix<double, 9, 1> g = element_gradient(e);
    for (int a = 0; a < 3; ++a) serial.segment<3>(3 * stencils[3 * e + a]) += g.segment<3>(3 * a);
  }
  for (int run = 0; run < 3; ++run) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * kVertices);
    add_element_gradients<3>(stencils, element_gradient, g);
    EXPECT_TRUE((g.array() == serial.array()).all());
  }
}

TEST(ElementLoop, NestedGradientScattersOnOneThreadKeepTheirOwnBuffers) {
  // An element gradient that itself runs a gradient loop (as a TBB thread waiting in one loop
  // may run another loop's task): the inner loop must not overwrite the outer one's buffer.
  const std::vector<int> outer_stencils = random_stencils(3);
  const std::vector<int> inner_stencils(3 * 64, 0);
  const auto inner_sum = [&]() {
    Eigen::VectorXd inner = Eigen::VectorXd::Zero(3 * kVertices);
    // Other values than the outer loop's first elements, so that an overwrite would show.
    add_element_gradients<3>(
        inner_stencils, [](std::size_t e) { return element_gradient(e + 7919); }, inner);
    return inner[0];
  };
  const double inner_first = inner_sum();
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(3 * kVertices);
  add_element_gradients<3>(outer_stencils, element_gradient, expected);

  Eigen::VectorXd nested = Eigen::VectorXd::Zero(3 * kVertices);
  add_element_gradients<3>(
      outer_stencils,
      [&](std::size_t e) -> Eigen::Matrix<double, 9, 1> {
        // Every 1000th element runs the inner loop; its value is known, so it adds nothing.
        if (e % 1000 == 0 && inner_sum() != inner_first) return Eigen::Matrix<double, 9, 1>::Ones();
        return element_gradient(e);
      },
      nested);
  EXPECT_TRUE((nested.array() == expected.array()).all());
}

TEST(ElementLoop, HessianFillWritesEveryBlockAndKeepsMatchingStorage) {
  const std::vector<int> stencils = random_stencils(2);
  const auto block = [](std::size_t e) {
    return Eigen::Matrix<double, 6, 6>::Constant(static_cast<double>(e));
  };
  ElementMatrices out;
  fill_element_hessians<2>(stencils, block, out);
  ASSERT_EQ(out.element_count(), kElements);
  EXPECT_EQ(out.vertices, stencils);
  for (std::size_t e = 0; e < kElements; e += 997)
    EXPECT_TRUE((out.block(e).array() == static_cast<double>(e)).all());
  const double* storage = out.values.data();
  fill_element_hessians<2>(stencils, block, out);
  EXPECT_EQ(out.values.data(), storage);
}

TEST(ElementLoop, PositionCheckRejectsShortAndNonFiniteVectors) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(12);
  EXPECT_NO_THROW(check_positions(x, 1, 3, "test"));
  EXPECT_THROW(check_positions(x, 2, 3, "test"), std::invalid_argument);
  x[3] = std::nan("");
  EXPECT_THROW(check_positions(x, 1, 3, "test"), NumericalError);
  EXPECT_NO_THROW(check_positions(x, 2, 2, "test"));  // the NaN belongs to another shell
}

}  // namespace
}  // namespace psq
