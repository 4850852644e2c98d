#include "engine/elastic/shell_bending.hpp"

#include <stdexcept>

namespace psq {
namespace {

std::variant<BendingEnergy, MidedgeBendingEnergy> build_bending(BendingModel model,
                                                                const TriMesh& rest,
                                                                const MeshTopology& topology,
                                                                const Material& material,
                                                                int vertex_offset) {
  switch (model) {
    case BendingModel::hinge:
      return BendingEnergy(rest, topology, material, vertex_offset);
    case BendingModel::midedge:
      return MidedgeBendingEnergy(rest, topology, material, vertex_offset);
  }
  throw std::invalid_argument("ShellBending: unknown bending model");
}

}  // namespace

ShellBending::ShellBending(BendingModel model, const TriMesh& rest, const MeshTopology& topology,
                           const Material& material, int vertex_offset)
    : energy_(build_bending(model, rest, topology, material, vertex_offset)) {}

double ShellBending::value(const Eigen::VectorXd& x) const {
  return std::visit([&](const auto& energy) { return energy.value(x); }, energy_);
}

void ShellBending::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  std::visit([&](const auto& energy) { energy.add_gradient(x, g); }, energy_);
}

void ShellBending::hessian(const Eigen::VectorXd& x, ElementMatrices& out, bool project_psd) const {
  std::visit([&](const auto& energy) { energy.hessian(x, out, project_psd); }, energy_);
}

BendingModel ShellBending::model() const {
  return std::holds_alternative<BendingEnergy>(energy_) ? BendingModel::hinge
                                                        : BendingModel::midedge;
}

}  // namespace psq
