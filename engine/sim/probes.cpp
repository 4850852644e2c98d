#include "engine/sim/probes.hpp"

namespace psq {
namespace {

Eigen::Vector3d mean_displacement(const ShellSystem& system, const std::vector<int>& vertices,
                                  const Eigen::VectorXd& x) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v : vertices)
    sum += x.segment<3>(3 * v) - system.rest_mesh().vertices.row(v).transpose();
  return sum / static_cast<double>(vertices.size());
}

Eigen::Vector3d reaction(const std::vector<int>& dofs, const Eigen::VectorXd& static_gradient) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int dof : dofs) sum[dof % 3] -= static_gradient[dof];
  return sum;
}

}  // namespace

std::vector<ProbeReading> read_probes(const ShellSystem& system, const Eigen::VectorXd& x,
                                      const Eigen::VectorXd& static_gradient) {
  std::vector<ProbeReading> readings;
  for (const SystemProbe& probe : system.probes())
    readings.push_back({probe.name, probe.kind,
                        probe.kind == ProbeKind::displacement
                            ? mean_displacement(system, probe.indices, x)
                            : reaction(probe.indices, static_gradient)});
  return readings;
}

}  // namespace psq
