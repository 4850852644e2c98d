#include "engine/solver/newton.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "engine/core/psd_projection.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The message of the NumericalError thrown by f, or "" when none is thrown.
template <class F>
std::string numerical_error_message(F&& f) {
  try {
    f();
  } catch (const NumericalError& error) {
    return error.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// E = ½ Σᵢ aᵢ (xᵢ − bᵢ)² + ½ Σ_springs k |x_p − x_q|²: a quadratic with a diagonal and
/// coupling element blocks, minimized by one exact Newton step.
class Quadratic : public Objective {
 public:
  Quadratic(Eigen::VectorXd a, Eigen::VectorXd b, std::vector<int> springs, double k)
      : a_(std::move(a)), b_(std::move(b)), springs_(std::move(springs)), k_(k) {}

  [[nodiscard]] Eigen::Index size() const override { return a_.size(); }
  double value(const Eigen::VectorXd& x) override {
    double e = 0.5 * (a_.array() * (x - b_).array().square()).sum();
    for (std::size_t s = 0; s < springs_.size(); s += 2) {
      const Eigen::Vector3d d = x.segment<3>(3 * springs_[s]) - x.segment<3>(3 * springs_[s + 1]);
      e += 0.5 * k_ * d.squaredNorm();
    }
    return e;
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    g = a_.cwiseProduct(x - b_);
    for (std::size_t s = 0; s < springs_.size(); s += 2) {
      const Eigen::Vector3d f =
          k_ * (x.segment<3>(3 * springs_[s]) - x.segment<3>(3 * springs_[s + 1]));
      g.segment<3>(3 * springs_[s]) += f;
      g.segment<3>(3 * springs_[s + 1]) -= f;
    }
  }
  void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
    h.diagonal = a_;
    h.batches.resize(1);
    h.batches[0].reset(2, springs_);
    for (std::size_t e = 0; e < h.batches[0].element_count(); ++e) {
      auto block = h.batches[0].block(e);
      const Eigen::Matrix3d i3 = k_ * Eigen::Matrix3d::Identity();
      block << i3, -i3, -i3, i3;
    }
  }
  /// The same quadratic as a dense matrix: E = ½ xᵀQx − cᵀx + const.
  [[nodiscard]] Eigen::MatrixXd dense_matrix() const {
    Eigen::MatrixXd q = a_.asDiagonal();
    for (std::size_t s = 0; s < springs_.size(); s += 2)
      for (int c = 0; c < 3; ++c) {
        const int p = 3 * springs_[s] + c;
        const int r = 3 * springs_[s + 1] + c;
        q(p, p) += k_;
        q(r, r) += k_;
        q(p, r) -= k_;
        q(r, p) -= k_;
      }
    return q;
  }
  [[nodiscard]] Eigen::VectorXd linear_term() const { return a_.cwiseProduct(b_); }

 private:
  Eigen::VectorXd a_, b_;
  std::vector<int> springs_;
  double k_;
};

/// A chain of springs with rest length L, E = Σ k/2 (|x_{i+1} − x_i| − L)², with per-element
/// PSD-projected Hessians. Records whether any evaluation saw the pinned ends moved.
class SpringChain : public Objective {
 public:
  SpringChain(int vertex_count, double rest_length, double stiffness, Eigen::VectorXd state)
      : n_(vertex_count), rest_(rest_length), k_(stiffness), pinned_state_(std::move(state)) {
    for (int i = 0; i + 1 < n_; ++i) {
      edges_.push_back(i);
      edges_.push_back(i + 1);
    }
  }

  [[nodiscard]] Eigen::Index size() const override { return 3 * n_; }
  double value(const Eigen::VectorXd& x) override {
    check_pins(x);
    double e = 0.0;
    for (int i = 0; i + 1 < n_; ++i) {
      const double stretch = (x.segment<3>(3 * i + 3) - x.segment<3>(3 * i)).norm() - rest_;
      e += 0.5 * k_ * stretch * stretch;
    }
    return e;
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    check_pins(x);
    g = Eigen::VectorXd::Zero(3 * n_);
    for (int i = 0; i + 1 < n_; ++i) {
      const Eigen::Vector3d d = x.segment<3>(3 * i + 3) - x.segment<3>(3 * i);
      const Eigen::Vector3d f = k_ * (d.norm() - rest_) * d.normalized();
      g.segment<3>(3 * i + 3) += f;
      g.segment<3>(3 * i) -= f;
    }
  }
  void hessian(const Eigen::VectorXd& x, HessianBlocks& h) override {
    check_pins(x);
    h.diagonal.resize(0);
    h.batches.resize(1);
    h.batches[0].reset(2, edges_);
    for (int i = 0; i + 1 < n_; ++i) {
      const Eigen::Vector3d d = x.segment<3>(3 * i + 3) - x.segment<3>(3 * i);
      const double length = d.norm();
      const Eigen::Vector3d u = d / length;
      // ∂²E/∂d² = k [uuᵀ + (1 − L/l)(I − uuᵀ)], indefinite for compressed springs.
      const Eigen::Matrix3d along = u * u.transpose();
      const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - along;
      const Eigen::Matrix3d hd = k_ * (along + (1.0 - rest_ / length) * across);
      auto block = h.batches[0].block(i);
      block << hd, -hd, -hd, hd;
      project_to_psd(block);
    }
  }

  bool pins_moved = false;

 private:
  void check_pins(const Eigen::VectorXd& x) {
    for (int c = 0; c < 3; ++c)
      pins_moved = pins_moved || x[c] != pinned_state_[c] ||
                   x[3 * (n_ - 1) + c] != pinned_state_[3 * (n_ - 1) + c];
  }

  int n_;
  double rest_;
  double k_;
  Eigen::VectorXd pinned_state_;
  std::vector<int> edges_;
};

/// ½ Σ (xᵢ − target)² with an optional nan region and feasible-step bound, for line search
/// tests. Records every point at which the gradient was evaluated (the accepted iterates).
class ProbeQuadratic : public Objective {
 public:
  explicit ProbeQuadratic(Eigen::Index size, double target) : size_(size), target_(target) {}

  [[nodiscard]] Eigen::Index size() const override { return size_; }
  double value(const Eigen::VectorXd& x) override {
    if (!iterates.empty() && (x - iterates.back()).lpNorm<Eigen::Infinity>() > nan_radius)
      return kNaN;
    return 0.5 * (x.array() - target_).square().sum();
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    iterates.push_back(x);
    g = (x.array() - target_).matrix();
  }
  void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
    h.diagonal = Eigen::VectorXd::Constant(size_, hessian_diagonal);
    h.batches.clear();
  }
  double max_feasible_step(const Eigen::VectorXd&, const Eigen::VectorXd& dx) override {
    return std::min(1.0, max_displacement / dx.lpNorm<Eigen::Infinity>());
  }

  double nan_radius = std::numeric_limits<double>::infinity();
  double max_displacement = std::numeric_limits<double>::infinity();
  double hessian_diagonal = 1.0;
  std::vector<Eigen::VectorXd> iterates;

 private:
  Eigen::Index size_;
  double target_;
};

