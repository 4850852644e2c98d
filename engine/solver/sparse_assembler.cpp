#include "engine/solver/sparse_assembler.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace psq {
namespace {

/// Rejects blocks whose sizes disagree with each other or with the DOF map: a bug upstream,
/// and cheap to catch here before it turns into out-of-bounds reads.
void check_sizes(const HessianBlocks& blocks, const DofMap& dofs) {
  if (blocks.diagonal.size() != 0 && blocks.diagonal.size() != dofs.full_size())
    throw std::invalid_argument(fmt::format("Hessian diagonal has {} entries, expected {}",
                                            blocks.diagonal.size(), dofs.full_size()));
  for (std::size_t b = 0; b < blocks.batches.size(); ++b) {
    const ElementMatrices& batch = blocks.batches[b];
    const bool stencil_ok = batch.stencil_size > 0 ? batch.vertices.size() % batch.stencil_size == 0
                                                   : batch.vertices.empty();
    if (!stencil_ok || batch.values.size() != batch.element_count() * batch.block_size())
      throw std::invalid_argument(fmt::format(
          "Hessian batch {}: stencil size {}, {} vertices and {} values do not match", b,
          batch.stencil_size, batch.vertices.size(), batch.values.size()));
  }
}

/// Slot of entry (row, col) in a compressed-column pattern whose columns hold sorted rows,
/// searched from slot `from` of that column on (a slot whose row is at most `row`) when given.
int find_slot(const Eigen::SparseMatrix<double>& pattern, int row, int col, int from = -1) {
  const int* inner = pattern.innerIndexPtr();
  const int* first = inner + std::max(from, pattern.outerIndexPtr()[col]);
  const int* last = inner + pattern.outerIndexPtr()[col + 1];
  return static_cast<int>(std::lower_bound(first, last, row) - inner);
}

/// The slots of one element's upper entries, packed as the scatter reads them ((i, j), i ≤ j,
/// at j(j+1)/2 + i), given the reduced index of each local DOF (−1: fixed). The entries are
/// visited column by column in increasing reduced order: a column holds sorted, distinct rows,
/// and the pattern holds every entry of the element, so a row one above the previous one lies in
/// the next slot, and only the first row of each vertex's run is searched for.
void element_slots(const Eigen::SparseMatrix<double>& pattern, const std::vector<int>& local,
                   std::vector<int>& order, int* slots) {
  const int m = static_cast<int>(local.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return local[a] < local[b]; });
  for (int jj = 0; jj < m; ++jj) {
    const int col = local[order[jj]];
    int previous_row = -2, previous_slot = -1;
    for (int ii = 0; ii <= jj; ++ii) {
      const int row = local[order[ii]];  // row ≤ col
      int slot = -1;
      if (row >= 0) {
        slot = row == previous_row + 1 ? previous_slot + 1
                                       : find_slot(pattern, row, col, previous_slot);
        previous_row = row;
        previous_slot = slot;
      }
      const int i = std::min(order[ii], order[jj]), j = std::max(order[ii], order[jj]);
      slots[j * (j + 1) / 2 + i] = slot;
    }
  }
}

bool repeats_a_vertex(const int* stencil, int size) {
  for (int a = 0; a < size; ++a)
    for (int b = a + 1; b < size; ++b)
      if (stencil[a] == stencil[b]) return true;
  return false;
}

bool has_free_dof(const DofMap& dofs, int vertex) {
  return dofs.reduced(3 * vertex) >= 0 || dofs.reduced(3 * vertex + 1) >= 0 ||
         dofs.reduced(3 * vertex + 2) >= 0;
}

/// Vertex-level upper adjacency: for each vertex, the sorted vertices ≤ it that share an
/// element with it (itself included). Built at vertex granularity because it is 9× smaller
/// than the DOF-level pattern it expands to.
struct VertexAdjacency {
  std::vector<int> start;  ///< size vertex_count + 1
  std::vector<int> rows;
};

