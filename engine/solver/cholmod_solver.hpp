#pragma once
// Sparse Cholesky through CHOLMOD's C API (supernodal LLᵀ), keeping the symbolic analysis
// explicitly so that it is redone only when the sparsity pattern changes.

#include <Eigen/SparseCore>
#include <memory>

#include "engine/core/error.hpp"

namespace psq {

/// The matrix given to CholmodSolver::factorize is not positive definite.
class NotPositiveDefiniteError : public NumericalError {
 public:
  NotPositiveDefiniteError(const std::string& message, Eigen::Index column)
      : NumericalError(message), column_(column) {}
  /// Column of the input matrix at which the factorization broke down.
  [[nodiscard]] Eigen::Index column() const { return column_; }

 private:
  Eigen::Index column_;
};

/// Owns a cholmod_common and a supernodal factor. Matrices are symmetric and given by their
/// upper triangle in compressed-column form (as SparseAssembler produces them).
///
/// Usage: analyze(A) whenever A's pattern changes, then factorize(A) for every new set of
/// values with that pattern, then solve(b) any number of times.
class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(CholmodSolver&&) noexcept;
  CholmodSolver& operator=(CholmodSolver&&) noexcept;

  /// Symbolic analysis of A's pattern: fill-reducing ordering (CHOLMOD's default choice among
  /// AMD/METIS/…) and supernode structure. Discards any previous factorization.
  void analyze(const Eigen::SparseMatrix<double>& upper);

  /// Numeric factorization of A + shift·I = LLᵀ (after the fill-reducing permutation) with the
  /// last analysis; A must have the analyzed pattern.
  /// @throws NumericalError when A has a non-finite entry (naming it).
  /// @throws NotPositiveDefiniteError when A + shift·I is not positive definite (naming the
  ///   column where the factorization broke down).
  void factorize(const Eigen::SparseMatrix<double>& upper, double shift = 0.0);

  /// x = (A + shift·I)⁻¹ b with the last successful factorization.
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::VectorXd& rhs);

  [[nodiscard]] bool analyzed() const;
  [[nodiscard]] bool factorized() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace psq
