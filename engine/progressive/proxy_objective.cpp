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

ProxyElastics::ProxyElastics(const ShellSystem& level, const ShellSystem& finest,
                             const SystemProlongation& to_finest, ProxyGradient gradient)
    : level_(level), finest_(finest), to_finest_(to_finest), gradient_kind_(gradient) {
  for (std::size_t s = 0; s < level.shells().size(); ++s)
    bending_scale_.push_back(bending_stiffening(level.shells()[s], finest.shells()[s]));
}

ProxyElastics::FineEvaluation& ProxyElastics::at(const Eigen::VectorXd& x) const {
  const bool hit = memo_.x.size() > 0 && x.size() == memo_.x.size() &&
                   std::memcmp(x.data(), memo_.x.data(),
                               sizeof(double) * static_cast<std::size_t>(x.size())) == 0;
  if (!hit) {
    memo_ = FineEvaluation{};
    memo_.prolonged = to_finest_.apply(x);
    memo_.x = x;
  }
  return memo_;
}

double ProxyElastics::elastic_at(FineEvaluation& fine) const {
  if (!fine.elastic) fine.elastic = fine_elastics(finest_, fine.prolonged);
  return *fine.elastic;
}

double ProxyElastics::elastic_energy(const Eigen::VectorXd& x) const {
  return elastic_at(at(x));
}

double ProxyElastics::energy(const Eigen::VectorXd& x) const {
  FineEvaluation& fine = at(x);
  return elastic_at(fine) - finest_.external_force().dot(fine.prolonged);
}

void ProxyElastics::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  const Eigen::VectorXd& fine = at(x).prolonged;
  Eigen::VectorXd fine_g = -finest_.external_force();
  for (const auto& m : finest_.membranes()) m.add_gradient(fine, fine_g);
  for (const auto& b : finest_.bendings()) b.add_gradient(fine, fine_g);
  g += gradient_kind_ == ProxyGradient::exact ? to_finest_.apply_jacobian_transpose(x, fine_g)
                                              : to_finest_.apply_linear_transpose(fine_g);
}

void ProxyElastics::hessian(const Eigen::VectorXd& x, std::vector<ElementMatrices>& batches,
                            bool project_psd) const {
  const std::size_t shells = level_.membranes().size();
  batches.resize(2 * shells);
  for (std::size_t s = 0; s < shells; ++s) {
    level_.membranes()[s].hessian(x, batches[2 * s], project_psd);
    ElementMatrices& bending = batches[2 * s + 1];
    level_.bendings()[s].hessian(x, bending, project_psd);
    Eigen::Map<Eigen::VectorXd>(bending.values.data(),
                                static_cast<Eigen::Index>(bending.values.size())) *= bending_scale_[s];
  }
}

}  // namespace psq