VertexAdjacency upper_vertex_adjacency(const HessianBlocks& blocks, const DofMap& dofs) {
  const int vertex_count = static_cast<int>(dofs.full_size() / 3);
  std::vector<char> active(vertex_count);
  for (int v = 0; v < vertex_count; ++v) active[v] = has_free_dof(dofs, v);

  // Two passes over the element pairs: count per column vertex, then fill.
  std::vector<int> count(vertex_count + 1, 0);
  const auto for_each_pair = [&](auto&& visit) {
    for (const ElementMatrices& batch : blocks.batches) {
      const int s = batch.stencil_size;
      for (std::size_t e = 0; e < batch.element_count(); ++e) {
        const int* stencil = batch.vertices.data() + e * s;
        for (int a = 0; a < s; ++a)
          for (int b = a + 1; b < s; ++b) {
            const int va = stencil[a];
            const int vb = stencil[b];
            if (active[va] && active[vb]) visit(std::min(va, vb), std::max(va, vb));
          }
      }
    }
  };
  for (int v = 0; v < vertex_count; ++v) count[v] = active[v];
  for_each_pair([&](int, int col) { ++count[col]; });

  VertexAdjacency adjacency;
  adjacency.start.assign(vertex_count + 1, 0);
  for (int v = 0; v < vertex_count; ++v) adjacency.start[v + 1] = adjacency.start[v] + count[v];
  adjacency.rows.resize(adjacency.start[vertex_count]);
  std::vector<int> cursor(adjacency.start.begin(), adjacency.start.end() - 1);
  for (int v = 0; v < vertex_count; ++v)
    if (active[v]) adjacency.rows[cursor[v]++] = v;
  for_each_pair([&](int row, int col) { adjacency.rows[cursor[col]++] = row; });

  // Sort and deduplicate each column in place, compacting the array.
  int write = 0;
  for (int v = 0; v < vertex_count; ++v) {
    const auto first = adjacency.rows.begin() + adjacency.start[v];
    const auto last = adjacency.rows.begin() + adjacency.start[v + 1];
    std::sort(first, last);
    const auto unique_end = std::unique(first, last);
    adjacency.start[v] = write;
    write = static_cast<int>(std::copy(first, unique_end, adjacency.rows.begin() + write) -
                             adjacency.rows.begin());
  }
  adjacency.start[vertex_count] = write;
  adjacency.rows.resize(write);
  return adjacency;
}

}  // namespace

bool SparseAssembler::assemble(const HessianBlocks& blocks, const DofMap& dofs) {
  check_sizes(blocks, dofs);
  bool pattern_changed = false;
  if (rebuild_count_ == 0 || !stencils_match(blocks, dofs)) {
    pattern_changed = rebuild_pattern(blocks, dofs) || rebuild_count_ == 0;
    rebuild_scatter_map(blocks, dofs, pattern_changed);
    ++rebuild_count_;
  }
  scatter(blocks);
  return pattern_changed;
}

bool SparseAssembler::dofs_match(const DofMap& dofs) const {
  if (static_cast<Eigen::Index>(reduced_.size()) != dofs.full_size()) return false;
  for (std::size_t i = 0; i < reduced_.size(); ++i)
    if (reduced_[i] != dofs.reduced(static_cast<Eigen::Index>(i))) return false;
  return true;
}

bool SparseAssembler::batch_matches(std::size_t b, const ElementMatrices& batch) const {
  return b < batches_.size() && batch.stencil_size == batches_[b].stencil_size &&
         batch.vertices == batches_[b].vertices;
}

bool SparseAssembler::stencils_match(const HessianBlocks& blocks, const DofMap& dofs) const {
  if (!dofs_match(dofs) || blocks.batches.size() != batches_.size()) return false;
  for (std::size_t b = 0; b < batches_.size(); ++b)
    if (!batch_matches(b, blocks.batches[b])) return false;
  return true;
}

bool SparseAssembler::rebuild_pattern(const HessianBlocks& blocks, const DofMap& dofs) {
  const Eigen::Index vertex_count = dofs.full_size() / 3;
  for (std::size_t b = 0; b < blocks.batches.size(); ++b)
    for (int v : blocks.batches[b].vertices)
      if (v < 0 || v >= vertex_count)
        throw std::invalid_argument(fmt::format(
            "Hessian batch {} names vertex {}, outside [0, {})", b, v, vertex_count));

  const VertexAdjacency adjacency = upper_vertex_adjacency(blocks, dofs);
  const auto free_size = static_cast<int>(dofs.free_size());
  std::vector<int> outer(free_size + 1, 0);
  std::vector<int> inner;
  inner.reserve(adjacency.rows.size() * 9);
  int column = 0;
  for (Eigen::Index v = 0; v < vertex_count; ++v)
    for (int c = 0; c < 3; ++c) {
      const int col = dofs.reduced(3 * v + c);
      if (col < 0) continue;
      // Columns are emitted in full-DOF order, which must be their reduced order.
      if (col != column)
        throw std::invalid_argument("DofMap must number free DOFs in increasing order");
      outer[column++] = static_cast<int>(inner.size());
      for (int k = adjacency.start[v]; k < adjacency.start[v + 1]; ++k)
        for (int d = 0; d < 3; ++d) {
          const int row = dofs.reduced(3 * adjacency.rows[k] + d);
          if (row >= 0 && row <= col) inner.push_back(row);
        }
    }
  outer[free_size] = static_cast<int>(inner.size());

  const bool same = matrix_.rows() == free_size && matrix_.nonZeros() == outer[free_size] &&
                    std::equal(outer.begin(), outer.end(), matrix_.outerIndexPtr()) &&
                    std::equal(inner.begin(), inner.end(), matrix_.innerIndexPtr());
  if (same) return false;
  matrix_.resize(free_size, free_size);
  matrix_.resizeNonZeros(outer[free_size]);
  std::copy(outer.begin(), outer.end(), matrix_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), matrix_.innerIndexPtr());
  return true;
}

