#include "engine/solver/cholmod_solver.hpp"

#include <cholmod.h>
#include <fmt/format.h>

#include <cmath>
#include <new>
#include <stdexcept>

#include "engine/solver/factorization_threads.hpp"

namespace psq {
namespace {

/// A cholmod_sparse header over the arrays of an Eigen matrix (no copy). CHOLMOD only reads
/// them, hence the const_casts its C API requires.
cholmod_sparse view_upper(const Eigen::SparseMatrix<double>& upper) {
  if (!upper.isCompressed() || upper.rows() != upper.cols())
    throw std::invalid_argument("CHOLMOD needs a square matrix in compressed form");
  cholmod_sparse view{};
  view.nrow = static_cast<std::size_t>(upper.rows());
  view.ncol = static_cast<std::size_t>(upper.cols());
  view.nzmax = static_cast<std::size_t>(upper.nonZeros());
  view.p = const_cast<int*>(upper.outerIndexPtr());
  view.i = const_cast<int*>(upper.innerIndexPtr());
  view.x = const_cast<double*>(upper.valuePtr());
  view.stype = 1;  // symmetric, upper triangle stored: the fastest input for a permuted LLᵀ
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  return view;
}

/// CHOLMOD may silently factorize NaN into garbage, so non-finite input is caught here.
void check_finite(const Eigen::SparseMatrix<double>& upper) {
  for (Eigen::Index col = 0; col < upper.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(upper, col); it; ++it)
      if (!std::isfinite(it.value()))
        throw NumericalError(fmt::format("matrix entry ({}, {}) is {}", it.row(), col, it.value()));
}

/// Turns a failed CHOLMOD call into an exception; warnings other than "not positive definite"
/// (handled by the caller) are not failures.
void check_status(const cholmod_common& common, const char* call) {
  if (common.status == CHOLMOD_OUT_OF_MEMORY) throw std::bad_alloc();
  if (common.status < CHOLMOD_OK)
    throw Error(fmt::format("CHOLMOD {} failed with status {}", call, common.status));
}

}  // namespace

struct CholmodSolver::State {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  Eigen::Index analyzed_nonzeros = 0;
  bool factorized = false;

  State() {
    use_single_threaded_factorization();
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;  // the engine never prints; failures become exceptions
  }
  State(const State&) = delete;
  State& operator=(const State&) = delete;
  ~State() {
    cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
};

CholmodSolver::CholmodSolver() : state_(std::make_unique<State>()) {}
CholmodSolver::~CholmodSolver() = default;
CholmodSolver::CholmodSolver(CholmodSolver&&) noexcept = default;
CholmodSolver& CholmodSolver::operator=(CholmodSolver&&) noexcept = default;

bool CholmodSolver::analyzed() const { return state_->factor != nullptr; }
bool CholmodSolver::factorized() const { return state_->factorized; }

void CholmodSolver::analyze(const Eigen::SparseMatrix<double>& upper) {
  cholmod_sparse view = view_upper(upper);
  cholmod_free_factor(&state_->factor, &state_->common);
  state_->factorized = false;
  state_->factor = cholmod_analyze(&view, &state_->common);
  check_status(state_->common, "analyze");
  if (state_->factor == nullptr) throw Error("CHOLMOD analyze returned no factor");
  state_->analyzed_nonzeros = upper.nonZeros();
}

void CholmodSolver::factorize(const Eigen::SparseMatrix<double>& upper, double shift) {
  if (!analyzed()) throw std::logic_error("CholmodSolver::factorize called before analyze");
  if (static_cast<std::size_t>(upper.rows()) != state_->factor->n ||
      upper.nonZeros() != state_->analyzed_nonzeros)
    throw std::logic_error("CholmodSolver::factorize: the pattern differs from the analyzed one");
  check_finite(upper);
  if (!std::isfinite(shift)) throw NumericalError(fmt::format("diagonal shift is {}", shift));

  cholmod_sparse view = view_upper(upper);
  double beta[2] = {shift, 0.0};
  state_->factorized = false;
  cholmod_factorize_p(&view, beta, nullptr, 0, state_->factor, &state_->common);
  check_status(state_->common, "factorize");
  if (state_->common.status == CHOLMOD_NOT_POSDEF) {
    // L->minor counts columns of the permuted matrix PAPᵀ; Perm maps it back to A's column.
    const auto pivot = static_cast<Eigen::Index>(state_->factor->minor);
    const auto* perm = static_cast<const int*>(state_->factor->Perm);
    const Eigen::Index column = perm != nullptr ? perm[pivot] : pivot;
    throw NotPositiveDefiniteError(
        fmt::format("matrix{} is not positive definite: Cholesky broke down at column {} "
                    "(pivot {} of {} in the fill-reducing order)",
                    shift != 0.0 ? fmt::format(" + {:g}·I", shift) : "", column, pivot,
                    upper.rows()),
        column);
  }
  state_->factorized = true;
}

Eigen::VectorXd CholmodSolver::solve(const Eigen::VectorXd& rhs) {
  if (!factorized()) throw std::logic_error("CholmodSolver::solve called without a factorization");
  if (static_cast<std::size_t>(rhs.size()) != state_->factor->n)
    throw std::invalid_argument(fmt::format("right-hand side has {} entries, the matrix {}",
                                            rhs.size(), state_->factor->n));
  cholmod_dense b{};
  b.nrow = b.nzmax = b.d = static_cast<std::size_t>(rhs.size());
  b.ncol = 1;
  b.x = const_cast<double*>(rhs.data());
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, state_->factor, &b, &state_->common);
  check_status(state_->common, "solve");
  Eigen::VectorXd solution =
      Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x->x), rhs.size());
  cholmod_free_dense(&x, &state_->common);
  return solution;
}

}  // namespace psq
