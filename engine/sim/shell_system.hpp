#pragma once
// Everything the solver needs to know about a scene at one resolution, with all shells
// concatenated into one vertex array: rest mesh, elastic energies, masses, pins, loads.

#include <array>
#include <memory>
#include <vector>

#include "engine/elastic/membrane.hpp"
#include "engine/elastic/shell_bending.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/scene/scene.hpp"

namespace psq {

/// One mesh's place in the concatenated system: its runs of vertices and triangles.
struct MeshBlock {
  std::string name;
  int first_vertex = 0;
  int vertex_count = 0;
  int first_triangle = 0;
  int triangle_count = 0;
  MeshTopology topology;
};

/// A shell's block.
using ShellBlock = MeshBlock;
/// A collider's block: its vertices follow after every shell's and are scripted (pinned)
/// vertices without mass or elastic energy.
using ColliderBlock = MeshBlock;

/// Per Cartesian component of a pinned vertex, the index of the pinned set (in its shell's
/// `pins`) that prescribes it, or −1 when the component is free.
using PinSources = std::array<int, 3>;

/// Pinned vertices and where their scripted motions take their fixed components.
struct PinnedVertex {
  int vertex;
  Eigen::Vector3d rest;
  /// Per component, the motions that prescribe it (from the vertex's rest position), or
  /// nullptr when that component is a free unknown.
  std::array<const std::vector<RigidMotion>*, 3> motions;
  /// The vertex's pin group (LevelShellMesh::pin_group): a set index, a shared condition, or −1
  /// for a collider vertex.
  int group;
  [[nodiscard]] bool fixes(int component) const { return motions[component] != nullptr; }
};

/// One shell of a hierarchy level: its rest mesh and, per vertex, its pin group: negative for a
/// free vertex; k < S (S = the scene shell's number of pins) when set k alone prescribes its
/// fixed components (which are then set k's); S + i for the vertices several sets share, whose
/// fixed components come from different sets as `shared_pins[i]` says. A vertex pinned by
/// several sets fixes every component one of them fixes, each following the first set (in
/// scene order) that fixes it.
struct LevelShellMesh {
  TriMesh rest;
  std::vector<int> pin_group;
  std::vector<PinSources> shared_pins;
};

/// A probe of the scene resolved on the system's vertices (engine/sim/probes.hpp reads it).
struct SystemProbe {
  std::string name;
  ProbeKind kind = ProbeKind::displacement;
  /// ProbeKind::displacement: the selected vertices; ProbeKind::reaction: the DOFs (3·vertex +
  /// component) the probed set fixes, each fixed DOF belonging to the first set that fixes it.
  std::vector<int> indices;
};

class ShellSystem {
 public:
  /// Builds every shell's mesh, energies, masses, pins and loads. Throws InputError for
  /// selections that select nothing, for meshes that fail validation, for shells with slivers
  /// (check_shell_triangle_shapes) and for a time step the tolerance cannot judge convergence
  /// at (check_convergence_resolution).
  explicit ShellSystem(const Scene& scene);
  /// The system of one hierarchy level: the scene's shells (same order, materials and
  /// motions) with the given rest meshes; each pinned vertex follows its set's motions from its
  /// own rest position. External force is gravity on this level's masses; loads are selected
  /// on the finest mesh only, so they are left out (the progressive solver applies the finest
  /// external force through the prolongation). `colliders` are the colliders' rest meshes at
  /// this level, one per scene collider in order (each vertex follows its collider's motions
  /// from its own rest position); empty: the scene's own collider meshes. Probes are selected
  /// on the finest mesh too and are left out alike.
  /// @throws std::invalid_argument when the meshes or pin groups do not fit the scene.
  ShellSystem(const Scene& scene, const std::vector<LevelShellMesh>& shells,
              const std::vector<TriMesh>& colliders = {});
  // Pins point into scene_'s motions: the system stays where it was built.
  ShellSystem(const ShellSystem&) = delete;
  ShellSystem& operator=(const ShellSystem&) = delete;

  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const TriMesh& rest_mesh() const { return rest_; }
  [[nodiscard]] const std::vector<ShellBlock>& shells() const { return shells_; }
  /// Shell `shell`'s rest mesh in its own vertex numbering (local vertex i is global vertex
  /// shells()[shell].first_vertex + i).
  [[nodiscard]] TriMesh shell_rest_mesh(int shell) const;
  /// Collider `collider`'s rest mesh in its own vertex numbering (local vertex i is global
  /// vertex colliders()[collider].first_vertex + i).
  [[nodiscard]] TriMesh collider_rest_mesh(int collider) const;
  /// The colliders, whose vertices and triangles follow the shells' in rest_mesh().
  [[nodiscard]] const std::vector<ColliderBlock>& colliders() const { return colliders_; }
  [[nodiscard]] const std::vector<MembraneEnergy>& membranes() const { return membranes_; }
  /// Per shell, its bending energy in the model the scene chose for it.
  [[nodiscard]] const std::vector<ShellBending>& bendings() const { return bendings_; }
  /// Lumped mass per DOF (3n).
  [[nodiscard]] const Eigen::VectorXd& dof_masses() const { return dof_masses_; }
  /// External force per DOF (3n) at the load time last set (set_load_time; 0 until then):
  /// gravity plus the loads scaled by the scene's load scale.
  [[nodiscard]] const Eigen::VectorXd& external_force() const { return external_force_; }
  /// Sets the time the external force is of: the loads scaled by the scene's load scale at
  /// `time` (scene.hpp, LoadScale); gravity stays as it is.
  void set_load_time(double time);
  /// The loads at scale 1, per DOF (3n): the scene's on the finest mesh; none on a level
  /// system unless set_loads gave them.
  [[nodiscard]] const Eigen::VectorXd& loads() const { return loads_; }
  /// Replaces the loads at scale 1 (3n, per DOF) by `loads`: a level system solved as a
  /// problem of its own carries the finest loads transferred to it. The external force is
  /// that of load time 0 until set_load_time.
  /// @throws std::invalid_argument when the size does not fit the system.
  void set_loads(const Eigen::VectorXd& loads);
  /// The scene's probes on this system's vertices, in scene order (none below the finest).
  [[nodiscard]] const std::vector<SystemProbe>& probes() const { return probes_; }
  /// The vertices with at least one fixed component (shell pins, then every collider vertex).
  [[nodiscard]] const std::vector<PinnedVertex>& pinned() const { return pinned_; }
  /// Per DOF (3n), whether a pin fixes it.
  [[nodiscard]] std::vector<bool> fixed_dofs() const;
  /// Per vertex of shell `shell` (local numbering): its pin group (LevelShellMesh::pin_group),
  /// −1 when it is free.
  [[nodiscard]] std::vector<int> pin_groups(int shell) const;
  /// The fixed components of shell `shell`'s pin groups S, S + 1, ... (LevelShellMesh).
  [[nodiscard]] const std::vector<PinSources>& shared_pins(int shell) const {
    return shared_pins_.at(shell);
  }
  /// Sets the fixed components of the pinned vertices of x to their scripted values at `time`;
  /// free components are left as they are.
  void apply_pins(Eigen::VectorXd& x, double time) const;

