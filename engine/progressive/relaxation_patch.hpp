#pragma once
// The local patch of a relaxation (paper §4.4.3: "a few Newton iterations ... on the local
// patch"). A relaxation frees a few vertices of pairs left closer than the safe gap and holds the
// rest; a contact term over the whole surface would spend every iteration's broad phase, pair
// evaluation and CCD on pairs that cannot change. The patch keeps the primitives the freed
// vertices can reach, and confines each freed vertex to a box that makes that exact:
//
// - the freed vertices are grouped into clusters, two freed vertices sharing a triangle or an
//   edge being in one cluster, so every primitive that moves has its freed vertices in one
//   cluster;
// - a cluster's box holds its freed vertices, their targets and the other vertices of their
//   primitives, grown by the largest distance of a freed vertex to its target plus the reach;
// - the patch holds every primitive whose box meets a cluster's box grown by the reach.
//
// While each freed vertex stays inside its cluster's box (Confinement::max_step cuts the steps),
// every moving primitive stays inside that box, farther than the reach from every primitive left
// out: the barrier, its derivatives and the CCD of the patch equal the whole surface's but for
// the constant energy of pairs that do not move.

#include <Eigen/Geometry>
#include <vector>

#include "engine/contact/contact_potential.hpp"

namespace psq {

/// Boxes that freed vertices must stay in during a relaxation.
struct Confinement {
  std::vector<Eigen::AlignedBox3d> boxes;
  std::vector<int> box_of;  ///< per vertex, its box in `boxes`; −1: not confined

  /// The largest t ≤ 1 such that every confined vertex v of x + t·dx (flat) stays in its box;
  /// x must have them inside.
  [[nodiscard]] double max_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) const;
};

struct RelaxationPatch {
  ContactSurface surface;       ///< the primitives the freed vertices can reach, renumbered
  std::vector<int> vertex;      ///< per patch vertex, its vertex in the whole surface
  std::vector<bool> freed;      ///< per patch vertex
  Confinement confinement;      ///< per patch vertex
};

/// The patch of `surface` at positions x (rows per vertex) for relaxing the vertices `freed`
/// toward `target`, where `reach` is the contact thickness plus the activation distance d̂.
RelaxationPatch relaxation_patch(const ContactSurface& surface, const Positions& x,
                                 const Positions& target, const std::vector<bool>& freed,
                                 double reach);

}  // namespace psq
