#include "engine/solver/sparse_assembler.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <stdexcept>

namespace psq {
namespace {

/// Random symmetric element blocks on random distinct stencils, so elements overlap.
ElementMatrices random_batch(int stencil_size, int element_count, int vertex_count,
                             std::mt19937& rng) {
  std::vector<int> vertices;
  std::uniform_int_distribution<int> pick(0, vertex_count - 1);
  for (int e = 0; e < element_count; ++e) {
    std::vector<int> stencil;
    while (static_cast<int>(stencil.size()) < stencil_size) {
      const int v = pick(rng);
      if (std::find(stencil.begin(), stencil.end(), v) == stencil.end()) stencil.push_back(v);
    }
    vertices.insert(vertices.end(), stencil.begin(), stencil.end());
  }
  ElementMatrices batch;
  batch.reset(stencil_size, vertices);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  for (std::size_t e = 0; e < batch.element_count(); ++e) {
    Eigen::MatrixXd r(batch.dofs_per_element(), batch.dofs_per_element());
    for (Eigen::Index i = 0; i < r.size(); ++i) r.data()[i] = value(rng);
    batch.block(e) = r + r.transpose();
  }
  return batch;
}

HessianBlocks random_blocks(int vertex_count, std::mt19937& rng) {
  HessianBlocks blocks;
  std::uniform_real_distribution<double> value(0.5, 2.0);
  blocks.diagonal = Eigen::VectorXd::NullaryExpr(3 * vertex_count, [&] { return value(rng); });
  blocks.batches.push_back(random_batch(3, 15, vertex_count, rng));
  blocks.batches.push_back(random_batch(4, 10, vertex_count, rng));
  blocks.batches.push_back(random_batch(2, 8, vertex_count, rng));
  return blocks;
}

/// Brute force: every block entry added to a dense full matrix, then the free rows/columns.
Eigen::MatrixXd dense_reference(const HessianBlocks& blocks, const DofMap& dofs) {
  const Eigen::Index n = dofs.full_size();
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n, n);
  if (blocks.diagonal.size() != 0) full.diagonal() += blocks.diagonal;
  for (const ElementMatrices& batch : blocks.batches)
    for (std::size_t e = 0; e < batch.element_count(); ++e) {
      const auto block = batch.block(e);
      const auto dof = [&](Eigen::Index k) {
        return 3 * batch.vertices[e * batch.stencil_size + k / 3] + k % 3;
      };
      for (Eigen::Index i = 0; i < block.rows(); ++i)
        for (Eigen::Index j = 0; j < block.cols(); ++j) full(dof(i), dof(j)) += block(i, j);
    }
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(dofs.free_size(), dofs.free_size());
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      if (dofs.reduced(i) >= 0 && dofs.reduced(j) >= 0)
        reduced(dofs.reduced(i), dofs.reduced(j)) = full(i, j);
  return reduced;
}

Eigen::MatrixXd dense_symmetric(const Eigen::SparseMatrix<double>& upper) {
  const Eigen::MatrixXd u = Eigen::MatrixXd(upper);
  return Eigen::MatrixXd(u.selfadjointView<Eigen::Upper>());
}

void expect_matches_reference(const SparseAssembler& assembler, const HessianBlocks& blocks,
                              const DofMap& dofs) {
  const Eigen::MatrixXd expected = dense_reference(blocks, dofs);
  ASSERT_EQ(assembler.matrix().rows(), expected.rows());
  EXPECT_LT((dense_symmetric(assembler.matrix()) - expected).norm(), 1e-12 * expected.norm());
}

/// Replaces every block value with new random symmetric values, keeping the stencils.
void randomize_values(HessianBlocks& blocks, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-3.0, 3.0);
  for (ElementMatrices& batch : blocks.batches)
    for (std::size_t e = 0; e < batch.element_count(); ++e) {
      const Eigen::MatrixXd r =
          Eigen::MatrixXd::NullaryExpr(batch.dofs_per_element(), batch.dofs_per_element(),
                                       [&] { return value(rng); });
      batch.block(e) = r + r.transpose();
    }
  blocks.diagonal = blocks.diagonal.unaryExpr([&](double) { return value(rng); });
}