 private:
  /// Concatenates the shells' meshes (in scene order) with their energies, masses and gravity.
  void add_shells(const std::vector<TriMesh>& meshes);
  /// The rest mesh of one block in its own vertex numbering.
  [[nodiscard]] TriMesh block_rest_mesh(const MeshBlock& block) const;
  /// The scene's collider meshes, built from their sources and validated.
  [[nodiscard]] std::vector<TriMesh> scene_collider_meshes() const;
  /// Appends the colliders (one mesh per scene collider) after the shells: rest mesh, zero mass
  /// and force, and every collider vertex as a pinned vertex following the collider's motions.
  void add_colliders(const std::vector<TriMesh>& meshes);
  /// Appends shell `shell`'s vertex `v` (local numbering, rest position `rest`) as pinned by
  /// pin group `group` with the components `sources` fixes.
  void add_pinned(int shell, int v, const Eigen::Vector3d& rest, const PinSources& sources,
                  int group);
  /// Appends shell `shell`'s loads to loads_ (selected on `mesh`, its finest mesh).
  void add_loads(int shell, const TriMesh& mesh);
  /// Appends shell `shell`'s probes, selected on `mesh`; `sources` is, per vertex, the set
  /// that fixes each component.
  void add_probes(int shell, const TriMesh& mesh, const std::vector<PinSources>& sources);

  Scene scene_;
  TriMesh rest_;
  std::vector<ShellBlock> shells_;
  std::vector<ColliderBlock> colliders_;
  std::vector<MembraneEnergy> membranes_;
  std::vector<ShellBending> bendings_;
  Eigen::VectorXd dof_masses_;
  Eigen::VectorXd weight_;      ///< gravity on the lumped masses, per DOF
  Eigen::VectorXd loads_;       ///< the loads at scale 1, per DOF
  Eigen::VectorXd external_force_;  ///< weight_ + s · loads_ at the load time last set
  std::vector<PinnedVertex> pinned_;
  std::vector<SystemProbe> probes_;
  std::vector<std::vector<PinSources>> shared_pins_;  ///< per shell, LevelShellMesh::shared_pins
};

}  // namespace psq
