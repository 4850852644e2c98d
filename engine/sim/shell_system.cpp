#include "engine/sim/shell_system.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "engine/core/error.hpp"
#include "engine/mesh/mesh_io.hpp"
#include "engine/mesh/triangle_shape.hpp"
#include "engine/scene/load_scale.hpp"
#include "engine/scene/rigid_motion.hpp"
#include "engine/scene/shell_mesh.hpp"
#include "engine/scene/vertex_selection.hpp"
#include "engine/sim/lumped_mass.hpp"
#include "engine/sim/solver_tolerance.hpp"

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

/// The fixed components of a vertex that set `set` alone pins.
PinSources single_set_sources(const PinnedSet& pin, int set) {
  PinSources sources{-1, -1, -1};
  for (int c = 0; c < 3; ++c)
    if (pin.components[c]) sources[c] = set;
  return sources;
}

/// The pin group (LevelShellMesh::pin_group) of a vertex whose components `sources` fixes:
/// the set index when one set prescribes them all, else S + its index in `shared` (appended
/// when new), so that vertices under the same condition share a group.
int pin_group_of(const PinSources& sources, int set_count, std::vector<PinSources>& shared) {
  int only = -1;
  bool mixed = false;
  for (int set : sources) {
    if (set < 0) continue;
    if (only >= 0 && set != only) mixed = true;
    only = set;
  }
  if (!mixed) return only;
  const auto it = std::find(shared.begin(), shared.end(), sources);
  if (it != shared.end()) return set_count + static_cast<int>(it - shared.begin());
  shared.push_back(sources);
  return set_count + static_cast<int>(shared.size()) - 1;
}

}  // namespace

void ShellSystem::add_pinned(int shell, int v, const Eigen::Vector3d& rest,
                             const PinSources& sources, int group) {
  const std::vector<PinnedSet>& pins = scene_.shells[shell].pins;
  PinnedVertex pinned{shells_[shell].first_vertex + v, rest, {nullptr, nullptr, nullptr}, group};
  for (int c = 0; c < 3; ++c)
    if (sources[c] >= 0) pinned.motions[c] = &pins[sources[c]].motions;
  pinned_.push_back(pinned);
}

ShellSystem::ShellSystem(const Scene& scene) : scene_(scene) {
  std::vector<TriMesh> meshes;
  for (const Shell& shell : scene_.shells) {
    TriMesh mesh = build_shell_mesh(shell.mesh);
    const std::string source = fmt::format("{}: shell '{}'", scene_.source.string(), shell.name);
    validate_mesh(mesh, source);
    check_shell_triangle_shapes(mesh, source);
    meshes.push_back(std::move(mesh));
  }
  add_shells(meshes);
  for (std::size_t s = 0; s < shells_.size(); ++s) {
    const Shell& shell = scene_.shells[s];
    const ShellBlock& block = shells_[s];
    const TriMesh& mesh = meshes[s];
    // Per vertex, each component from the first set (in scene order) that fixes it.
    std::vector<PinSources> sources(mesh.vertex_count(), PinSources{-1, -1, -1});
    for (std::size_t k = 0; k < shell.pins.size(); ++k) {
      const PinnedSet& pin = shell.pins[k];
      const auto what = fmt::format("pin '{}' of shell '{}'", pin.name, shell.name);
      for (int v : select_vertices(pin.selector, mesh, block.topology, what))
        for (int c = 0; c < 3; ++c)
          if (pin.components[c] && sources[v][c] < 0) sources[v][c] = static_cast<int>(k);
    }
    std::vector<PinSources>& shared = shared_pins_[s];
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      const int group = pin_group_of(sources[v], static_cast<int>(shell.pins.size()), shared);
      if (group >= 0)
        add_pinned(static_cast<int>(s), v, mesh.vertices.row(v).transpose(), sources[v], group);
    }
    add_loads(static_cast<int>(s), mesh);
    add_probes(static_cast<int>(s), mesh, sources);
  }
  add_colliders(scene_collider_meshes());
  set_load_time(0.0);
  check_convergence_resolution(scene_, bounding_box_diagonal(rest_.vertices));
}

void ShellSystem::add_loads(int shell_index, const TriMesh& mesh) {
  const Shell& shell = scene_.shells[shell_index];
  const ShellBlock& block = shells_[shell_index];
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
      loads_.segment<3>(3 * (block.first_vertex + selected[k])) +=
          load.total_force * weight[k] / total;
  }
}

