#pragma once
// The scene model: what a scene file describes, after validation. Units SI throughout.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/elastic/bending_model.hpp"
#include "engine/elastic/material.hpp"
#include "engine/mesh/generators.hpp"

namespace psq {

/// Where a shell's mesh comes from: a file (OBJ, PLY, OFF) or a generator, then a rigid
/// placement (scale, then rotation about the origin, then translation).
struct MeshSource {
  enum class Kind { File, Sheet, Cylinder, Sphere, CylindricalPanel, SphericalPanel } kind =
      Kind::Sheet;
  std::filesystem::path file;  ///< Kind::File, resolved relative to the scene file
  SheetGenerator sheet;
  CylinderGenerator cylinder;
  SphereGenerator sphere;
  CylindricalPanelGenerator cylindrical_panel;
  SphericalPanelGenerator spherical_panel;
  double scale = 1.0;
  Eigen::Vector3d rotation_axis = Eigen::Vector3d::UnitZ();
  double rotation_degrees = 0.0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

/// Chooses vertices of one shell: inside an axis-aligned box, on a boundary loop, or listed.
struct VertexSelector {
  enum class Kind { Box, BoundaryLoop, List } kind = Kind::Box;
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();
  int boundary_loop = 0;  ///< index into the shell's boundary loops, ordered by size, largest first
  std::vector<int> indices;
  /// Where the selector was written (scene file and line; empty / 0 when built in code), so
  /// that a selection that turns out empty on the built mesh can be reported there.
  std::filesystem::path source_file;
  long source_line = 0;
};

/// A rigid motion applied to a pinned set between two times, linearly in time: at time t the
/// set is rotated by angle·s about the axis through `axis_point`, then translated by
/// translation·s, with s = clamp((t − start)/(end − start), 0, 1). Motions of one set compose
/// in order.
struct RigidMotion {
  double start_time = 0.0, end_time = 1.0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitZ();
  double angle_degrees = 0.0;
};

/// Which Cartesian components (x, y, z) a pinned set fixes; the others stay free unknowns of its
/// vertices. Axis-aligned only: a roller on a plane normal to an axis, a symmetry plane normal
/// to an axis, a rigid diaphragm in an axis plane.
using PinComponents = std::array<bool, 3>;

struct PinnedSet {
  std::string name;
  VertexSelector selector;
  std::vector<RigidMotion> motions;  ///< empty: fixed in place; else they prescribe `components`
  PinComponents components{true, true, true};  ///< the `components` key; all three by default
};

/// An external force. `Point` spreads the total force equally over the selected vertices;
/// `Line` spreads it in proportion to each selected vertex's share of the boundary edges
/// whose two ends are both selected.
struct Load {
  enum class Kind { Point, Line } kind = Kind::Point;
  VertexSelector selector;
  Eigen::Vector3d total_force = Eigen::Vector3d::Zero();  ///< [N]
};

/// A shell's strain limit (the `strain_limit` keys of its material table): no principal
/// stretch of any of its triangles may reach `limit` (C-IPC strain limiting,
/// docs/friction-and-strain-limiting.md).
/// What a probe records at every frame (docs/scene-format.md, `[[shell.probe]]`).
enum class ProbeKind {
  /// The mean displacement x − X over a vertex selection [m].
  displacement,
  /// The force a pinned set's vertices exert on what holds them, summed over the components the
  /// set fixes [N] (engine/sim/probes.hpp derives it and its sign).
  reaction,
};

/// A named quantity of one shell recorded per frame: the mean displacement of a selection, or
/// the reaction of one of the shell's pinned sets.
struct Probe {
  std::string name;  ///< unique among the scene's probes
  ProbeKind kind = ProbeKind::displacement;
  VertexSelector selector;  ///< ProbeKind::displacement
  std::string pin;          ///< ProbeKind::reaction: the name of one of the shell's pins
};

struct StrainLimitSettings {
  double limit = 1.05;  ///< s̄ > 1, the largest principal stretch approached
  /// κ_s [N/m] to start from (doubled while the barrier loses); unset: E h δ²
  /// (initial_strain_limit_stiffness).
  std::optional<double> stiffness;
};

struct Shell {
  std::string name;
  MeshSource mesh;
  Material material;
  BendingModel bending = BendingModel::hinge;  ///< the `bending` key
  std::optional<StrainLimitSettings> strain_limit;  ///< none: the shell stretches freely
  std::vector<PinnedSet> pins;
  std::vector<Load> loads;
  std::vector<Probe> probes;
};

/// How every load's force (the [[shell.load]] forces; gravity is not scaled) scales with time:
/// s(t) piecewise linear through the keyframes (t_i, s_i), times strictly increasing, constant
/// before the first keyframe and after the last. A ramp from 0 at `start` to 1 at `end` is the
/// keyframes (start, 0), (end, 1): the same s(t) as a pin motion's (RigidMotion), which a jump
/// (end = start) is too: s = 0 before the time and 1 from it on.
struct LoadScale {
  std::vector<std::pair<double, double>> keyframes{{0.0, 1.0}};  ///< the default: s = 1
};

struct TimeStepping {
  double step = 0.04;  ///< pseudo time step Δt [s]
  int frames = 25;     ///< number of steps; frame k is at time k·Δt
};

/// What a frame's answer is (the [solver] table's frame_solution).
enum class FrameSolution {
  /// A static equilibrium of the frame's loading: the frame's step from the previous frame, then
  /// settling steps with the loading held (engine/sim/settling.hpp) until the state is at rest.
  equilibrium,
  /// One quasistatic step of Δt from the previous frame, a gradient-flow path: for scenes whose
  /// path matters (buckling, contact history), where settling every frame would jump to another
  /// equilibrium than the loading's history leads to. Frames are then not equilibria.
  fixed_step,
};

struct SolverSettings {
  /// Converged when ‖Δx‖∞/Δt falls below this [m/s]. Unset: 1e-4 × bounding-box diagonal / s.
  std::optional<double> tolerance;
  /// Newton iterations per frame (its step and its settling steps together) before reporting
  /// non-convergence.
  int max_iterations = 200;
  FrameSolution frame_solution = FrameSolution::equilibrium;
  /// [solver] hessian: "project_on_demand" (true) or "projected" (NewtonSettings::
  /// project_on_demand).
  bool project_on_demand = false;
};

/// The [hierarchy] table: progressive simulation over a coarse-to-fine hierarchy (paper §3,
/// §4.5). levels = 1 is a direct simulation of the scene's own meshes.
struct HierarchyOptions {
  int levels = 1;              ///< levels including the finest
  double vertex_ratio = 0.25;  ///< each coarser level keeps about this fraction of the vertices
  /// Preview levels stop when a step changes the solution by less than this (‖Δx‖∞/Δt)
  /// [m/s]. Unset: 10 × the solver tolerance.
  std::optional<double> preview_tolerance;
  int preview_iterations = 2;       ///< Newton-type iterations per preview step at most
  std::optional<int> refine_frame;  ///< the frame where levels are refined; unset: the last
};

/// A [[contact.pair]] entry: the friction coefficient between two named bodies, overriding
/// [contact] friction for their contacts.
struct BodyPairFriction {
  std::array<std::string, 2>
      bodies;             ///< shell or collider names; the same name twice: self-contact
  double friction = 0.0;  ///< μ ≥ 0 between them
};

/// The [contact] table: IPC contact between shells, shell self-contact and colliders.
struct ContactSettings {
  /// Unset: on when the scene has more than one body (shells and colliders) or self_contact.
  std::optional<bool> enabled;
  bool self_contact = false;  ///< whether each shell may touch itself
  /// d̂ [m], the gap below which the barrier acts. Unset: 1e-3 × the bounding-box diagonal.
  std::optional<double> activation_distance;
  double thickness = 0.0;           ///< ξ [m], the offset of the contact surface (≥ 0)
  std::optional<double> stiffness;  ///< κ; unset: IPC's automatic choice and updates
  double friction = 0.0;            ///< μ, the friction coefficient between any two bodies
  std::vector<BodyPairFriction> pair_friction;  ///< per-pair overrides of `friction`
  /// ε_v [m per unit time], the tangential speed below which a contact sticks (IPC's static
  /// friction threshold; ε = ε_v Δt). Unset: 1e-3 × the bounding-box diagonal per unit time.
  std::optional<double> friction_slip_velocity;
  double ccd_rescaling = 0.9;       ///< s of the additive CCD (fraction of the safe advance)
  double ccd_ratio_bound = 0.1;     ///< r: a CCD step keeps at least r × the initial gap
  int ccd_max_iterations = 10'000;  ///< CCD advances per pair before stopping conservatively
  /// Skip the barrier and the CCD when no pair is within reach (a speed-up only; off to measure
  /// it).
  bool skip_when_apart = true;
};

/// A rigid triangle mesh taking part in contact: fixed, or moved by keyframed rigid motions
/// (each vertex follows the motions from its placed rest position, like a pinned set).
struct Collider {
  std::string name;
  MeshSource mesh;
  std::vector<RigidMotion> motions;  ///< empty: fixed in place
};

struct Scene {
  std::filesystem::path source;  ///< the scene file, for messages and relative paths
  std::string name;
  std::vector<Shell> shells;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< [m/s²]
  TimeStepping time;
  LoadScale load_scale;
  SolverSettings solver;
  HierarchyOptions hierarchy;
  ContactSettings contact;
  std::vector<Collider> colliders;
};

}  // namespace psq
