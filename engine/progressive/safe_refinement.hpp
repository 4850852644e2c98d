#pragma once
// Safe initialization of a finer level from a coarser level's intersection-free state (paper
// §4.4, DESIGN.md §6): the level-(l+1) mesh is expanded from x_l one colour of the expansion
// colouring at a time, so that no state on the way intersects.
//
// Each level-(l+1) vertex starts at its parent's position: every coarse vertex is a cluster of
// coincident children, and the surface is x_l itself ("mixed" meshes below: the level-(l+1)
// triangles with the not yet expanded clusters merged into one vertex, whose images are the
// level-l triangles). The safe gap g is measured once, on x_l: the smallest distance between
// primitives that may touch (capped at the barrier's reach). Per colour:
//   1. the gap of the current mixed mesh, which bounds how far a perturbation may move;
//   2. every cluster of the colour is placed at its anchors (its children's intrinsic places on
//      the deformed level-l surface, in the sectors of the parent's one-ring their triangles
//      take), which resample the level-l surface itself; the exact check decides, and a cluster
//      whose patch intersects or comes closer than a perturbation to anything is placed instead
//      with its anchor layout shrunk about the parent, its farthest child at a tenth of the
//      current gap. Every point of the new triangles is then within that distance of the old
//      surface, so only the expansion patch itself can intersect; the exact check decides. A
//      cluster whose patch intersects, or whose own pairs come closer than a hundredth of the
//      layout's size, is tried again toward its prolonged targets, then with
//      the children's rest layout turned by the rotation that best fits it to the targets, then
//      by random rotations; a cluster no layout suits is expanded by undoing its collapses
//      latest first (single edge expansions, §4.4.1): each removed vertex splits off its
//      survivor toward its anchor's offset, then into the sector of its neighbours, then in
//      random directions, its triangles checked exactly (bounded tries, seeded so that a
//      resumed run repeats them);
//   3. shrunk layouts grow back to full size about their parents by additive CCD (a scaled patch
//      keeps its shape, so its own pairs only separate), then the colour's vertices advance
//      toward their targets by additive CCD (ACCD with the per-pair ratio bound: 0.999 for a
//      pair already closer than g, 0.1 otherwise, over the pairs whose swept boxes come within
//      g). The advance is repeated: each round moves every vertex by the smallest safe
//      fraction, then stops the vertices of the pairs that limited it, and the others go on
//      (§4.4.4).
// After the last colour every vertex advances toward its target the same way, and the vertices
// the advances stopped short, with those of pairs left closer than g, are relaxed toward their
// targets with the barrier (patch relaxation, §4.4.3, target_relaxation.hpp). The result is
// checked once more with exact predicates; every step of the way is intersection-free by
// construction, the final check is the independent judge.
//
// The colours come from the hierarchy (two clusters of one colour never share a level-(l+1)
// triangle); the broad phase is built once per batch over the batch's whole motion.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "engine/sim/shell_system.hpp"

namespace psq {

/// Told the phase of a refinement as it starts ("batch 2 of 5: 40 clusters", "advance", …), for
/// progress display; the refinement writes nothing, so a process killed inside it resumes from
/// the level it refines.
using RefinementProgress = std::function<void(const std::string& phase)>;

/// What one refinement's safe initialization did.
struct RefinementStats {
  int level = 0;                  ///< the level refined into
  int expansions = 0;             ///< coarse vertices split into two or more vertices
  int batches = 0;                ///< colours with at least one expansion
  int perturbation_retries = 0;   ///< cluster perturbations tried again after an intersection
  int ccd_rounds = 0;             ///< additive CCD advances, all batches and the final one
  int folded_advances = 0;        ///< advances that ended folded, redone with each round checked
  double smallest_gap = 0.0;      ///< smallest g measured before a batch [m]
  double final_gap = 0.0;         ///< smallest distance at the initializer (capped at d̂) [m]
  double max_target_distance = 0.0;   ///< largest |initializer − prolonged target| of a vertex
  double mean_target_distance = 0.0;  ///< mean of the same
  double gap_seconds = 0.0;       ///< measuring g
  double perturb_seconds = 0.0;   ///< perturbations and their exact checks
  double ccd_seconds = 0.0;       ///< CCD advances
  double check_seconds = 0.0;     ///< the final exact check
  int relaxed_vertices = 0;       ///< vertices the patch relaxation freed (target_relaxation.hpp)
  int relax_iterations = 0;       ///< its Newton iterations
  double relax_seconds = 0.0;     ///< its time
  double seconds = 0.0;           ///< the whole initialization
};

/// The level-(l+1) initializer of `fine` (the level-(l+1) system, colliders included) from
/// `coarse_x` (level l, intersection-free): `parent[v]` is the level-l vertex each level-(l+1)
/// vertex collapsed into (a collider vertex: its own copy), `color[k]` the expansion colour of
/// level-l vertex k, `collapses` the collapses that made level l from level l+1 in order
/// ((removed, survivor), level-(l+1) indices; HierarchyLevel::collapses), `anchors` the linear part U^l_{l+1} x_l of the prolongation (each vertex
/// at its intrinsic place on the deformed level-l surface), `target` the prolonged state P^l_{l+1}(x_l) with the pinned vertices at
/// their scripted positions. `level` (l+1) names the level in messages and stats; `progress`
/// (if set) is told each phase as it starts.
/// @throws NumericalError naming the level and vertex when no intersection-free perturbation
/// of a cluster is found, or when the final state fails the exact check.
Eigen::VectorXd safe_initialize(const ShellSystem& fine, const std::vector<int>& parent,
                                const std::vector<int>& color, const Eigen::VectorXd& coarse_x,
                                const std::vector<std::array<int, 2>>& collapses,
                                const Eigen::VectorXd& anchors, const Eigen::VectorXd& target,
                                int level, RefinementStats& stats,
                                const RefinementProgress& progress = {});

}  // namespace psq