TEST(SparseAssembler, MatchesDenseSumWithFixedDofs) {
  std::mt19937 rng(7);
  const int vertex_count = 14;
  const HessianBlocks blocks = random_blocks(vertex_count, rng);
  const DofMap dofs(vertex_count, {2, 9, 13});
  SparseAssembler assembler;
  EXPECT_TRUE(assembler.assemble(blocks, dofs));
  expect_matches_reference(assembler, blocks, dofs);
}

TEST(SparseAssembler, PatternIsSortedUpperTriangleWithFullDiagonal) {
  std::mt19937 rng(3);
  const int vertex_count = 10;
  const DofMap dofs(vertex_count, {0, 5});
  SparseAssembler assembler;
  assembler.assemble(random_blocks(vertex_count, rng), dofs);
  const Eigen::SparseMatrix<double>& m = assembler.matrix();
  ASSERT_TRUE(m.isCompressed());
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    const int* rows = m.innerIndexPtr();
    const int first = m.outerIndexPtr()[c];
    const int last = m.outerIndexPtr()[c + 1];
    ASSERT_GT(last, first);
    EXPECT_EQ(rows[last - 1], c) << "diagonal must close column " << c;
    for (int k = first + 1; k < last; ++k) EXPECT_LT(rows[k - 1], rows[k]);
  }
}

TEST(SparseAssembler, DiagonalOnlyAndEmptyDiagonal) {
  const DofMap dofs(3, {1});
  HessianBlocks blocks;
  blocks.diagonal = Eigen::VectorXd::LinSpaced(9, 1.0, 9.0);
  SparseAssembler assembler;
  assembler.assemble(blocks, dofs);
  const Eigen::MatrixXd expected =
      Eigen::VectorXd((Eigen::VectorXd(6) << 1, 2, 3, 7, 8, 9).finished()).asDiagonal();
  EXPECT_EQ(dense_symmetric(assembler.matrix()), expected);

  std::mt19937 rng(11);
  HessianBlocks no_diagonal;
  no_diagonal.batches.push_back(random_batch(2, 3, 3, rng));
  assembler.assemble(no_diagonal, dofs);
  expect_matches_reference(assembler, no_diagonal, dofs);
}

TEST(SparseAssembler, RepeatedVertexInStencilAddsBothMirrorEntries) {
  const DofMap dofs(4, {3});
  HessianBlocks blocks;
  ElementMatrices batch;
  batch.reset(3, {1, 2, 1});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const Eigen::MatrixXd r = Eigen::MatrixXd::NullaryExpr(9, 9, [&] { return value(rng); });
  batch.block(0) = r + r.transpose();
  blocks.batches.push_back(batch);
  SparseAssembler assembler;
  assembler.assemble(blocks, dofs);
  expect_matches_reference(assembler, blocks, dofs);
}

TEST(SparseAssembler, ReusesPatternWhileStencilsAreUnchanged) {
  std::mt19937 rng(21);
  const int vertex_count = 40;  // sparse enough that new stencils change the pattern
  const DofMap dofs(vertex_count, {4});
  HessianBlocks blocks = random_blocks(vertex_count, rng);
  SparseAssembler assembler;
  EXPECT_TRUE(assembler.assemble(blocks, dofs));
  EXPECT_EQ(assembler.rebuild_count(), 1u);

  randomize_values(blocks, rng);
  EXPECT_FALSE(assembler.assemble(blocks, dofs));
  EXPECT_EQ(assembler.rebuild_count(), 1u);
  expect_matches_reference(assembler, blocks, dofs);

  // New stencils: rebuilt, and the new pattern differs.
  blocks.batches[1] = random_batch(4, 12, vertex_count, rng);
  EXPECT_TRUE(assembler.assemble(blocks, dofs));
  EXPECT_EQ(assembler.rebuild_count(), 2u);
  expect_matches_reference(assembler, blocks, dofs);

  // Values only again: reused.
  randomize_values(blocks, rng);
  EXPECT_FALSE(assembler.assemble(blocks, dofs));
  EXPECT_EQ(assembler.rebuild_count(), 2u);
  expect_matches_reference(assembler, blocks, dofs);
}

