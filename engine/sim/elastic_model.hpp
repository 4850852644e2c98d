#pragma once
// The elastic and external-load part of an incremental potential, Ψ(x) − f·x, with the
// Hessian blocks its Newton steps use. A system's own shells (membrane plus bending, gravity and
// loads) are the default; a coarse level of a progressive solve supplies the fine elastics
// through the prolongation instead (paper eq. 2), so that contact, friction and strain limits
// are added to either in the same way.

#include <Eigen/Core>
#include <vector>

#include "engine/core/element_matrices.hpp"

namespace psq {

class ElasticModel {
 public:
  virtual ~ElasticModel() = default;
  /// Ψ(x): the elastic energy, for reports.
  [[nodiscard]] virtual double elastic_energy(const Eigen::VectorXd& x) const = 0;
  /// Ψ(x) − f·x.
  [[nodiscard]] virtual double energy(const Eigen::VectorXd& x) const = 0;
  /// g += ∇(Ψ − f·x)(x).
  virtual void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const = 0;
  /// PSD element blocks approximating ∇²Ψ(x), or with `project_psd` false the elements'
  /// unprojected Hessians, written to `batches` (resized by the model).
  virtual void hessian(const Eigen::VectorXd& x, std::vector<ElementMatrices>& batches,
                       bool project_psd) const = 0;
};

}  // namespace psq
