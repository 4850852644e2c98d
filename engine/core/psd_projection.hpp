#pragma once
#include <Eigen/Core>

namespace psq {

/// Replaces a symmetric matrix by its closest positive semi-definite matrix (negative
/// eigenvalues clamped to zero), so Newton directions stay descent directions.
void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric);
/// The same for a contact pair's 12×12 block, with a fixed-size eigensolver: it runs once per
/// pair within reach per Hessian, and the dynamic one allocates.
void project_to_psd(Eigen::Matrix<double, 12, 12>& symmetric);

}  // namespace psq
