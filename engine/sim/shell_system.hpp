#pragma once
// Everything the solver needs to know about a scene at one resolution, with all shells
// concatenated into one vertex array: rest mesh, elastic energies, masses, pins, loads.

#include <memory>
#include <vector>

#include "engine/elastic/bending.hpp"
#include "engine/elastic/membrane.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/scene/scene.hpp"

namespace psq {

/// One shell's place in the concatenated system.
struct ShellBlock {
  std::string name;
  int first_vertex = 0;
  int vertex_count = 0;
  int first_triangle = 0;
  int triangle_count = 0;
  MeshTopology topology;
};

/// Pinned vertices and where their scripted motions take them.
struct PinnedVertex {
  int vertex;
  Eigen::Vector3d rest;
  const std::vector<RigidMotion>* motions;
};

class ShellSystem {
 public:
  /// Builds every shell's mesh, energies, masses, pins and loads. Throws InputError for
  /// selections that select nothing and for meshes that fail validation.
  explicit ShellSystem(const Scene& scene);
  // Pins point into scene_'s motions: the system stays where it was built.
  ShellSystem(const ShellSystem&) = delete;
  ShellSystem& operator=(const ShellSystem&) = delete;

  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const TriMesh& rest_mesh() const { return rest_; }
  [[nodiscard]] const std::vector<ShellBlock>& shells() const { return shells_; }
  [[nodiscard]] const std::vector<MembraneEnergy>& membranes() const { return membranes_; }
  [[nodiscard]] const std::vector<BendingEnergy>& bendings() const { return bendings_; }
  /// Lumped mass per DOF (3n).
  [[nodiscard]] const Eigen::VectorXd& dof_masses() const { return dof_masses_; }
  /// Constant external force per DOF (3n): gravity and loads.
  [[nodiscard]] const Eigen::VectorXd& external_force() const { return external_force_; }
  [[nodiscard]] const std::vector<PinnedVertex>& pinned() const { return pinned_; }
  [[nodiscard]] std::vector<int> pinned_vertex_indices() const;
  /// Sets the pinned vertices of x to their scripted positions at `time`.
  void apply_pins(Eigen::VectorXd& x, double time) const;

 private:
  Scene scene_;
  TriMesh rest_;
  std::vector<ShellBlock> shells_;
  std::vector<MembraneEnergy> membranes_;
  std::vector<BendingEnergy> bendings_;
  Eigen::VectorXd dof_masses_;
  Eigen::VectorXd external_force_;
  std::vector<PinnedVertex> pinned_;
};

}  // namespace psq