NewtonSettings tight_settings() {
  NewtonSettings settings;
  settings.tolerance = 1e-10;
  settings.max_iterations = 60;
  return settings;
}

/// A probe minimized from x = 0 with every DOF free: where it ended and how.
struct ProbeRun {
  Eigen::VectorXd x;
  NewtonResult result;
};
ProbeRun run_from_origin(ProbeQuadratic& probe, const NewtonSettings& settings) {
  ProbeRun run{Eigen::VectorXd::Zero(probe.size()), {}};
  NewtonSolver solver;
  run.result = solver.minimize(probe, run.x, DofMap(probe.size() / 3, {}), settings);
  return run;
}

TEST(Newton, QuadraticConvergesInOneStep) {
  const int vertices = 6;
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> positive(0.5, 3.0);
  const auto random = [&](double offset) -> Eigen::VectorXd {
    return Eigen::VectorXd::NullaryExpr(3 * vertices, [&] { return positive(rng) + offset; });
  };
  const Eigen::VectorXd a = random(0.0);
  const Eigen::VectorXd b = random(-1.7);
  Quadratic quadratic(a, b, {0, 1, 1, 2, 2, 3, 3, 4, 1, 4, 4, 5}, 2.0);
  const DofMap dofs(vertices, {});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(3 * vertices);

  NewtonSolver solver;
  const NewtonResult result = solver.minimize(quadratic, x, dofs, tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_EQ(result.iterations, 1);
  ASSERT_EQ(result.history.size(), 2u);
  EXPECT_EQ(result.history[0].step_length, 1.0);
  EXPECT_EQ(result.history[0].direction, DirectionKind::newton);
  const Eigen::VectorXd exact = quadratic.dense_matrix().ldlt().solve(quadratic.linear_term());
  EXPECT_LT((x - exact).lpNorm<Eigen::Infinity>(), 1e-12);
}

TEST(Newton, SeparableQuadraticWithPinnedVertex) {
  const Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(9, 1.0, 5.0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(9, -2.0, 2.0);
  Quadratic quadratic(a, b, {}, 0.0);
  const DofMap dofs(3, {1});
  Eigen::VectorXd x = Eigen::VectorXd::Constant(9, 0.25);
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(quadratic, x, dofs, tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_EQ(result.iterations, 1);
  for (int i = 0; i < 9; ++i) {
    if (i >= 3 && i < 6)
      EXPECT_EQ(x[i], 0.25) << "pinned DOF " << i << " moved";
    else
      EXPECT_NEAR(x[i], b[i], 1e-14);
  }
}

/// A stretched chain between two pins, started from a crooked state.
struct ChainProblem {
  static constexpr int kVertices = 12;
  Eigen::Vector3d start{0.3, -0.2, 0.1};
  Eigen::Vector3d end;
  Eigen::VectorXd x;
  DofMap dofs{kVertices, {0, kVertices - 1}};

  ChainProblem() {
    const double rest = 1.0;
    end = start + 1.5 * rest * (kVertices - 1) * Eigen::Vector3d(2, 1, -2).normalized();
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> jitter(-0.3, 0.3);
    x.resize(3 * kVertices);
    for (int i = 0; i < kVertices; ++i) {
      x.segment<3>(3 * i) = even_point(i);
      if (i != 0 && i != kVertices - 1)
        x.segment<3>(3 * i) += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
    }
  }
  [[nodiscard]] Eigen::Vector3d even_point(int i) const {
    return start + (end - start) * (static_cast<double>(i) / (kVertices - 1));
  }
  SpringChain objective() const { return SpringChain(kVertices, 1.0, 10.0, x); }
};

TEST(Newton, SpringChainReachesEvenlySpacedEquilibrium) {
  ChainProblem problem;
  SpringChain chain = problem.objective();
  // Derivative sanity of the test objective itself, independent of the solver.
  const auto energy = [&](const Eigen::VectorXd& y) { return chain.value(y); };
  const Eigen::VectorXd fd = test::fd_gradient(energy, problem.x, 1e-6);
  Eigen::VectorXd g;
  chain.gradient(problem.x, g);
  ASSERT_LT(test::relative_error(g, fd), 1e-7);
  chain.pins_moved = false;  // the finite differences moved them on purpose

  NewtonSolver solver;
  const NewtonResult result = solver.minimize(chain, problem.x, problem.dofs, tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_FALSE(chain.pins_moved);
  for (int i = 0; i < ChainProblem::kVertices; ++i)
    EXPECT_LT((problem.x.segment<3>(3 * i) - problem.even_point(i)).norm(), 1e-9) << "vertex " << i;
  EXPECT_EQ(problem.x.segment<3>(0), problem.start);
  // Every spring stretched by L/2: E = (n − 1) · k/2 · (L/2)².
  EXPECT_NEAR(result.energy, (ChainProblem::kVertices - 1) * 0.5 * 10.0 * 0.25, 1e-12);
  EXPECT_LT(result.gradient_norm, 1e-8);

  // Quadratic convergence: once ‖g‖ is small, the next residual is about its square
  // (order log g_{k+1} / log g_k ≥ 1.8 for some consecutive pair), with full steps.
  bool quadratic_step = false;
  for (std::size_t k = 0; k + 1 < result.history.size(); ++k) {
    const double gk = result.history[k].gradient_norm;
    const double gk1 = result.history[k + 1].gradient_norm;
    if (gk < 1e-2 && gk > 1e-12 && gk1 > 0.0 && std::log(gk1) / std::log(gk) >= 1.8) {
      quadratic_step = true;
      EXPECT_EQ(result.history[k].step_length, 1.0);
    }
  }
  EXPECT_TRUE(quadratic_step);
  // Energies decrease monotonically.
  for (std::size_t k = 0; k + 1 < result.history.size(); ++k)
    EXPECT_LE(result.history[k + 1].energy, result.history[k].energy * (1 + 1e-12));
}

TEST(Newton, ReusesAnalysisAcrossCalls) {
  ChainProblem problem;
  SpringChain chain = problem.objective();
  NewtonSolver solver;
  NewtonSettings settings = tight_settings();
  const NewtonResult first = solver.minimize(chain, problem.x, problem.dofs, settings);
  ASSERT_GE(first.history.size(), 2u);
  EXPECT_TRUE(first.history[0].pattern_changed);
  for (std::size_t k = 1; k < first.history.size(); ++k)
    EXPECT_FALSE(first.history[k].pattern_changed);

  // Perturb and solve again with the same solver: same stencils, no new analysis.
  problem.x.segment<3>(15) += Eigen::Vector3d(0.2, -0.1, 0.05);
  const NewtonResult second = solver.minimize(chain, problem.x, problem.dofs, settings);
  ASSERT_TRUE(second.converged);
  for (const NewtonIteration& record : second.history) EXPECT_FALSE(record.pattern_changed);
}

TEST(Newton, MaxIterationsReturnsUnconverged) {
  ChainProblem problem;
  SpringChain chain = problem.objective();
  NewtonSettings settings = tight_settings();
  settings.max_iterations = 2;
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(chain, problem.x, problem.dofs, settings);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 2);
  ASSERT_EQ(result.history.size(), 3u);
  EXPECT_EQ(result.history.back().step_length, 0.0);
  EXPECT_GE(result.step_norm, settings.tolerance);
}

TEST(Newton, StatisticsAddUp) {
  ChainProblem problem;
  SpringChain chain = problem.objective();
  NewtonSolver solver;
  std::vector<NewtonIteration> reported;
  const NewtonResult result =
      solver.minimize(chain, problem.x, problem.dofs, tight_settings(),
                      [&](const NewtonIteration& record) { reported.push_back(record); });
  ASSERT_EQ(reported.size(), result.history.size());
  PhaseTimes sum;
  for (std::size_t k = 0; k < reported.size(); ++k) {
    const NewtonIteration& record = reported[k];
    EXPECT_EQ(record.iteration, static_cast<int>(k));
    EXPECT_EQ(record.energy, result.history[k].energy);
    EXPECT_GE(record.times.assembly, 0.0);
    EXPECT_GE(record.times.factorization, 0.0);
    EXPECT_GE(record.times.solve, 0.0);
    EXPECT_GE(record.times.line_search, 0.0);
    EXPECT_GE(record.gradient_norm, 0.0);
    sum += record.times;
  }
  EXPECT_GT(result.times.assembly, 0.0);
  EXPECT_GT(result.times.factorization, 0.0);
  EXPECT_GT(result.times.line_search, 0.0);
  EXPECT_NEAR(sum.assembly, result.times.assembly, 1e-12);
  EXPECT_NEAR(sum.factorization, result.times.factorization, 1e-12);
  EXPECT_NEAR(sum.solve, result.times.solve, 1e-12);
  EXPECT_NEAR(sum.line_search, result.times.line_search, 1e-12);
  EXPECT_LE(result.times.total(), result.wall_seconds);
  EXPECT_EQ(result.energy, result.history.back().energy);
}

TEST(Newton, NonFiniteStartIsNamed) {
  NewtonSolver solver;
  const DofMap dofs(2, {});
  ProbeQuadratic probe(6, 1.0);

  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
  x[4] = kNaN;
  EXPECT_TRUE(contains(numerical_error_message([&] { solver.minimize(probe, x, dofs, {}); }),
                       "initial position is nan at DOF 4 (vertex 1, y)"));

  Quadratic bad_value(Eigen::VectorXd::Constant(6, kNaN), Eigen::VectorXd::Zero(6), {}, 0.0);
  x.setZero();
  x[0] = 1.0;
  EXPECT_TRUE(contains(numerical_error_message([&] { solver.minimize(bad_value, x, dofs, {}); }),
                       "objective value is nan at the initial point"));

  // A non-finite gradient at a fixed DOF is ignored; at a free one it is named.
  class InfiniteGradient : public ProbeQuadratic {
   public:
    InfiniteGradient(Eigen::Index bad_dof) : ProbeQuadratic(6, 1.0), bad_dof_(bad_dof) {}
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
      ProbeQuadratic::gradient(x, g);
      g[bad_dof_] = std::numeric_limits<double>::infinity();
    }

   private:
    Eigen::Index bad_dof_;
  };
  const DofMap first_pinned(2, {0});
  InfiniteGradient at_fixed(2);
  x.setZero();
  EXPECT_TRUE(solver.minimize(at_fixed, x, first_pinned, {}).converged);
  InfiniteGradient at_free(4);
  x.setZero();
  const std::string message =
      numerical_error_message([&] { solver.minimize(at_free, x, first_pinned, {}); });
  EXPECT_TRUE(contains(message, "gradient is inf at DOF 4 (vertex 1, y) at the initial point"))
      << message;
}

TEST(Newton, NanAwayFromIterateForcesBacktracking) {
  ProbeQuadratic probe(6, 3.0);
  probe.nan_radius = 0.6;
  const auto [x, result] = run_from_origin(probe, tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_LT((x.array() - 3.0).abs().maxCoeff(), 1e-12);
  EXPECT_LT(result.history[0].step_length, 1.0);
  EXPECT_GT(result.history[0].line_search_trials, 1);
  for (std::size_t k = 1; k < probe.iterates.size(); ++k)
    EXPECT_LE((probe.iterates[k] - probe.iterates[k - 1]).lpNorm<Eigen::Infinity>(), 0.6)
        << "accepted a point where the energy is nan";
}

TEST(Newton, RespectsMaxFeasibleStep) {
  ProbeQuadratic probe(3, -2.0);
  probe.max_displacement = 0.25;
  const auto [x, result] = run_from_origin(probe, tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_LT((x.array() + 2.0).abs().maxCoeff(), 1e-12);
  EXPECT_GE(result.iterations, 8);  // 2 / 0.25 steps at least
  for (const NewtonIteration& record : result.history)
    EXPECT_LE(record.step_length, record.feasible_step);
  for (std::size_t k = 1; k < probe.iterates.size(); ++k)
    EXPECT_LE((probe.iterates[k] - probe.iterates[k - 1]).lpNorm<Eigen::Infinity>(), 0.25 + 1e-15);
}

// A caller that can stiffen the constraint cutting its steps gets control back after
// max_cut_steps steps in a row below cut_step, instead of after the whole budget.
TEST(Newton, ReturnsAfterConsecutiveCutStepsWhenAsked) {
  ProbeQuadratic probe(3, -2.0);
  probe.max_displacement = 0.05;  // every step cut to 0.05 / 2 of the way, then less
  NewtonSettings settings = tight_settings();
  settings.max_cut_steps = 3;
  settings.cut_step = 0.1;
  const auto [x, result] = run_from_origin(probe, settings);
  EXPECT_FALSE(result.converged);
  EXPECT_FALSE(result.stagnated);
  EXPECT_EQ(result.iterations, 3);
  EXPECT_NEAR(x[0], -0.15, 1e-12);

  // Without it the same steps run until the budget ends (2 / 0.05 = 40 steps < 60).
  const ProbeRun whole = run_from_origin(probe, tight_settings());
  EXPECT_TRUE(whole.result.converged);
  EXPECT_GE(whole.result.iterations, 40);

  // Cut steps that are not consecutive never end the solve: a full step resets the count.
  ProbeQuadratic once(3, -2.0);
  once.max_displacement = 1.0;  // the first step goes half way, the second all the rest
  settings.max_cut_steps = 2;
  settings.cut_step = 0.6;
  const auto [y, alternating] = run_from_origin(once, settings);
  EXPECT_TRUE(alternating.converged);
  EXPECT_LT((y.array() + 2.0).abs().maxCoeff(), 1e-12);
}

// A Hessian 100 times too stiff (as a PSD projection can make it where E is not convex) gives
// full steps 1/100 of the way: they are extended to α = 64 while E keeps decreasing.
TEST(Newton, ExtendsFullStepsWhereHessianOverestimatesCurvature) {
  ProbeQuadratic probe(3, -2.0);
  probe.hessian_diagonal = 100.0;
  const auto [x, result] = run_from_origin(probe, tight_settings());
  ASSERT_TRUE(result.converged);
  // The tolerance bounds d = −g/100, so the error is within 100 × 1e-10.
  EXPECT_LT((x.array() + 2.0).abs().maxCoeff(), 1e-8);
  EXPECT_EQ(result.history[0].step_length, 64.0);
  // Without extension: ‖x + 2‖ shrinks by 0.99 per step, about 2800 steps to 1e-12.
  EXPECT_LE(result.iterations, 20);
}

// A solve capped by design skips the final iterate: two steps cost two gradients and two
// factorizations instead of three, end at the same point, and report not converged.
TEST(Newton, CappedSolveWithoutFinalJudgementSkipsTheLastEvaluation) {
  NewtonSettings settings = tight_settings();
  settings.max_iterations = 2;
  ProbeQuadratic judged_probe(3, -2.0), capped_probe(3, -2.0);
  // d = −g/1.5: each full step removes 2/3 of the error (E drops by 2/3 of the linear
  // prediction, too little to extend the step), so two steps stop short.
  judged_probe.hessian_diagonal = capped_probe.hessian_diagonal = 1.5;
  const auto [judged_x, judged] = run_from_origin(judged_probe, settings);
  settings.judge_final_iterate = false;
  const auto [capped_x, capped] = run_from_origin(capped_probe, settings);

  EXPECT_FALSE(judged.converged);
  EXPECT_FALSE(capped.converged);
  EXPECT_EQ(judged.iterations, 2);
  EXPECT_EQ(capped.iterations, 2);
  EXPECT_EQ(judged_probe.iterates.size(), 3u);  // gradients evaluated
  EXPECT_EQ(capped_probe.iterates.size(), 2u);
  ASSERT_EQ(capped.history.size(), 2u);
  EXPECT_GT(capped.history.back().step_length, 0.0);
  EXPECT_TRUE(capped_x == judged_x);
  EXPECT_DOUBLE_EQ(capped.energy, judged.energy);
  EXPECT_DOUBLE_EQ(capped.energy, capped_probe.value(capped_x));
}

// The extension asks the CCD about the whole longer motion: it stops at the last α whose
// displacement the feasible-step bound allows.
TEST(Newton, ExtensionRespectsMaxFeasibleStep) {
  ProbeQuadratic probe(3, -2.0);
  probe.hessian_diagonal = 100.0;
  probe.max_displacement = 0.1;  // d = −0.02 per coordinate: α = 4 moves 0.08, α = 8 0.16
  const auto [x, result] = run_from_origin(probe, tight_settings());
  EXPECT_EQ(result.history[0].step_length, 4.0);
  for (std::size_t k = 1; k < probe.iterates.size(); ++k)
    EXPECT_LE((probe.iterates[k] - probe.iterates[k - 1]).lpNorm<Eigen::Infinity>(), 0.1 + 1e-15);
}

TEST(Newton, LineSearchFailureIsReported) {
  // max_feasible_step = 0: no step can be taken.
  ProbeQuadratic blocked(3, 1.0);
  blocked.max_displacement = 0.0;
  const DofMap dofs(1, {});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(3);
  NewtonSolver solver;
  std::string message = numerical_error_message([&] { solver.minimize(blocked, x, dofs, {}); });
  EXPECT_TRUE(contains(message, "line search failed at iteration 0")) << message;

  // A gradient inconsistent with the energy: the "descent" direction increases E every time.
  class WrongGradient : public ProbeQuadratic {
   public:
    using ProbeQuadratic::ProbeQuadratic;
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
      ProbeQuadratic::gradient(x, g);
      g = -g;
    }
  } wrong(3, 1.0);
  message = numerical_error_message([&] { solver.minimize(wrong, x, dofs, {}); });
  EXPECT_TRUE(contains(message, "line search failed at iteration 0, ‖g‖ = 1.732")) << message;
  EXPECT_TRUE(contains(message, "40 trials")) << message;
  EXPECT_EQ(x, Eigen::VectorXd::Zero(3)) << "a failed line search must not move x";
}

TEST(Newton, IndefiniteHessianFallsBackToShift) {
  // E = Σ (xᵢ² − 1)² with its exact (unprojected) Hessian 12xᵢ² − 4, negative at x₀ = 0.1.
  class DoubleWell : public Objective {
   public:
    [[nodiscard]] Eigen::Index size() const override { return 3; }
    double value(const Eigen::VectorXd& x) override {
      return (x.array().square() - 1.0).square().sum();
    }
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
      g = (4.0 * x.array() * (x.array().square() - 1.0)).matrix();
    }
    void hessian(const Eigen::VectorXd& x, HessianBlocks& h) override {
      h.diagonal = (12.0 * x.array().square() - 4.0).matrix();
      h.batches.clear();
    }
  } well;
  Eigen::VectorXd x(3);
  x << 0.1, 2.0, -2.0;
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(well, x, DofMap(1, {}), tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_EQ(result.history[0].direction, DirectionKind::shifted_newton);
  EXPECT_GT(result.history[0].shift, 0.0);
  EXPECT_EQ(result.history.back().direction, DirectionKind::newton);
  EXPECT_LT((x.array().abs() - 1.0).abs().maxCoeff(), 1e-10);
}

TEST(Newton, NegativeDefiniteHessianFallsBackToGradient) {
  // E = ½|x|² with a wrong Hessian −I: no shift up to the diagonal's scale helps.
  class WrongCurvature : public Objective {
   public:
    [[nodiscard]] Eigen::Index size() const override { return 3; }
    double value(const Eigen::VectorXd& x) override { return 0.5 * x.squaredNorm(); }
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override { g = x; }
    void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
      h.diagonal = -Eigen::VectorXd::Ones(3);
      h.batches.clear();
    }
  } wrong;
  Eigen::VectorXd x(3);
  x << 1.0, -2.0, 0.5;
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(wrong, x, DofMap(1, {}), tight_settings());
  ASSERT_TRUE(result.converged);
  EXPECT_EQ(result.history[0].direction, DirectionKind::gradient);
  EXPECT_EQ(x, Eigen::VectorXd::Zero(3));
}

/// A separable quadratic ½ Σ (xᵢ − 1)² carried on a large energy offset, whose gradient holds a
/// deterministic error of relative size `noise` (as a gradient summed from large cancelling
/// element forces does): Newton gets within about `noise` of the minimum and then only moves in
/// the error, with energy changes far below the rounding of E.
/// With `late_drop`, E also falls by that much once the gradient has been evaluated
/// `drop_after` times: a real decrease (a fold snapping) after the step norm stopped falling.
class NoisyQuadratic : public Objective {
 public:
  NoisyQuadratic(int vertices, double noise, double late_drop = 0.0, long drop_after = 0)
      : n_(3 * vertices), noise_(noise), late_drop_(late_drop), drop_after_(drop_after) {}
  [[nodiscard]] Eigen::Index size() const override { return n_; }
  double value(const Eigen::VectorXd& x) override {
    const double drop = evaluations_ >= drop_after_ ? late_drop_ : 0.0;
    return kOffset - drop + 0.5 * (x.array() - 1.0).square().sum();
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    ++evaluations_;
    g = x.array() - 1.0;
    for (Eigen::Index i = 0; i < n_; ++i)
      g[i] += noise_ * std::sin(1e3 * static_cast<double>(evaluations_ * n_ + i));
  }
  void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
    h.diagonal = Eigen::VectorXd::Ones(n_);
    h.batches.clear();
  }

 private:
  static constexpr double kOffset = 1e6;
  Eigen::Index n_;
  double noise_;
  double late_drop_;
  long drop_after_;
  long evaluations_ = 0;
};

TEST(Newton, StagnationAtRoundoffStopsAndSaysSo) {
  NoisyQuadratic objective(4, 1e-9);
  NewtonSettings settings;
  settings.tolerance = 1e-12;  // below the gradient's error: unreachable
  settings.max_iterations = 400;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(objective.size());
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(4, {}), settings);
  EXPECT_FALSE(result.converged);
  EXPECT_TRUE(result.stagnated);
  EXPECT_LT(result.iterations, 30);  // not the 400 allowed
  // The accuracy reached is the gradient error's, and the iterate is that close to the minimum.
  EXPECT_LT(result.step_norm, 1e-8);
  EXPECT_GT(result.step_norm, settings.tolerance);
  EXPECT_LT((x.array() - 1.0).abs().maxCoeff(), 1e-8);
}

