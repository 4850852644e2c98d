#include "engine/sim/shell_system.hpp"

#include <fmt/format.h>

#include <set>
#include <stdexcept>

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
  auto slot = [&](int v) {
    return std::lower_bound(selected.begin(), selected.end(), v) - selected.begin();
  };
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
  for (const Shell& shell : scene_.shells) {
    TriMesh mesh = build_shell_mesh(shell.mesh);
    validate_mesh(mesh, fmt::format("{}: shell '{}'", scene_.source.string(), shell.name));
    meshes.push_back(std::move(mesh));
  }
  add_shells(meshes);
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    const Shell& shell = scene_.shells[s];
    const ShellBlock& block = shells_[s];
    const TriMesh& mesh = meshes[s];
    for (std::size_t k = 0; k < shell.pins.size(); ++k) {
      const PinnedSet& pin = shell.pins[k];
      const auto what = fmt::format("pin '{}' of shell '{}'", pin.name, shell.name);
      for (int v : select_vertices(pin.selector, mesh, block.topology, what))
        pinned_.push_back({block.first_vertex + v, mesh.vertices.row(v).transpose(), &pin.motions,
                           static_cast<int>(k)});
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
        throw InputError(
            fmt::format("{}: {} is a line load but selects no boundary edge (both ends "
                        "of an edge must be selected)",
                        scene_.source.string(), what));
      for (std::size_t k = 0; k < selected.size(); ++k)
        external_force_.segment<3>(3 * (block.first_vertex + selected[k])) +=
            load.total_force * weight[k] / total;
    }
  }
  // A vertex pinned by two sets keeps the first one's motion.
  std::set<int> seen;
  std::erase_if(pinned_, [&](const PinnedVertex& p) { return !seen.insert(p.vertex).second; });
  add_colliders(scene_collider_meshes());
}

ShellSystem::ShellSystem(const Scene& scene, const std::vector<LevelShellMesh>& shells,
                         const std::vector<TriMesh>& colliders)
    : scene_(scene) {
  if (shells.size() != scene_.shells.size())
    throw std::invalid_argument(fmt::format("ShellSystem: {} level meshes for {} shells",
                                            shells.size(), scene_.shells.size()));
  std::vector<TriMesh> meshes;
  for (const LevelShellMesh& shell : shells) {
    if (static_cast<int>(shell.pin_group.size()) != shell.rest.vertex_count())
      throw std::invalid_argument("ShellSystem: pin_group needs one entry per vertex");
    meshes.push_back(shell.rest);
  }
  add_shells(meshes);
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    const std::vector<PinnedSet>& pins = scene_.shells[s].pins;
    for (int v = 0; v < shells_[s].vertex_count; ++v) {
      const int group = shells[s].pin_group[v];
      if (group < 0) continue;
      if (group >= static_cast<int>(pins.size()))
        throw std::invalid_argument(
            fmt::format("ShellSystem: pin group {} of shell '{}' does not "
                        "exist",
                        group, scene_.shells[s].name));
      pinned_.push_back({shells_[s].first_vertex + v, meshes[s].vertices.row(v).transpose(),
                         &pins[group].motions, group});
    }
  }
  if (!colliders.empty() && colliders.size() != scene_.colliders.size())
    throw std::invalid_argument(fmt::format("ShellSystem: {} level meshes for {} colliders",
                                            colliders.size(), scene_.colliders.size()));
  add_colliders(colliders.empty() ? scene_collider_meshes() : colliders);
}

