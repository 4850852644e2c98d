#pragma once
#include <Eigen/Core>

namespace psq {

/// Replaces a symmetric matrix by its closest positive semi-definite matrix (negative
/// eigenvalues clamped to zero), so Newton directions stay descent directions.
void project_to_psd(Eigen::Ref<Eigen::MatrixXd> symmetric);

}  // namespace psq
