#pragma once
// Parallel loops over the elements of an energy term (triangles, hinges), shared by every
// per-element energy. Results are reproducible bit for bit from run to run: sums use a fixed
// reduction tree and gradients are scattered serially in element order.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Core>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/core/element_matrices.hpp"
#include "engine/core/error.hpp"

namespace psq {

/// Elements per parallel task: enough work to amortize scheduling; fixed so that the
/// deterministic reduction always splits the same way.
inline constexpr std::size_t element_grain_size = 256;

/// Runs body(e) for every element e in [0, count), in parallel.
template <class Body>
void parallel_for_elements(std::size_t count, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, element_grain_size),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t e = range.begin(); e != range.end(); ++e) body(e);
                    });
}

/// Σ_e term(e) over [0, count), in parallel, summed in the same order on every run.
template <class Term>
double parallel_element_sum(std::size_t count, const Term& term) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, count, element_grain_size), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        for (std::size_t e = range.begin(); e != range.end(); ++e) sum += term(e);
        return sum;
      },
      [](double a, double b) { return a + b; });
}

/// The positions of element e's vertices as columns, gathered from the flat position vector x
/// (size 3N); `stencils` lists StencilSize global vertices per element.
template <int StencilSize>
Eigen::Matrix<double, 3, StencilSize> element_positions(const Eigen::VectorXd& x,
                                                        const std::vector<int>& stencils,
                                                        std::size_t e) {
  Eigen::Matrix<double, 3, StencilSize> corners;
  for (int a = 0; a < StencilSize; ++a)
    corners.col(a) = x.segment<3>(3 * stencils[StencilSize * e + a]);
  return corners;
}

/// `size` doubles of scratch memory, not zeroed. It is the calling thread's kept buffer when
/// that is free, so that a gradient does not allocate, zero and page-fault in several MB each
/// time: that was 6 % of the samples of `perf record -D 3300 ./build/tests/bench_progressive
/// --vertices 50000 --scenes cylinder_compress --preview-only 1`. A nested use on the same
/// thread (a TBB thread that, waiting in one element loop, runs another's task) gets a buffer
/// of its own.
class ElementScratch {
 public:
  explicit ElementScratch(std::size_t size) {
    Kept& kept = thread_kept();
    if (!kept.in_use) {
      kept.in_use = true;
      kept_ = &kept;
      kept.values.resize(size);
      data_ = kept.values.data();
    } else {
      own_.resize(size);
      data_ = own_.data();
    }
  }
  ~ElementScratch() {
    if (kept_ != nullptr) kept_->in_use = false;
  }
  ElementScratch(const ElementScratch&) = delete;
  ElementScratch& operator=(const ElementScratch&) = delete;

  /// The memory; the pointer may be shared with the threads of a parallel loop.
  [[nodiscard]] double* data() const { return data_; }

 private:
  struct Kept {
    std::vector<double> values;
    bool in_use = false;
  };
  static Kept& thread_kept() {
    thread_local Kept kept;
    return kept;
  }

  Kept* kept_ = nullptr;
  std::vector<double> own_;
  double* data_ = nullptr;
};

/// g += Σ_e (element e's gradient scattered to its stencil). `stencils` lists StencilSize
/// global vertices per element; gradient(e) returns the 3·StencilSize vector ordered like the
/// stencil. Element gradients are computed in parallel into a buffer, then added serially in
/// element order: race-free and deterministic.
template <int StencilSize, class ElementGradient>
void add_element_gradients(const std::vector<int>& stencils, const ElementGradient& gradient,
                           Eigen::VectorXd& g) {
  constexpr int dofs = 3 * StencilSize;
  const std::size_t count = stencils.size() / StencilSize;
  const ElementScratch scratch(count * dofs);
  double* const buffer = scratch.data();
  parallel_for_elements(count, [&](std::size_t e) {
    Eigen::Map<Eigen::Matrix<double, dofs, 1>>(buffer + e * dofs) = gradient(e);
  });
  for (std::size_t e = 0; e < count; ++e)
    for (int a = 0; a < StencilSize; ++a)
      g.segment<3>(3 * stencils[e * StencilSize + a]) +=
          Eigen::Map<const Eigen::Vector3d>(buffer + e * dofs + 3 * a);
}

/// Writes hessian(e) as element e's block of `out`. The storage of `out` is reused when its
/// stencils already equal `stencils` (the common case from one Newton iteration to the next).
template <int StencilSize, class ElementHessian>
void fill_element_hessians(const std::vector<int>& stencils, const ElementHessian& hessian,
                           ElementMatrices& out) {
  if (out.stencil_size != StencilSize || out.vertices != stencils ||
      out.values.size() != out.element_count() * out.block_size())
    out.reset(StencilSize, stencils);
  parallel_for_elements(out.element_count(), [&](std::size_t e) { out.block(e) = hessian(e); });
}

/// Checks that x holds the vertices [first_vertex, first_vertex + vertex_count) and that their
/// coordinates are finite. Throws std::invalid_argument for a too-short x (a caller bug) and
/// NumericalError for NaN or infinite coordinates, naming `term`.
inline void check_positions(const Eigen::VectorXd& x, int first_vertex, int vertex_count,
                            const char* term) {
  if (x.size() < 3 * static_cast<Eigen::Index>(first_vertex + vertex_count))
    throw std::invalid_argument(std::string(term) + ": position vector too short for its shell");
  if (!x.segment(3 * first_vertex, 3 * vertex_count).allFinite())
    throw NumericalError(std::string(term) + ": non-finite vertex positions");
}

}  // namespace psq