void SparseAssembler::rebuild_scatter_map(const HessianBlocks& blocks, const DofMap& dofs,
                                          bool pattern_changed) {
  const bool slots_kept = !pattern_changed && dofs_match(dofs);
  reduced_.resize(static_cast<std::size_t>(dofs.full_size()));
  diagonal_slots_.resize(reduced_.size());
  for (std::size_t i = 0; i < reduced_.size(); ++i) {
    const int r = dofs.reduced(static_cast<Eigen::Index>(i));
    reduced_[i] = r;
    diagonal_slots_[i] = r < 0 ? -1 : find_slot(matrix_, r, r);
  }

  batches_.resize(blocks.batches.size());
  for (std::size_t b = 0; b < batches_.size(); ++b)
    if (!(slots_kept && batch_matches(b, blocks.batches[b])))
      rebuild_batch_map(blocks.batches[b], batches_[b]);
}

void SparseAssembler::rebuild_batch_map(const ElementMatrices& batch, BatchMap& map) const {
  map.stencil_size = batch.stencil_size;
  map.vertices = batch.vertices;
  map.mirrored.clear();
  const int m = batch.dofs_per_element();
  const std::size_t upper_size = static_cast<std::size_t>(m) * (m + 1) / 2;
  map.slots.resize(batch.element_count() * upper_size);
  const auto local_dofs = [&](std::size_t e, std::vector<int>& local) {
    for (int k = 0; k < m; ++k)
      local[k] = reduced_[3 * batch.vertices[e * batch.stencil_size + k / 3] + k % 3];
  };
  // Each element fills its own slots, so the lookups run in parallel: a pattern change, as
  // contact pairs come and go, redoes them for every element of every batch.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batch.element_count(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<int> local(m), order(m);
                      for (std::size_t e = range.begin(); e != range.end(); ++e) {
                        local_dofs(e, local);
                        element_slots(matrix_, local, order, map.slots.data() + e * upper_size);
                      }
                    });
  // Two local DOFs coincide only where the stencil lists a vertex twice. In element order, so
  // that the scatter sums them in the same order on every run.
  std::vector<int> local(m);
  for (std::size_t e = 0; e < batch.element_count(); ++e) {
    if (!repeats_a_vertex(batch.vertices.data() + e * batch.stencil_size, batch.stencil_size))
      continue;
    local_dofs(e, local);
    const int* slot = map.slots.data() + e * upper_size;
    for (int j = 0; j < m; ++j)
      for (int i = 0; i <= j; ++i, ++slot)
        if (i < j && local[i] == local[j] && local[i] >= 0)
          map.mirrored.emplace_back(e * batch.block_size() + static_cast<std::size_t>(i) * m + j,
                                    *slot);
  }
}

void SparseAssembler::scatter(const HessianBlocks& blocks) {
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  if (blocks.diagonal.size() != 0)
    for (std::size_t i = 0; i < diagonal_slots_.size(); ++i)
      if (diagonal_slots_[i] >= 0)
        values[diagonal_slots_[i]] += blocks.diagonal[static_cast<Eigen::Index>(i)];

  for (std::size_t b = 0; b < batches_.size(); ++b) {
    const ElementMatrices& batch = blocks.batches[b];
    const BatchMap& map = batches_[b];
    const int m = batch.dofs_per_element();
    const int* slot = map.slots.data();
    const double* block = batch.values.data();
    for (std::size_t e = 0; e < batch.element_count(); ++e, block += batch.block_size())
      for (int j = 0; j < m; ++j) {
        const double* column = block + static_cast<std::ptrdiff_t>(j) * m;
        for (int i = 0; i <= j; ++i, ++slot)
          if (*slot >= 0) values[*slot] += column[i];
      }
    for (const auto& [index, target] : map.mirrored) values[target] += batch.values[index];
  }
}

}  // namespace psq