TEST(SparseAssembler, ReorderedStencilRebuildsMapButKeepsPattern) {
  std::mt19937 rng(8);
  const int vertex_count = 9;
  const DofMap dofs(vertex_count, {});
  HessianBlocks blocks = random_blocks(vertex_count, rng);
  SparseAssembler assembler;
  assembler.assemble(blocks, dofs);

  // Rotate the vertex order of the first triangle and permute its block to match: the same
  // matrix, a different scatter map, the same pattern.
  ElementMatrices& triangles = blocks.batches[0];
  std::rotate(triangles.vertices.begin(), triangles.vertices.begin() + 1,
              triangles.vertices.begin() + 3);
  Eigen::PermutationMatrix<9> rotate;
  rotate.indices() << 6, 7, 8, 0, 1, 2, 3, 4, 5;  // old local vertex k sits at (k + 2) % 3
  const Eigen::MatrixXd old_block = triangles.block(0);
  triangles.block(0) = rotate * old_block * rotate.transpose();

  EXPECT_FALSE(assembler.assemble(blocks, dofs));
  EXPECT_EQ(assembler.rebuild_count(), 2u);
  expect_matches_reference(assembler, blocks, dofs);
}

TEST(SparseAssembler, NewStencilsWithinThePatternKeepTheOtherBatchesMaps) {
  // Contact pairs that come and go between vertices the elastic elements already couple leave
  // the pattern as it is: only their batch's map is rebuilt, and the sum stays exact.
  std::mt19937 rng(31);
  const int vertex_count = 30;
  const DofMap dofs(vertex_count, {3});
  HessianBlocks blocks = random_blocks(vertex_count, rng);
  // Edges of every other triangle of batch 0, starting at its corner `first`.
  const auto triangle_edges = [&](int first) {
    const ElementMatrices& triangles = blocks.batches[0];
    std::vector<int> pairs;
    for (std::size_t e = 0; e < triangles.element_count(); e += 2)
      for (int k = 0; k < 3; ++k) {
        pairs.push_back(triangles.vertices[3 * e + (k + first) % 3]);
        pairs.push_back(triangles.vertices[3 * e + (k + first + 1) % 3]);
      }
    return pairs;
  };
  blocks.batches[2].reset(2, triangle_edges(0));
  randomize_values(blocks, rng);
  SparseAssembler assembler;
  EXPECT_TRUE(assembler.assemble(blocks, dofs));
  for (int round = 1; round <= 3; ++round) {
    std::vector<int> pairs = triangle_edges(round % 2);
    if (round == 3) pairs.resize(4);  // fewer pairs, still coupled
    blocks.batches[2].reset(2, std::move(pairs));
    randomize_values(blocks, rng);
    EXPECT_FALSE(assembler.assemble(blocks, dofs)) << round;
    EXPECT_EQ(assembler.rebuild_count(), 1u + round);
    expect_matches_reference(assembler, blocks, dofs);
    // Then values only: nothing rebuilt.
    randomize_values(blocks, rng);
    EXPECT_FALSE(assembler.assemble(blocks, dofs));
    EXPECT_EQ(assembler.rebuild_count(), 1u + round);
    expect_matches_reference(assembler, blocks, dofs);
  }
}

TEST(SparseAssembler, ChangedDofMapRebuilds) {
  std::mt19937 rng(4);
  const int vertex_count = 10;
  const HessianBlocks blocks = random_blocks(vertex_count, rng);
  SparseAssembler assembler;
  assembler.assemble(blocks, DofMap(vertex_count, {1}));
  const DofMap more_pinned(vertex_count, {1, 6});
  EXPECT_TRUE(assembler.assemble(blocks, more_pinned));
  EXPECT_EQ(assembler.rebuild_count(), 2u);
  expect_matches_reference(assembler, blocks, more_pinned);
}

TEST(SparseAssembler, RejectsInconsistentBlocks) {
  const DofMap dofs(4, {});
  SparseAssembler assembler;
  HessianBlocks wrong_diagonal;
  wrong_diagonal.diagonal = Eigen::VectorXd::Ones(5);
  EXPECT_THROW(assembler.assemble(wrong_diagonal, dofs), std::invalid_argument);

  HessianBlocks out_of_range;
  out_of_range.batches.emplace_back().reset(2, {0, 4});
  EXPECT_THROW(assembler.assemble(out_of_range, dofs), std::invalid_argument);

  HessianBlocks short_values;
  short_values.batches.emplace_back().reset(2, {0, 1});
  short_values.batches.back().values.pop_back();
  EXPECT_THROW(assembler.assemble(short_values, dofs), std::invalid_argument);
}

}  // namespace
}  // namespace psq
