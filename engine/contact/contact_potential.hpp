#pragma once
// The IPC contact potential of a contact surface (Li et al. 2020): the barrier summed over
// every point–triangle and edge–edge pair within reach, with its gradient, PSD-projected
// Hessian blocks and the CCD-safe step of a line search.
//
//   B(x) = κ Σ_{point–triangle pairs} b(d(x) − ξ²) + κ Σ_{edge–edge pairs} m(c(x)) b(d(x) − ξ²)
//
// with d the squared pair distance (every closest-feature sub-case), b the barrier of
// barrier.hpp (band ξ, d̂) and m the edge–edge mollifier (threshold from the rest positions).
// Pairs sharing a vertex and pairs of bodies the surface's rule keeps apart never enter.
//
// Skips (DESIGN.md §4, docs/contact.md "Skips"), all under `skip_when_apart`:
//  - A clearance certificate (x_ref, r): one BroadPhase::clearance query found no pair within
//    reach + 2r at x_ref. A point–triangle or edge–edge distance changes by at most 2r when
//    every vertex moves by at most r (each point of a segment or triangle is a convex
//    combination of its vertices), so at any x whose every vertex lies within r of its x_ref
//    position no pair is within reach: no barrier work and no broad phase, one O(n) check.
//    A linear step whose both ends are in that set stays in it (the set is a product of
//    balls, which are convex): α = 1, no CCD. Colliders and pinned vertices are part of x, so
//    their scripted motion is checked the same way.
//  - When a state leaves the certificate and the last state had no pair within reach, one
//    clearance query at it (capped at reach + 2 r_max) either renews the certificate there,
//    with r = (clearance − reach)/2 less a rounding margin, or finds a pair within reach (then
//    the candidates are searched as without the skip).
//  - A step that the certificate does not cover, from a state with no pair within reach,
//    costs one query (any_within_reach_during) and no CCD when no pair comes within reach.
// Skipped states and steps, and the certificate's share of them, are counted in ContactStats.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "engine/contact/additive_ccd.hpp"
#include "engine/contact/barrier.hpp"
#include "engine/contact/broad_phase.hpp"
#include "engine/core/element_matrices.hpp"

namespace psq {

/// Every body of a simulation as one contact surface: shells and colliders concatenated.
struct ContactSurface {
  Triangles triangles;
  std::vector<std::array<int, 2>> edges;  ///< unique edges, both ends in one body
  std::vector<int> vertex_body;           ///< body id of every vertex, 0..B−1
  BodyPairRule may_touch;                 ///< which bodies touch (self-contact: a == b)
  Positions rest;                         ///< rest positions (edge–edge mollifier thresholds)
  /// Per vertex, whether the solve holds it (empty: none is held). A pair of held vertices
  /// only has a constant barrier: it is left out of the potential, its derivatives and the CCD.
  std::vector<bool> held;
};

struct ContactParameters {
  BarrierBand band;             ///< d̂ and ξ
  AdditiveCcdSettings ccd;      ///< its min_distance is taken from band.thickness
  bool skip_when_apart = true;  ///< use the early-outs (off only to measure what they save)
};

/// Work counters and times of a ContactPotential, for frame statistics and benchmarks.
struct ContactStats {
  long barrier_evaluations = 0;    ///< states whose active pairs were determined
  long barrier_skips = 0;          ///< of those, states with no pair within reach (no barrier work)
  long ccd_evaluations = 0;        ///< feasible-step queries
  long ccd_skips = 0;              ///< of those, steps on which no pair came within reach (no CCD)
  long ccd_pair_queries = 0;       ///< pair CCD queries run
  long barrier_certified = 0;      ///< of the barrier skips, those the certificate answered
  long ccd_certified = 0;          ///< of the CCD skips, those the certificate answered
  long certificate_renewals = 0;   ///< clearance queries that issued a certificate
  long state_reuses = 0;           ///< states whose candidates the kept CCD search gave
  long ccd_reuses = 0;             ///< CCD queries whose candidates the kept CCD search gave
  long max_active_pairs = 0;       ///< the most pairs within reach at one state
  double broad_phase_seconds = 0;  ///< early-outs and candidate searches of the barrier
  double barrier_seconds = 0;      ///< distances, barrier values and derivatives
  double ccd_seconds = 0;          ///< swept early-outs, swept candidates and pair CCD

  ContactStats& operator+=(const ContactStats& other);
};

/// A pair within reach: point–triangle (p, t0, t1, t2) or edge–edge (a0, a1, b0, b1).
struct ContactPair {
  std::array<int, 4> vertices;
  bool edge_edge = false;
  double mollifier_threshold = 0;  ///< ε_x of an edge–edge pair
};

/// The four positions of a pair's stencil at x (flat, 3n).
PairPositions stencil_positions(const std::array<int, 4>& vertices, const Eigen::VectorXd& x);
/// The squared distance of a pair at x (point_triangle_distance, edge_edge_distance).
double pair_distance(const ContactPair& pair, const Eigen::VectorXd& x);
/// The candidates as stencils in `broad`'s numbering, point–triangle pairs first (mollifier
/// thresholds not set).
std::vector<ContactPair> candidate_pairs(const ContactCandidates& candidates,
                                         const BroadPhase& broad);

/// The constant factor of a pair's barrier at x: the edge–edge mollifier m(c(x)) of an edge–edge
/// pair, 1 for a point–triangle pair (the barrier weight of its normal force, friction.hpp).
double barrier_weight(const ContactPair& pair, const Eigen::VectorXd& x);

/// A clearance certificate: at `reference` no pair was within reach + 2 radius, so no pair is
/// within reach at a state whose every vertex lies within `radius` of its reference position.
struct ClearanceCertificate {
  Eigen::VectorXd reference;
  double radius = -1;  ///< negative: no certificate

