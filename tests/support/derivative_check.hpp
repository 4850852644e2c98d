#pragma once
// Finite-difference checks of functions that return their value, gradient and Hessian together
// (StencilDerivatives), and of Hessians stored as element blocks.

#include <Eigen/Core>

#include "engine/core/element_matrices.hpp"
#include "support/finite_difference.hpp"

namespace psq::test {

/// Relative errors (relative_error) of an analytic gradient and Hessian against central
/// differences.
struct DerivativeErrors {
  double gradient;
  double hessian;
};

/// The errors at x of f's gradient against central differences of its value and of its
/// Hessian against central differences of its gradient, both with step h. f maps a flat
/// position vector to a struct with `value`, `gradient` and `hessian` (StencilDerivatives).
template <class Function>
DerivativeErrors derivative_errors(const Function& f, const Eigen::VectorXd& x, double h) {
  const auto at_x = f(x);
  const Eigen::VectorXd fd_g =
      fd_gradient([&](const Eigen::VectorXd& y) { return f(y).value; }, x, h);
  const Eigen::MatrixXd fd_h =
      fd_jacobian([&](const Eigen::VectorXd& y) -> Eigen::VectorXd { return f(y).gradient; }, x, h);
  return {relative_error(at_x.gradient, fd_g), relative_error(at_x.hessian, fd_h)};
}

/// Sums element blocks into a dense dofs × dofs matrix.
inline Eigen::MatrixXd dense_hessian(const ElementMatrices& blocks, Eigen::Index dofs) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(dofs, dofs);
  const int s = blocks.stencil_size;
  for (std::size_t e = 0; e < blocks.element_count(); ++e)
    for (int a = 0; a < s; ++a)
      for (int b = 0; b < s; ++b)
        h.block<3, 3>(3 * blocks.vertices[e * s + a], 3 * blocks.vertices[e * s + b]) +=
            blocks.block(e).block<3, 3>(3 * a, 3 * b);
  return h;
}

}  // namespace psq::test