TEST(Newton, StagnationIsFoundAfterALateRealDropOfTheEnergy) {
  // E falls by 1e-3 (1e-9 of |E|, far above its rounding) at iteration 5, after the step
  // norm stopped halving; only rounding-level changes follow. Judged against the energy at the
  // best step norm, that one drop hid the stagnation for all 400 iterations.
  NoisyQuadratic objective(4, 1e-9, 1e-3, 5);
  NewtonSettings settings;
  settings.tolerance = 1e-12;
  settings.max_iterations = 400;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(objective.size());
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(4, {}), settings);
  EXPECT_TRUE(result.stagnated);
  EXPECT_GT(result.iterations, 15);  // the window with the drop did not count
  EXPECT_LT(result.iterations, 50);
  EXPECT_LT((x.array() - 1.0).abs().maxCoeff(), 1e-8);
}

TEST(Newton, AReachableToleranceIsNotStagnation) {
  NoisyQuadratic objective(4, 1e-9);
  NewtonSettings settings;
  settings.tolerance = 1e-7;  // above the gradient's error
  Eigen::VectorXd x = Eigen::VectorXd::Zero(objective.size());
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(4, {}), settings);
  EXPECT_TRUE(result.converged);
  EXPECT_FALSE(result.stagnated);
}

TEST(Newton, ALinearlyConvergingSolveBelowTheEnergysRoundingIsNotStagnation) {
  // E = 1e6 + ½|x − 1|² with a Newton matrix 20 times too stiff: full steps converge linearly at
  // ρ = 0.95, so the step norm halves only every 14 iterations, and E's changes are below its
  // rounding (1e-12 |E| per iteration) from the start. Steps still shrink by ρ each.
  class StiffMatrix : public Objective {
   public:
    [[nodiscard]] Eigen::Index size() const override { return 6; }
    double value(const Eigen::VectorXd& x) override {
      return 1e6 + 0.5 * (x.array() - 1.0).square().sum();
    }
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
      g = x.array() - 1.0;
    }
    void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
      h.diagonal = Eigen::VectorXd::Constant(6, 20.0);
      h.batches.clear();
    }
  } objective;
  NewtonSettings settings;
  settings.tolerance = 1e-9;
  settings.max_iterations = 1000;
  Eigen::VectorXd x(6);
  x << 1.001, 0.999, 1.0005, 0.9995, 1.0, 1.0002;
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(2, {}), settings);
  EXPECT_FALSE(result.stagnated);
  EXPECT_TRUE(result.converged);
  EXPECT_LT((x.array() - 1.0).abs().maxCoeff(), 20 * settings.tolerance);
}