std::vector<TriMesh> ShellSystem::scene_collider_meshes() const {
  std::vector<TriMesh> meshes;
  for (const Collider& collider : scene_.colliders) {
    TriMesh mesh = build_shell_mesh(collider.mesh);
    validate_mesh(mesh, fmt::format("{}: collider '{}'", scene_.source.string(), collider.name));
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

void ShellSystem::add_colliders(const std::vector<TriMesh>& meshes) {
  for (std::size_t c = 0; c < meshes.size(); ++c) {
    const Collider& collider = scene_.colliders[c];
    const TriMesh& mesh = meshes[c];
    ColliderBlock block{collider.name,         rest_.vertex_count(),
                        mesh.vertex_count(),   rest_.triangle_count(),
                        mesh.triangle_count(), MeshTopology::build(mesh, collider.name)};
    rest_.vertices.conservativeResize(block.first_vertex + block.vertex_count, 3);
    rest_.triangles.conservativeResize(block.first_triangle + block.triangle_count, 3);
    rest_.vertices.bottomRows(block.vertex_count) = mesh.vertices;
    rest_.triangles.bottomRows(block.triangle_count) = mesh.triangles.array() + block.first_vertex;
    const Eigen::Index dofs = 3 * rest_.vertex_count();
    dof_masses_.conservativeResizeLike(Eigen::VectorXd::Zero(dofs));
    external_force_.conservativeResizeLike(Eigen::VectorXd::Zero(dofs));
    for (int v = 0; v < block.vertex_count; ++v)
      pinned_.push_back(
          {block.first_vertex + v, mesh.vertices.row(v).transpose(), &collider.motions, -1});
    colliders_.push_back(std::move(block));
  }
}

void ShellSystem::add_shells(const std::vector<TriMesh>& meshes) {
  int vertices = 0, triangles = 0;
  for (std::size_t s = 0; s < meshes.size(); ++s) {
    const TriMesh& mesh = meshes[s];
    const std::string& name = scene_.shells[s].name;
    ShellBlock block{name,
                     vertices,
                     mesh.vertex_count(),
                     triangles,
                     mesh.triangle_count(),
                     MeshTopology::build(mesh, name)};
    vertices += block.vertex_count;
    triangles += block.triangle_count;
    shells_.push_back(std::move(block));
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
    bendings_.emplace_back(shell.bending, mesh, block.topology, shell.material, block.first_vertex);

    const Eigen::VectorXd mass = lumped_vertex_masses(mesh, shell.material);
    for (int v = 0; v < block.vertex_count; ++v) {
      const int g = block.first_vertex + v;
      dof_masses_.segment<3>(3 * g).setConstant(mass[v]);
      external_force_.segment<3>(3 * g) += mass[v] * scene_.gravity;
    }
  }
}

TriMesh ShellSystem::shell_rest_mesh(int shell) const { return block_rest_mesh(shells_.at(shell)); }

TriMesh ShellSystem::collider_rest_mesh(int collider) const {
  return block_rest_mesh(colliders_.at(collider));
}

TriMesh ShellSystem::block_rest_mesh(const MeshBlock& block) const {
  TriMesh mesh;
  mesh.vertices = rest_.vertices.middleRows(block.first_vertex, block.vertex_count);
  mesh.triangles = rest_.triangles.middleRows(block.first_triangle, block.triangle_count).array() -
                   block.first_vertex;
  return mesh;
}

std::vector<int> ShellSystem::pinned_vertex_indices() const {
  std::vector<int> out;
  out.reserve(pinned_.size());
  for (const PinnedVertex& p : pinned_) out.push_back(p.vertex);
  return out;
}

std::vector<int> ShellSystem::pin_groups(int shell) const {
  const ShellBlock& block = shells_.at(shell);
  std::vector<int> groups(block.vertex_count, -1);
  for (const PinnedVertex& p : pinned_) {
    const int local = p.vertex - block.first_vertex;
    if (local >= 0 && local < block.vertex_count) groups[local] = p.group;
  }
  return groups;
}

void ShellSystem::apply_pins(Eigen::VectorXd& x, double time) const {
  for (const PinnedVertex& p : pinned_)
    x.segment<3>(3 * p.vertex) = apply_motions(*p.motions, p.rest, time);
}

}  // namespace psq
