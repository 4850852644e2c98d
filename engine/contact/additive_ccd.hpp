#pragma once
// Additive continuous collision detection (ACCD, Li et al. 2021, "Codimensional Incremental
// Potential Contact") for point–triangle and edge–edge pairs moving linearly over a step.
//
// The four vertices move from `start` to `end` as x(t) = start + t (end − start), t ∈ [0, 1].
// After subtracting the mean displacement (distances do not see a common translation), the
// distance d(t) between the primitives changes at most at the rate l_p, the sum of the largest
// relative displacement on each side. From a gap d − ξ the pair therefore stays farther apart
// than ξ for the time (d − ξ)/l_p, and ACCD advances by a fraction of it,
//   Δt = s′ (d − ξ)/l_p,  s′ = min(s, 1 − r),
// re-measuring d after each advance. It stops — reporting a possible collision at the time t*
// reached — before a step that would end with a gap below r (d₀ − ξ); it reports no collision
// once the advance reaches t_max. We use the unsigned distance d (not d²): the gap d − ξ is
// then formed directly, and the distance routines are those of ccd_distance.hpp.
// Li et al. tie the two knobs together (s = 1 − r); here they are separate so that PSQ's
// r = 0.999 means "keep 99.9% of the gap" while the default s = 0.9, r = 0.1 is theirs.
//
// Every [0, t*] returned is safe: the distance stays above ξ on it (a strict bound in exact
// arithmetic; rounding is covered by the margin below). At t* the gap is at least r (d₀ − ξ)
// (the "ratio bound", PSQ §4.4.2), except that t* may be 0.
//
// Floating point: d is computed from rounded coordinates, so ξ is enlarged by a margin
// δ = 16 ε_mach · max |coordinate| of the eight positions — about 3.6e-15 m in a scene one
// metre across. Without it, pairs whose exact distance is below rounding level could be
// stepped through; with it they are reported as touching (a false positive at worst).

#include <Eigen/Core>
#include <array>
#include <limits>

namespace psq {

/// Positions of the four vertices of a primitive pair: point–triangle (p, t0, t1, t2) or
/// edge–edge (a0, a1, b0, b1).
using PairPositions = std::array<Eigen::Vector3d, 4>;

/// δ = 16 ε max |coordinate|: how far rounding of positions with coordinates up to
/// `largest_coordinate` (in absolute value) and of a distance computed from them may move a
/// pair distance. The CCD enlarges ξ by it; the contact skips shrink their clearance by it.
double distance_rounding_margin(double largest_coordinate);

/// Parameters of the additive CCD. The defaults are those of Li et al. (s = 0.9, r = 0.1).
struct AdditiveCcdSettings {
  /// s ∈ (0, 1): the fraction of the guaranteed-safe time (d − ξ)/l_p taken per advance
  /// (Li et al.'s conservative rescaling; capped at 1 − r so that a single advance never
  /// crosses the ratio bound).
  double rescaling = 0.9;
  /// r ∈ (0, 1): the minimum-distance ratio. The reported t* keeps the gap d − ξ at least
  /// r·(d₀ − ξ). PSQ's safe expansion uses 0.999 for pairs already closer than its gap and
  /// 0.1 otherwise; a larger r means smaller advances and more iterations.
  double ratio_bound = 0.1;
  /// ξ ≥ 0: the minimum separation (thickness) that counts as contact.
  double min_distance = 0.0;
  /// Advances before giving up; a capped query reports a collision at the time reached. With
  /// the default s and r the shared benchmark set needs at most ~6500; a larger r needs more.
  int max_iterations = 10'000;
  /// The query covers t ∈ [0, t_max] (t_max > 0); t_max = 1 is the full step.
  double t_max = 1.0;
  /// Once the advance has passed this time the query ends, reporting no collision at the time
  /// reached: a caller that already holds this bound from another pair learns nothing more.
  /// Unlike a smaller t_max it leaves the advances before it as they are, so a collision found
  /// earlier is found at the same time.
  double stop_after = std::numeric_limits<double>::infinity();
};

/// Throws InputError naming the first setting outside its range (see AdditiveCcdSettings).
void validate_ccd_settings(const AdditiveCcdSettings& settings);

/// The outcome of one CCD query.
struct CcdResult {
  /// False when the primitives provably stay farther apart than ξ over [0, t_max]; true when
  /// that could not be shown (a contact, a near miss closer than the ratio bound allows, an
  /// initial distance ≤ ξ, or the iteration cap).
  bool collision = false;
  /// t* ∈ [0, t_max]: the pair stays farther apart than ξ over [0, t*]; t_max without
  /// collision. As a step-size filter, t* is the largest safe fraction of the step.
  double toi = 0.0;
  /// Distance evaluations after the initial one.
  int iterations = 0;
};

/// The time s′ (d₀ − ξ − δ)/l_p that a pair's first advance covers: over [0, t] with t up to
/// it the pair provably stays apart, and its query cannot report a collision before it. 0 when the pair starts
/// within ξ + δ, +∞ when it does not move relative to itself. Lets a caller after the smallest
/// time of impact over many pairs skip those that cannot lower the one it already has.
double ccd_first_advance(const PairPositions& start, const PairPositions& end, bool edge_edge,
                         const AdditiveCcdSettings& settings = {});

/// ACCD for a point p and a triangle (t0, t1, t2): positions (p, t0, t1, t2) at t = 0 and 1.
/// l_p = |Δp| + max_i |Δt_i| after the mean displacement is removed. NumericalError if a
/// position is not finite (both functions).
CcdResult point_triangle_ccd(const PairPositions& start, const PairPositions& end,
                             const AdditiveCcdSettings& settings = {});

/// ACCD for edges (a0, a1) and (b0, b1): positions (a0, a1, b0, b1) at t = 0 and 1.
/// l_p = max(|Δa0|, |Δa1|) + max(|Δb0|, |Δb1|) after the mean displacement is removed.
CcdResult edge_edge_ccd(const PairPositions& start, const PairPositions& end,
                        const AdditiveCcdSettings& settings = {});

}  // namespace psq