TEST(Newton, ALineSearchLostInTheEnergysRoundingIsStagnationNotFailure) {
  // E = ½|x − 1|² that rounds 1e-5 higher anywhere but at the start (as a sum of large
  // cancelling terms can): no α decreases E, and the step's predicted decrease (3e-6) is below
  // that rounding, so the solve has stagnated at round-off; it is no line-search failure.
  class RoundedHighAway : public Objective {
   public:
    explicit RoundedHighAway(Eigen::VectorXd start) : start_(std::move(start)) {}
    [[nodiscard]] Eigen::Index size() const override { return 3; }
    double value(const Eigen::VectorXd& x) override {
      return 0.5 * (x.array() - 1.0).square().sum() + (x == start_ ? 0.0 : 1e-5);
    }
    void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override { g = x.array() - 1.0; }
    void hessian(const Eigen::VectorXd&, HessianBlocks& h) override {
      h.diagonal = Eigen::VectorXd::Ones(3);
      h.batches.clear();
    }

   private:
    Eigen::VectorXd start_;
  };
  const Eigen::VectorXd start = Eigen::VectorXd::Constant(3, 1.0 + 1e-3);
  RoundedHighAway objective(start);
  NewtonSettings settings;
  settings.tolerance = 1e-12;
  Eigen::VectorXd x = start;
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(1, {}), settings);
  EXPECT_TRUE(result.stagnated);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 0);
  ASSERT_FALSE(result.history.empty());
  EXPECT_TRUE(result.history.back().below_energy_rounding);
  EXPECT_EQ(x, start) << "no step is taken";
  EXPECT_NEAR(result.step_norm, 1e-3, 1e-12);
}

