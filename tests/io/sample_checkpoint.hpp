#pragma once
// A checkpoint with every field filled with distinct, non-round values, and a field-by-field
// comparison, shared by the checkpoint and XDMF tests.

#include <gtest/gtest.h>

#include <cmath>

#include "engine/io/checkpoint.hpp"

namespace psq::test {

/// A k×k grid of vertices on a bumpy sheet, two triangles per cell, at `level` and `frame`.
inline Checkpoint sample_checkpoint(int k, int level, int frame) {
  Checkpoint c;
  c.code_version = "0.1.0-test";
  c.parameters = R"({"material":{"E":1.5e6,"nu":0.3},"thickness":0.001,"name":"drapé \"sheet\""})";
  c.level = level;
  c.frame = frame;
  c.time = 0.1 * frame + 1e-17;
  const int n = k * k;
  c.rest_positions.resize(n, 3);
  c.positions.resize(n, 3);
  c.finest_positions.resize(2 * n, 3);
  c.solver.previous_positions.resize(n, 3);
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      const int v = i * k + j;
      const double x = i / (k - 1.0), y = j / (k - 1.0);
      c.rest_positions.row(v) << x, y, 0.0;
      c.positions.row(v) << x + 1e-3 * std::sin(3 * x), y, -0.05 * std::sin(M_PI * x) * y;
      c.solver.previous_positions.row(v) << x, y, -0.04 * std::sin(M_PI * x) * y;
      c.finest_positions.row(2 * v) = c.positions.row(v);
      c.finest_positions.row(2 * v + 1) << x, y, 0.5;
    }
  }
  c.triangles.resize(2 * (k - 1) * (k - 1), 3);
  int t = 0;
  for (int i = 0; i + 1 < k; ++i) {
    for (int j = 0; j + 1 < k; ++j) {
      const int v = i * k + j;
      c.triangles.row(t++) << v, v + k, v + 1;
      c.triangles.row(t++) << v + 1, v + k, v + k + 1;
    }
  }
  c.solver.progress = LevelProgress::inside_frame;
  c.solver.iterations_in_frame = 3;
  c.solver.scalars = {{"barrier_stiffness", 1234.5678}, {"friction_lag", 2.0}};
  for (int it = 0; it < 7; ++it)
    c.statistics.iterations.push_back({frame - it / 4, it % 4, -1.0 / (it + 3), std::pow(0.1, it),
                                       std::pow(0.2, it), it % 3 == 0 ? 0.5 : 1.0, 0.01 * it});
  c.statistics.timings = {{"assembly", 0.125}, {"factorization", 0.375}, {"wall", 1.0 / 3.0}};
  c.statistics.refinement = {{"expansions", 12.0}, {"final_gap", 1.0 / 7.0}, {"seconds", 0.25}};
  return c;
}

/// Every field of `actual` equals the one of `expected`, bit for bit.
inline void expect_same_checkpoint(const Checkpoint& actual, const Checkpoint& expected) {
  EXPECT_EQ(actual.schema_version, expected.schema_version);
  EXPECT_EQ(actual.code_version, expected.code_version);
  EXPECT_EQ(actual.parameters, expected.parameters);
  EXPECT_EQ(actual.level, expected.level);
  EXPECT_EQ(actual.frame, expected.frame);
  EXPECT_EQ(actual.time, expected.time);
  auto same = [](const auto& a, const auto& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && (a.size() == 0 || a == b);
  };
  EXPECT_TRUE(same(actual.positions, expected.positions));
  EXPECT_TRUE(same(actual.rest_positions, expected.rest_positions));
  EXPECT_TRUE(same(actual.triangles, expected.triangles));
  EXPECT_TRUE(same(actual.finest_positions, expected.finest_positions));
  EXPECT_TRUE(same(actual.solver.previous_positions, expected.solver.previous_positions));
  EXPECT_EQ(actual.solver.progress, expected.solver.progress);
  EXPECT_EQ(actual.solver.iterations_in_frame, expected.solver.iterations_in_frame);
  EXPECT_EQ(actual.solver.scalars, expected.solver.scalars);
  EXPECT_EQ(actual.statistics.iterations, expected.statistics.iterations);
  EXPECT_EQ(actual.statistics.timings, expected.statistics.timings);
  EXPECT_EQ(actual.statistics.refinement, expected.statistics.refinement);
}

}  // namespace psq::test
