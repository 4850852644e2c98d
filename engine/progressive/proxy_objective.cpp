#include "engine/progressive/proxy_objective.hpp"

#include <cmath>
#include <cstring>

namespace psq {
namespace {

double fine_elastics(const ShellSystem& finest, const Eigen::VectorXd& fine) {
  double e = 0.0;
  for (const auto& m : finest.membranes()) e += m.value(fine);
  for (const auto& b : finest.bendings()) e += b.value(fine);
  return e;
}

/// How much stiffer the fine bending through P^l is than the level's own bending energy. P^l
/// keeps the fine vertices of a flat coarse triangle in its plane, so a coarse crease is carried
/// by the row of fine hinges that cross it, and a hinge's energy grows as its edge height shrinks:
/// by about the coarse/fine edge-length ratio (4.3× measured at three levels,
/// tests/hierarchy/prolongation_bending_test.cpp), which for a shell whose area the decimation
/// keeps is √(fine triangles / level triangles).
double bending_stiffening(const ShellBlock& level, const ShellBlock& finest) {
  return std::sqrt(static_cast<double>(finest.triangle_count) / level.triangle_count);
}

}  // namespace

ProxyObjective::ProxyObjective(const ShellSystem& level, const ShellSystem& finest,
                               const SystemProlongation& to_finest, double time_step,
                               ProxyGradient gradient)
    : level_(level),
      finest_(finest),
      to_finest_(to_finest),
      inertia_weight_(1.0 / (time_step * time_step)),
      gradient_kind_(gradient),
      previous_(flat(level.rest_mesh().vertices)) {
  for (std::size_t s = 0; s < level.shells().size(); ++s)
    bending_scale_.push_back(bending_stiffening(level.shells()[s], finest.shells()[s]));
}

const Eigen::VectorXd& ProxyObjective::prolonged(const Eigen::VectorXd& x) const {
  // Bitwise equality, so a hit returns exactly what apply(x) would (a non-finite x, which apply
  // rejects, is never stored). Comparing 3n numbers is cheap next to prolonging 3m of them.
  const bool hit = prolonged_at_.size() > 0 && x.size() == prolonged_at_.size() &&
                   std::memcmp(x.data(), prolonged_at_.data(),
                               sizeof(double) * static_cast<std::size_t>(x.size())) == 0;
  if (!hit) {
    prolonged_ = to_finest_.apply(x);
    prolonged_at_ = x;
  }
  return prolonged_;
}

double ProxyObjective::elastic_energy(const Eigen::VectorXd& x) const {
  return fine_elastics(finest_, prolonged(x));
}

double ProxyObjective::value(const Eigen::VectorXd& x) {
  const Eigen::VectorXd dx = x - previous_;
  const double inertia = 0.5 * inertia_weight_ * dx.dot(level_.dof_masses().cwiseProduct(dx));
  const Eigen::VectorXd& fine = prolonged(x);
  return inertia + fine_elastics(finest_, fine) - finest_.external_force().dot(fine);
}

Eigen::VectorXd ProxyObjective::fine_gradient(const Eigen::VectorXd& fine) const {
  Eigen::VectorXd g = -finest_.external_force();
  for (const auto& m : finest_.membranes()) m.add_gradient(fine, g);
  for (const auto& b : finest_.bendings()) b.add_gradient(fine, g);
  return g;
}

void ProxyObjective::gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  const Eigen::VectorXd fine_g = fine_gradient(prolonged(x));
  g = inertia_weight_ * level_.dof_masses().cwiseProduct(x - previous_);
  if (gradient_kind_ == ProxyGradient::exact)
    g += to_finest_.apply_jacobian_transpose(x, fine_g);
  else
    g += to_finest_.apply_linear_transpose(fine_g);
}

void ProxyObjective::hessian(const Eigen::VectorXd& x, HessianBlocks& H) {
  H.diagonal = inertia_weight_ * level_.dof_masses();
  const std::size_t shells = level_.membranes().size();
  H.batches.resize(2 * shells);
  for (std::size_t s = 0; s < shells; ++s) {
    level_.membranes()[s].hessian(x, H.batches[2 * s]);
    ElementMatrices& bending = H.batches[2 * s + 1];
    level_.bendings()[s].hessian(x, bending);
    Eigen::Map<Eigen::VectorXd>(bending.values.data(), static_cast<Eigen::Index>(bending.values.size())) *=
        bending_scale_[s];
  }
}

}  // namespace psq