TEST(Newton, OneWatcherFindsStagnationAcrossSolvesShorterThanItsWindow) {
  // The noisy quadratic stagnates after a few iterations; solved in chunks of 6 (as FrameSolver
  // splits a contact solve between κ updates), a fresh watcher per chunk never sees a full
  // window of kWindow = 10, one watcher for all chunks does.
  const auto chunks_until_stagnation = [](bool shared) {
    NoisyQuadratic objective(4, 1e-9);
    NewtonSettings settings;
    settings.tolerance = 1e-12;
    settings.max_iterations = 6;
    settings.judge_final_iterate = false;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(objective.size());
    NewtonSolver solver;
    RoundoffStagnation watcher;
    for (int chunk = 1; chunk <= 20; ++chunk)
      if (solver.minimize(objective, x, DofMap(4, {}), settings, {}, shared ? &watcher : nullptr)
              .stagnated)
        return chunk;
    return 0;
  };
  EXPECT_EQ(chunks_until_stagnation(false), 0);
  const int shared = chunks_until_stagnation(true);
  EXPECT_GT(shared, 1);
  EXPECT_LE(shared, 5);
}

TEST(Newton, AnUnjudgedSolveWithNoIterationsLeftDoesNothing) {
  NoisyQuadratic objective(2, 0.0);
  NewtonSettings settings;
  settings.max_iterations = 0;
  settings.judge_final_iterate = false;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(objective.size());
  NewtonSolver solver;
  const NewtonResult result = solver.minimize(objective, x, DofMap(2, {}), settings);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 0);
  EXPECT_TRUE(result.history.empty());  // no record that the uninterrupted capped step lacks
  EXPECT_TRUE(x.isZero(0.0));
}