void ShellSystem::add_probes(int shell_index, const TriMesh& mesh,
                             const std::vector<PinSources>& sources) {
  const Shell& shell = scene_.shells[shell_index];
  const ShellBlock& block = shells_[shell_index];
  for (const Probe& probe : shell.probes) {
    SystemProbe resolved{probe.name, probe.kind, {}};
    if (probe.kind == ProbeKind::displacement) {
      const auto what = fmt::format("probe '{}' of shell '{}'", probe.name, shell.name);
      for (int v : select_vertices(probe.selector, mesh, block.topology, what))
        resolved.indices.push_back(block.first_vertex + v);
    } else {
      const auto pin = std::find_if(shell.pins.begin(), shell.pins.end(),
                                    [&](const PinnedSet& p) { return p.name == probe.pin; });
      if (pin == shell.pins.end())
        throw InputError(fmt::format("{}: probe '{}' of shell '{}' names no pin of the shell ('{}')",
                                     scene_.source.string(), probe.name, shell.name, probe.pin));
      const int set = static_cast<int>(pin - shell.pins.begin());
      for (int v = 0; v < mesh.vertex_count(); ++v)
        for (int c = 0; c < 3; ++c)
          if (sources[v][c] == set) resolved.indices.push_back(3 * (block.first_vertex + v) + c);
      // Every component of the set's vertices may come from earlier sets.
      if (resolved.indices.empty())
        throw InputError(fmt::format(
            "{}: probe '{}' of shell '{}' records the reaction of pin '{}', but earlier pins "
            "fix every component of that pin's vertices; probe the pin that fixes them",
            scene_.source.string(), probe.name, shell.name, probe.pin));
    }
    probes_.push_back(std::move(resolved));
  }
}

void ShellSystem::set_load_time(double time) {
  external_force_ = weight_ + load_scale_at(scene_.load_scale, time) * loads_;
}

void ShellSystem::set_loads(const Eigen::VectorXd& loads) {
  if (loads.size() != loads_.size())
    throw std::invalid_argument(fmt::format("ShellSystem::set_loads: {} values for {} DOFs",
                                            loads.size(), loads_.size()));
  loads_ = loads;
  set_load_time(0.0);
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
    const int set_count = static_cast<int>(pins.size());
    shared_pins_[s] = shells[s].shared_pins;
    for (const PinSources& sources : shared_pins_[s])
      for (int set : sources)
        if (set >= set_count)
          throw std::invalid_argument(fmt::format(
              "ShellSystem: a shared pin of shell '{}' names set {}", scene_.shells[s].name, set));
    for (int v = 0; v < shells_[s].vertex_count; ++v) {
      const int group = shells[s].pin_group[v];
      if (group < 0) continue;
      if (group >= set_count + static_cast<int>(shared_pins_[s].size()))
        throw std::invalid_argument(
            fmt::format("ShellSystem: pin group {} of shell '{}' does not "
                        "exist",
                        group, scene_.shells[s].name));
      const PinSources sources = group < set_count ? single_set_sources(pins[group], group)
                                                   : shared_pins_[s][group - set_count];
      add_pinned(static_cast<int>(s), v, meshes[s].vertices.row(v).transpose(), sources, group);
    }
  }
  if (!colliders.empty() && colliders.size() != scene_.colliders.size())
    throw std::invalid_argument(fmt::format("ShellSystem: {} level meshes for {} colliders",
                                            colliders.size(), scene_.colliders.size()));
  add_colliders(colliders.empty() ? scene_collider_meshes() : colliders);
  set_load_time(0.0);
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
    weight_.conservativeResizeLike(Eigen::VectorXd::Zero(dofs));
    loads_.conservativeResizeLike(Eigen::VectorXd::Zero(dofs));
    for (int v = 0; v < block.vertex_count; ++v)
      pinned_.push_back({block.first_vertex + v,
                         mesh.vertices.row(v).transpose(),
                         {&collider.motions, &collider.motions, &collider.motions},
                         -1});
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
    shared_pins_.emplace_back();
  }
  if (shells_.empty())
    throw InputError(fmt::format("{}: the scene has no [[shell]]", scene_.source.string()));

  rest_.vertices.resize(vertices, 3);
  rest_.triangles.resize(triangles, 3);
  dof_masses_ = Eigen::VectorXd::Zero(3 * vertices);
  weight_ = Eigen::VectorXd::Zero(3 * vertices);
  loads_ = Eigen::VectorXd::Zero(3 * vertices);
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
      weight_.segment<3>(3 * g) += mass[v] * scene_.gravity;
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

std::vector<bool> ShellSystem::fixed_dofs() const {
  std::vector<bool> fixed(static_cast<std::size_t>(3 * rest_.vertex_count()), false);
  for (const PinnedVertex& p : pinned_)
    for (int c = 0; c < 3; ++c)
      if (p.fixes(c)) fixed[static_cast<std::size_t>(3 * p.vertex + c)] = true;
  return fixed;
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
  for (const PinnedVertex& p : pinned_) {
    // Components usually share their motions: place the point once per distinct motion list.
    const std::vector<RigidMotion>* placed_by = nullptr;
    Eigen::Vector3d placed;
    for (int c = 0; c < 3; ++c) {
      if (!p.fixes(c)) continue;
      if (p.motions[c] != placed_by) {
        placed_by = p.motions[c];
        placed = apply_motions(*placed_by, p.rest, time);
      }
      x[3 * p.vertex + c] = placed[c];
    }
  }
}

}  // namespace psq
