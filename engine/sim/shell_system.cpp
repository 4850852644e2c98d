#include "engine/sim/shell_system.hpp"

#include <fmt/format.h>
#include <set>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/scene/rigid_motion.hpp"
#include "engine/scene/shell_mesh.hpp"
#include "engine/scene/vertex_selection.hpp"
#include "engine/sim/lumped_mass.hpp"

namespace psq {
namespace {

/// Per-vertex weights of a line load: half the length of every boundary edge whose two
/// ends are both selected goes to each end.
std::vector<double> line_load_weights(const TriMesh& mesh, const MeshTopology& topo,
                                      const std::vector<int>& selected) {
  const std::set<int> chosen(selected.begin(), selected.end());
  std::vector<double> weight(selected.size(), 0.0);
  auto slot = [&](int v) { return std::lower_bound(selected.begin(), selected.end(), v) - selected.begin(); };
  for (const auto& loop : topo.boundary_loops)
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k];
      const int b = loop[(k + 1) % loop.size()];
      if (!chosen.count(a) || !chosen.count(b)) continue;
      const double half = 0.5 * (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
      weight[slot(a)] += half;
      weight[slot(b)] += half;
    }
  return weight;
}

}  // namespace

ShellSystem::ShellSystem(const Scene& scene) : scene_(scene) {
  std::vector<TriMesh> meshes;
  int vertices = 0, triangles = 0;
  for (const Shell& shell : scene_.shells) {
    TriMesh mesh = build_shell_mesh(shell.mesh);
    validate_mesh(mesh, fmt::format("{}: shell '{}'", scene_.source.string(), shell.name));
    ShellBlock block{shell.name, vertices, mesh.vertex_count(), triangles, mesh.triangle_count(),
                     MeshTopology::build(mesh, shell.name)};
    vertices += block.vertex_count;
    triangles += block.triangle_count;
    shells_.push_back(std::move(block));
    meshes.push_back(std::move(mesh));
  }
  if (shells_.empty())
    throw InputError(fmt::format("{}: the scene has no [[shell]]", scene_.source.string()));

  rest_.vertices.resize(vertices, 3);
  rest_.triangles.resize(triangles, 3);
  dof_masses_ = Eigen::VectorXd::Zero(3 * vertices);
  external_force_ = Eigen::VectorXd::Zero(3 * vertices);
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    const Shell& shell = scene_.shells[s];
    const ShellBlock& block = shells_[s];
    const TriMesh& mesh = meshes[s];
    rest_.vertices.middleRows(block.first_vertex, block.vertex_count) = mesh.vertices;
    rest_.triangles.middleRows(block.first_triangle, block.triangle_count) =
        mesh.triangles.array() + block.first_vertex;
    membranes_.emplace_back(mesh, shell.material, block.first_vertex);
    bendings_.emplace_back(mesh, block.topology, shell.material, block.first_vertex);

    const Eigen::VectorXd mass = lumped_vertex_masses(mesh, shell.material);
    for (int v = 0; v < block.vertex_count; ++v) {
      const int g = block.first_vertex + v;
      dof_masses_.segment<3>(3 * g).setConstant(mass[v]);
      external_force_.segment<3>(3 * g) += mass[v] * scene_.gravity;
    }
    for (const PinnedSet& pin : shell.pins) {
      const auto what = fmt::format("pin '{}' of shell '{}'", pin.name, shell.name);
      for (int v : select_vertices(pin.selector, mesh, block.topology, what))
        pinned_.push_back({block.first_vertex + v, mesh.vertices.row(v).transpose(), &pin.motions});
    }
    for (std::size_t l = 0; l < shell.loads.size(); ++l) {
      const Load& load = shell.loads[l];
      const auto what = fmt::format("load {} of shell '{}'", l + 1, shell.name);
      std::vector<int> selected = select_vertices(load.selector, mesh, block.topology, what);
      std::sort(selected.begin(), selected.end());
      std::vector<double> weight(selected.size(), 1.0);
      if (load.kind == Load::Kind::Line) weight = line_load_weights(mesh, block.topology, selected);
      double total = 0.0;
      for (double w : weight) total += w;
      if (total <= 0.0)
        throw InputError(fmt::format("{}: {} is a line load but selects no boundary edge (both ends "
                                     "of an edge must be selected)", scene_.source.string(), what));
      for (std::size_t k = 0; k < selected.size(); ++k)
        external_force_.segment<3>(3 * (block.first_vertex + selected[k])) += load.total_force * weight[k] / total;
    }
  }
  // A vertex pinned by two sets keeps the first one's motion.
  std::set<int> seen;
  std::erase_if(pinned_, [&](const PinnedVertex& p) { return !seen.insert(p.vertex).second; });
}

std::vector<int> ShellSystem::pinned_vertex_indices() const {
  std::vector<int> out;
  out.reserve(pinned_.size());
  for (const PinnedVertex& p : pinned_) out.push_back(p.vertex);
  return out;
}

void ShellSystem::apply_pins(Eigen::VectorXd& x, double time) const {
  for (const PinnedVertex& p : pinned_) x.segment<3>(3 * p.vertex) = apply_motions(*p.motions, p.rest, time);
}

}  // namespace psq