TEST(Newton, RejectsBadSettings) {
  ProbeQuadratic probe(3, 1.0);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(3);
  NewtonSolver solver;
  NewtonSettings settings;
  settings.step_scale = 0.0;
  EXPECT_THROW(solver.minimize(probe, x, DofMap(1, {}), settings), InputError);
  settings = NewtonSettings{};
  settings.backtracking = 1.0;
  EXPECT_THROW(solver.minimize(probe, x, DofMap(1, {}), settings), InputError);
  settings = NewtonSettings{};
  settings.max_cut_steps = -1;
  EXPECT_THROW(solver.minimize(probe, x, DofMap(1, {}), settings), InputError);
  settings = NewtonSettings{};
  settings.cut_step = 0.0;
  EXPECT_THROW(solver.minimize(probe, x, DofMap(1, {}), settings), InputError);
}

/// One free vertex with E = Σ_c [a (x_c − 1)² + b (x_c − 1)⁴ + c (x_c − 1)²] in two element
/// batches: the convex part a (·)² + b (·)⁴, and c (·)² with c < 0, whose block (2c I) the
/// projection clamps to zero, as it clamps a compressed membrane's negative curvature.
class ConcavePartObjective : public Objective {
 public:
  ConcavePartObjective(double a, double b, double c) : a_(a), b_(b), c_(c) {}
  [[nodiscard]] Eigen::Index size() const override { return 3; }
  double value(const Eigen::VectorXd& x) override {
    const Eigen::ArrayXd u = x.array() - 1.0;
    return ((a_ + c_) * u.square() + b_ * u.square().square()).sum();
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    const Eigen::ArrayXd u = x.array() - 1.0;
    g = (2.0 * (a_ + c_) * u + 4.0 * b_ * u.cube()).matrix();
  }
  void hessian(const Eigen::VectorXd& x, HessianBlocks& h) override {
    const Eigen::ArrayXd u = x.array() - 1.0;
    h.diagonal.resize(0);
    h.batches.resize(2);
    h.batches[0].reset(1, {0});
    h.batches[0].block(0) = (2.0 * a_ + 12.0 * b_ * u.square()).matrix().asDiagonal();
    h.batches[1].reset(1, {0});
    h.batches[1].block(0) = 2.0 * c_ * Eigen::Matrix3d::Identity();
    if (h.project) project_to_psd(h.batches[1].block(0));
  }

