#pragma once
// A fine-to-coarse simulation hierarchy of one shell (paper §4.1–4.2, DESIGN.md §5): the
// rest mesh of every level, built by quadric-error edge collapses from the finest mesh, and
// the intrinsic map (successive self-parameterization) that locates every finer point on
// every coarser level. Levels are numbered as in the paper: 0 is the coarsest, L the finest
// (the input mesh itself).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "engine/mesh/tri_mesh.hpp"

namespace psq {

/// A point on a level's surface: a triangle of that level and barycentric coordinates in it
/// (non-negative, summing to one).
struct SurfaceLocation {
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
};

/// Marks a vertex that no pinned set holds.
inline constexpr int kFreeVertex = -1;

struct HierarchySettings {
  /// Number of levels including the finest; 1 means the input mesh alone.
  int levels = 3;
  /// Each coarser level keeps about this fraction of the vertices of the next finer one.
  double vertex_ratio = 0.25;
  /// A level that no collapse can make coarser ends the hierarchy with fewer levels instead of
  /// being an InputError: for collision objects, whose coarse levels only save work, while a
  /// shell's levels are the schedule the user asked for.
  bool allow_fewer_levels = false;
};

/// One level of the hierarchy.
struct HierarchyLevel {
  TriMesh rest;  ///< this level's rest mesh
  /// Per vertex: its pin group, or kFreeVertex. A group is an opaque id here; for a shell it is
  /// the pin condition of LevelShellMesh::pin_group (engine/sim/shell_system.hpp: which set
  /// prescribes which components), so every coarse pinned vertex, a finest vertex kept in place,
  /// holds exactly the components it holds on the finest mesh. A pinned vertex keeps its finest
  /// rest position at every level, so that one rigid motion places it consistently.
  std::vector<int> pin_group;
  /// Every vertex of the finest level located on this level: the direct map U^l.
  std::vector<SurfaceLocation> finest;
  /// Every vertex of level l+1 located on this level: the per-level map U^l_{l+1}. Empty at
  /// the finest level.
  std::vector<SurfaceLocation> next_finer;
  /// Per vertex of level l+1: the vertex of this level it was collapsed into. Empty at the
  /// finest level.
  std::vector<int> parent;
  /// Per vertex of this level: the colour of its expansion into level l+1 (the vertices whose
  /// parent it is). Two expansions of one colour never touch the same triangle of level l+1,
  /// so they can be carried out in parallel. Empty at the finest level.
  std::vector<int> expansion_color;
  /// The collapses that took level l+1 to this level, in the order they were made: (removed,
  /// survivor) as level-(l+1) vertex indices. Undone in reverse order they are single edge
  /// expansions (paper §4.4.1), each splitting one vertex of normal valence. Empty at the
  /// finest level.
  std::vector<std::array<int, 2>> collapses;
};

/// The levels of one shell, coarsest first; levels.back().rest is the input mesh.
struct MeshHierarchy {
  std::vector<HierarchyLevel> levels;
  [[nodiscard]] int level_count() const { return static_cast<int>(levels.size()); }
  [[nodiscard]] const HierarchyLevel& finest() const { return levels.back(); }
};

/// Shape guarantee of every collapse: no triangle it creates has an angle below this bound,
/// or below the smallest angle of the triangles it replaces if those were already worse.
/// It bounds the aspect ratio by √3 cot 12° ≈ 8.1.
inline constexpr double kHierarchyMinAngleDegrees = 12.0;
/// No triangle a collapse changes turns its normal by more than this.
inline constexpr double kHierarchyMaxNormalChangeDegrees = 60.0;
/// A boundary vertex whose boundary turns by more than this (on the finest mesh or at the
/// time of the collapse) is a corner: it is never removed, and boundary vertices never move.
inline constexpr double kHierarchyCornerDegrees = 40.0;

/// Builds the hierarchy by quadric-error edge collapses (CGAL, probabilistic plane quadrics)
/// in stages: level l is snapshotted once about vertex_ratio × (vertices of level l+1)
/// remain. `pin_group`: per finest vertex, kFreeVertex or a pinned-set id (empty: all free).
/// Rules (docs/hierarchy.md): boundary vertices only collapse along boundary edges onto the
/// other endpoint and never if they are corners; a collapse touching a pinned vertex keeps
/// it at its position; collapses between different pinned sets are refused; collapses that
/// would break the angle or normal bounds, or flip a triangle against the finest surface
/// normals it covers, are refused. A level that cannot reach its target keeps the count it
/// reached. Throws InputError for settings out of range, a pin_group of the wrong size, an
/// invalid mesh, or (unless settings.allow_fewer_levels) a level that no collapse can make
/// coarser than the next finer one.
MeshHierarchy build_hierarchy(const TriMesh& finest, const std::vector<int>& pin_group,
                              const HierarchySettings& settings);

}  // namespace psq
