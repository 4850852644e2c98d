#pragma once
// Everything the solver needs to know about a scene at one resolution, with all shells
// concatenated into one vertex array: rest mesh, elastic energies, masses, pins, loads.

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

/// Pinned vertices and where their scripted motions take them.
struct PinnedVertex {
  int vertex;
  Eigen::Vector3d rest;
  const std::vector<RigidMotion>* motions;
  int group;  ///< index of the pinned set in its shell's `pins`; −1 for a collider vertex
};

/// One shell of a hierarchy level: its rest mesh and, per vertex, the index of the pinned set
/// (into the scene shell's `pins`) that holds it, or a negative number for a free vertex.
struct LevelShellMesh {
  TriMesh rest;
  std::vector<int> pin_group;
};

class ShellSystem {
 public:
  /// Builds every shell's mesh, energies, masses, pins and loads. Throws InputError for
  /// selections that select nothing and for meshes that fail validation.
  explicit ShellSystem(const Scene& scene);
  /// The system of one hierarchy level: the scene's shells (same order, materials and
  /// motions) with the given rest meshes; each pinned vertex follows its set's motions from its
  /// own rest position. External force is gravity on this level's masses; loads are selected
  /// on the finest mesh only, so they are left out (the progressive solver applies the finest
  /// external force through the prolongation). `colliders` are the colliders' rest meshes at
  /// this level, one per scene collider in order (each vertex follows its collider's motions
  /// from its own rest position); empty: the scene's own collider meshes.
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
  /// Constant external force per DOF (3n): gravity and loads.
  [[nodiscard]] const Eigen::VectorXd& external_force() const { return external_force_; }
  [[nodiscard]] const std::vector<PinnedVertex>& pinned() const { return pinned_; }
  [[nodiscard]] std::vector<int> pinned_vertex_indices() const;
  /// Per vertex of shell `shell` (local numbering): the index of the pinned set holding it in
  /// that shell's `pins`, or −1 when it is free.
  [[nodiscard]] std::vector<int> pin_groups(int shell) const;
  /// Sets the pinned vertices of x to their scripted positions at `time`.
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

  Scene scene_;
  TriMesh rest_;
  std::vector<ShellBlock> shells_;
  std::vector<ColliderBlock> colliders_;
  std::vector<MembraneEnergy> membranes_;
  std::vector<ShellBending> bendings_;
  Eigen::VectorXd dof_masses_;
  Eigen::VectorXd external_force_;
  std::vector<PinnedVertex> pinned_;
};

}  // namespace psq