 private:
  double a_, b_, c_;
};

/// Project-on-demand Newton at a tolerance far below the tests' answers' errors.
NewtonSettings tight_on_demand_settings() {
  NewtonSettings settings;
  settings.tolerance = 1e-10;
  settings.project_on_demand = true;
  return settings;
}

TEST(Newton, ProjectOnDemandTakesTheExactStepWhereTheProjectionOverstatesCurvature) {
  // E = 0.1 (x − 1)² per coordinate: ∇²E = 0.2 I, its projection 2 I (the −1.8 I clamped), so
  // projected Newton's full steps go only a tenth of the way.
  NewtonSettings settings = tight_on_demand_settings();
  NewtonSolver solver;
  ConcavePartObjective on_demand(1.0, 0.0, -0.9);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 2.0);
  const NewtonResult exact = solver.minimize(on_demand, x, DofMap(1, {}), settings);
  ASSERT_TRUE(exact.converged);
  EXPECT_EQ(exact.iterations, 1);
  EXPECT_FALSE(exact.history.front().projected());
  EXPECT_NEAR((x.array() - 1.0).abs().maxCoeff(), 0.0, 1e-12);

  settings.project_on_demand = false;
  x.setConstant(2.0);
  const NewtonResult projected = solver.minimize(on_demand, x, DofMap(1, {}), settings);
  ASSERT_TRUE(projected.converged);
  EXPECT_TRUE(projected.history.front().projected());
  EXPECT_GT(projected.iterations, 3);
}

