#pragma once
// Central finite differences for checking analytic gradients and Hessians.

#include <Eigen/Core>
#include <functional>

namespace psq::test {

/// Central-difference gradient of f at x with step h.
inline Eigen::VectorXd fd_gradient(const std::function<double(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& x, double h) {
  Eigen::VectorXd g(x.size());
  Eigen::VectorXd y = x;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    y[i] = x[i] + h;
    const double fp = f(y);
    y[i] = x[i] - h;
    const double fm = f(y);
    y[i] = x[i];
    g[i] = (fp - fm) / (2 * h);
  }
  return g;
}

/// Central-difference Jacobian of a gradient function (the Hessian of its potential).
inline Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& g,
                                   const Eigen::VectorXd& x, double h) {
  Eigen::MatrixXd J(g(x).size(), x.size());
  Eigen::VectorXd y = x;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    y[i] = x[i] + h;
    const Eigen::VectorXd gp = g(y);
    y[i] = x[i] - h;
    const Eigen::VectorXd gm = g(y);
    y[i] = x[i];
    J.col(i) = (gp - gm) / (2 * h);
  }
  return J;
}

/// ‖a − b‖ / max(‖b‖, floor): the relative error used by every derivative check.
inline double relative_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-12) {
  return (a - b).norm() / std::max(b.norm(), floor);
}

}  // namespace psq::test
