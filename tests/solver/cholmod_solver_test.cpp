#include "engine/solver/cholmod_solver.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace psq {
namespace {

/// The upper triangle of a random sparse symmetric matrix, made positive definite by strict
/// diagonal dominance (diagonal = Σ|off-diagonal| + margin in each row).
Eigen::SparseMatrix<double> random_spd_upper(int n, double density, std::mt19937& rng,
                                             double margin = 1.0) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < j; ++i)
      if (unit(rng) < density) {
        const double a = value(rng);
        entries.emplace_back(i, j, a);
        row_sums[i] += std::abs(a);
        row_sums[j] += std::abs(a);
      }
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, row_sums[i] + margin);
  Eigen::SparseMatrix<double> upper(n, n);
  upper.setFromTriplets(entries.begin(), entries.end());
  upper.makeCompressed();
  return upper;
}

/// Same pattern, new values, still diagonally dominant.
void refill_values(Eigen::SparseMatrix<double>& upper, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-2.0, 2.0);
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(upper.rows());
  for (Eigen::Index c = 0; c < upper.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(upper, c); it; ++it)
      if (it.row() != c) {
        it.valueRef() = value(rng);
        row_sums[it.row()] += std::abs(it.value());
        row_sums[c] += std::abs(it.value());
      }
  for (Eigen::Index c = 0; c < upper.outerSize(); ++c) upper.coeffRef(c, c) = row_sums[c] + 0.5;
}

double relative_residual(const Eigen::SparseMatrix<double>& upper, const Eigen::VectorXd& x,
                         const Eigen::VectorXd& b, double shift = 0.0) {
  const Eigen::VectorXd ax = upper.selfadjointView<Eigen::Upper>() * x + shift * x;
  return (ax - b).norm() / b.norm();
}

TEST(CholmodSolver, SolvesRandomSpdSystem) {
  std::mt19937 rng(1);
  const Eigen::SparseMatrix<double> a = random_spd_upper(400, 0.02, rng);
  std::uniform_real_distribution<double> value(-500.0, 500.0);
  const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(400, [&] { return value(rng); });
  CholmodSolver solver;
  solver.analyze(a);
  solver.factorize(a);
  const Eigen::VectorXd x = solver.solve(b);
  EXPECT_LT(relative_residual(a, x, b), 1e-10);
}

TEST(CholmodSolver, ReusesAnalysisAcrossFactorizations) {
  std::mt19937 rng(2);
  Eigen::SparseMatrix<double> a = random_spd_upper(300, 0.03, rng);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(300, -1.0, 2.0);
  CholmodSolver solver;
  solver.analyze(a);
  for (int round = 0; round < 4; ++round) {
    refill_values(a, rng);
    solver.factorize(a);
    EXPECT_LT(relative_residual(a, solver.solve(b), b), 1e-10) << "round " << round;
  }
  // A shifted factorization with the same analysis solves (A + σI)x = b.
  solver.factorize(a, 3.5);
  EXPECT_LT(relative_residual(a, solver.solve(b), b, 3.5), 1e-10);
}

TEST(CholmodSolver, NonPositiveDefiniteNamesTheColumn) {
  // Diagonal matrix: the factorization must break down exactly at the negative entry.
  const int n = 12;
  Eigen::SparseMatrix<double> a(n, n);
  for (int i = 0; i < n; ++i) a.insert(i, i) = i == 7 ? -1.0 : 2.0;
  a.makeCompressed();
  CholmodSolver solver;
  solver.analyze(a);
  try {
    solver.factorize(a);
    FAIL() << "factorize accepted an indefinite matrix";
  } catch (const NotPositiveDefiniteError& error) {
    EXPECT_EQ(error.column(), 7);
    EXPECT_NE(std::string(error.what()).find("column 7"), std::string::npos) << error.what();
  }
  EXPECT_FALSE(solver.factorized());
  EXPECT_THROW((void)solver.solve(Eigen::VectorXd::Ones(n)), std::logic_error);

  // The same analysis still serves a positive definite matrix afterwards, and a shift that
  // makes the indefinite one definite is accepted.
  a.coeffRef(7, 7) = 4.0;
  solver.factorize(a);
  EXPECT_NEAR(solver.solve(Eigen::VectorXd::Ones(n))[7], 0.25, 1e-15);
  a.coeffRef(7, 7) = -1.0;
  solver.factorize(a, 1.5);
  EXPECT_NEAR(solver.solve(Eigen::VectorXd::Ones(n))[7], 2.0, 1e-14);
}

TEST(CholmodSolver, IndefiniteCoupledMatrixThrowsNumericalError) {
  std::mt19937 rng(9);
  Eigen::SparseMatrix<double> a = random_spd_upper(50, 0.1, rng);
  // A 2×2 principal block [[1, 3], [3, 1]] has eigenvalue −2.
  a.coeffRef(10, 10) = 1.0;
  a.coeffRef(20, 20) = 1.0;
  a.coeffRef(10, 20) = 3.0;
  a.makeCompressed();
  CholmodSolver solver;
  solver.analyze(a);
  EXPECT_THROW(solver.factorize(a), NumericalError);
}

TEST(CholmodSolver, NonFiniteEntryIsNamed) {
  std::mt19937 rng(3);
  Eigen::SparseMatrix<double> a = random_spd_upper(30, 0.1, rng);
  CholmodSolver solver;
  solver.analyze(a);
  a.coeffRef(4, 4) = std::numeric_limits<double>::quiet_NaN();
  try {
    solver.factorize(a);
    FAIL() << "factorize accepted a NaN entry";
  } catch (const NotPositiveDefiniteError&) {
    FAIL() << "NaN must not be reported as indefiniteness";
  } catch (const NumericalError& error) {
    EXPECT_NE(std::string(error.what()).find("(4, 4) is nan"), std::string::npos) << error.what();
  }
}

TEST(CholmodSolver, MisuseIsRejected) {
  std::mt19937 rng(4);
  const Eigen::SparseMatrix<double> a = random_spd_upper(20, 0.2, rng);
  CholmodSolver solver;
  EXPECT_FALSE(solver.analyzed());
  EXPECT_THROW(solver.factorize(a), std::logic_error);
  solver.analyze(a);
  EXPECT_TRUE(solver.analyzed());
  const Eigen::SparseMatrix<double> other = random_spd_upper(20, 0.5, rng);
  EXPECT_THROW(solver.factorize(other), std::logic_error);
  solver.factorize(a);
  EXPECT_THROW((void)solver.solve(Eigen::VectorXd::Ones(19)), std::invalid_argument);
}

}  // namespace
}  // namespace psq