TEST(Newton, ProjectOnDemandKeepsHalfTheNegativeCurvatureWhereThatIsPositiveDefinite) {
  // E = −0.2 u² + u⁴ (u = x − 1), a convex part u² + u⁴ and a concave one −1.2 u²: at
  // u = 0.05, ∇²E = −0.4 + 12u² = −0.37 is indefinite, P = 2 + 12u² drops the concave part's
  // −2.4, and P + ½(∇²E − P) = 0.8 + 12u² = 0.83 is positive definite.
  NewtonSettings settings = tight_on_demand_settings();
  NewtonSolver solver;
  ConcavePartObjective objective(1.0, 1.0, -1.2);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 1.05);
  const NewtonResult result = solver.minimize(objective, x, DofMap(1, {}), settings);
  ASSERT_TRUE(result.converged);
  const NewtonIteration& first = result.history.front();
  EXPECT_FALSE(first.projected());
  EXPECT_EQ(first.kept_negative_curvature, 0.5);
  EXPECT_EQ(first.direction, DirectionKind::newton);
  // The full step of the blend is d = −g/0.83 per coordinate, g = −0.4u + 4u³.
  const double u = 0.05;
  const double full_step = (0.4 * u - 4.0 * u * u * u) / (0.8 + 12.0 * u * u);
  EXPECT_NEAR(first.step_norm, full_step, 1e-12);
  EXPECT_NEAR((x.array() - 1.0 - std::sqrt(0.1)).abs().maxCoeff(), 0.0, 1e-8);
}

TEST(Newton, ProjectOnDemandProjectsWhereTheHessianIsIndefinite) {
  // E = −0.75 u² + u⁴ (u = x − 1): ∇²E = −1.5 + 12 u² is negative near u = 0.1, where the
  // solve starts, and positive at the minimum u = √0.375.
  NewtonSettings settings = tight_on_demand_settings();
  NewtonSolver solver;
  ConcavePartObjective objective(0.0, 1.0, -0.75);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 1.1);
  const NewtonResult result = solver.minimize(objective, x, DofMap(1, {}), settings);
  ASSERT_TRUE(result.converged);
  EXPECT_TRUE(result.history.front().projected());
  EXPECT_TRUE(std::any_of(result.history.begin(), result.history.end(),
                          [](const NewtonIteration& it) { return !it.projected(); }));
  EXPECT_NEAR((x.array() - 1.0 - std::sqrt(0.375)).abs().maxCoeff(), 0.0, 1e-8);
}

}  // namespace
}  // namespace psq