  /// Whether every vertex of x lies within the radius of its reference position.
  [[nodiscard]] bool covers(const Eigen::VectorXd& x) const;
  /// Whether both ends of the linear motion x → x + dx (and so all of it) are covered.
  [[nodiscard]] bool covers_motion(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) const;
};

class ContactPotential {
 public:
  /// Throws InputError when d̂ is not positive, ξ is negative or a CCD setting is out of range.
  ContactPotential(ContactSurface surface, const ContactParameters& parameters);

  [[nodiscard]] const ContactParameters& parameters() const { return parameters_; }
  /// The bodies and their vertices (vertex_body tells which pair of bodies a pair joins).
  [[nodiscard]] const ContactSurface& surface() const { return surface_; }
  [[nodiscard]] const BroadPhase& broad_phase() const { return broad_phase_; }
  /// The distance within which pairs interact: ξ + d̂.
  [[nodiscard]] double reach() const;

  void set_stiffness(double kappa) { stiffness_ = kappa; }
  [[nodiscard]] double stiffness() const { return stiffness_; }

  /// B(x); +∞ when a pair is at or within the thickness (a state the line search rejects).
  double value(const Eigen::VectorXd& x);
  /// g += ∇B(x). Throws NumericalError at a penetrating state.
  void add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g);
  /// ∇ of Σ b (κ = 1), for the initial stiffness.
  Eigen::VectorXd unit_gradient(const Eigen::VectorXd& x);
  /// Resets `blocks` to one 4-vertex block per pair within reach: κ·PSD(∇²(m b)) over the
  /// vertices not in `fixed_vertices` (project_moving_block_to_psd; empty: none is fixed), or
  /// κ ∇²(m b) itself without `project_psd` (for derivative checks).
  void hessian(const Eigen::VectorXd& x, ElementMatrices& blocks, bool project_psd = true,
               const std::vector<bool>& fixed_vertices = {});
  /// The smallest squared distance of a pair within reach at x, +∞ when there is none.
  double min_distance(const Eigen::VectorXd& x);
  /// The pairs within reach at x (cached while x does not change).
  const std::vector<ContactPair>& active_pairs(const Eigen::VectorXd& x);

  /// The largest α ≤ 1 such that the linear motion x → x + α dx keeps every pair farther
  /// apart than ξ: the minimum additive-CCD time of impact over the swept candidates (each
  /// already conservative: the gap keeps at least ccd.ratio_bound of its start value).
  /// The candidates are searched within reach + 2s of the motion (the skin s is one reach,
  /// docs/contact.md) and kept: every later state or motion within s of the swept boxes (the line
  /// search's trials, the accepted iterate, the next iterations' short steps) then finds its pairs
  /// among them instead of searching the whole surface again.
  double max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx);

  /// The clearance certificate of the skips (radius < 0 while there is none).
  [[nodiscard]] const ClearanceCertificate& certificate() const { return certificate_; }

  [[nodiscard]] const ContactStats& stats() const { return stats_; }
  void reset_stats() { stats_ = ContactStats{}; }

 private:
  /// The region the last candidate search of a CCD query covered: per vertex, the box its
  /// motion swept, grown by a skin s on every side; and the candidates within reach + 2s of
  /// the unskinned boxes. A later state or motion whose every vertex stays in its box has
  /// every pair within reach among them (each box of a pair lies within s of a searched one).
  struct SearchedRegion {
    Positions lower, upper;
    ContactCandidates candidates;

    /// Whether every vertex of x lies in its box.
    [[nodiscard]] bool contains(const Positions& x) const;
  };

  /// Candidates for the motion start → end: the searched region's when it contains both ends
  /// (its boxes are convex, so the whole motion), else a new search that becomes the region.
  const ContactCandidates& swept_candidates(const Positions& start, const Positions& end);

  /// The candidates' pairs, without those of held vertices only.
  [[nodiscard]] std::vector<ContactPair> moving_pairs(const ContactCandidates& candidates) const;
  void refresh(const Eigen::VectorXd& x);
  bool renew_certificate(const Eigen::VectorXd& x);
  void accumulate_gradient(const Eigen::VectorXd& x, double scale, Eigen::VectorXd& g);

  ContactSurface surface_;
  ContactParameters parameters_;
  BroadPhase broad_phase_;
  double stiffness_ = 1.0;
  ContactStats stats_;
  // The active set of the last state asked about.
  Eigen::VectorXd cached_x_;
  std::vector<ContactPair> active_;
  double min_distance_ = 0;
  ClearanceCertificate certificate_;
  SearchedRegion searched_;
};

}  // namespace psq
