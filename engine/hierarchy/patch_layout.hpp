#pragma once
// Flattening of the small disk-shaped patches touched by one edge collapse, for the
// successive self-parameterization of Liu et al. 2021 (DESIGN.md §5). Both the patch before
// and the patch after a collapse are laid out over the same boundary polygon, so points can
// be carried from one to the other by their 2D position.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace psq {

/// A triangulated disk in local vertex numbering, faces consistently oriented.
struct Patch {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<int, 3>> faces;
};

/// The patch boundary as one loop of local vertices, interior on the left (the order of the
/// faces' own boundary edges); empty when the boundary is not a single simple loop.
std::vector<int> patch_boundary_loop(const Patch& patch);

/// Orthogonal projection onto the plane normal to `normal` (unit), in an orthonormal basis
/// of that plane. For a nearly flat patch this is close to isometric, so points carried
/// through it barely move; a patch of a flat sheet is reproduced exactly.
std::vector<Eigen::Vector2d> projected_layout(const std::vector<Eigen::Vector3d>& positions,
                                              const Eigen::Vector3d& normal);

/// True when every face of the patch is counter-clockwise in the layout with a twice-area of
/// at least `fraction` times its 3D twice-area (no face folded or seen almost edge-on).
bool faces_fit_layout(const std::vector<Eigen::Vector2d>& uv, const Patch& patch,
                      double fraction);

/// 2D positions of the loop on the unit circle, spaced by the 3D lengths of the loop edges
/// (a convex polygon, so that Tutte's theorem makes the interior embedding valid).
std::vector<Eigen::Vector2d> circle_layout(const Patch& patch, const std::vector<int>& loop);

/// Fills uv for every vertex whose `fixed` flag is false so that each is the mean-value
/// weighted average of its neighbours (Floater 2003: positive weights from the 3D angles,
/// w_ij = (tan(α_{j−1}/2) + tan(α_j/2)) / |x_j − x_i|). With a convex fixed boundary the
/// result is a valid embedding. Returns false if the weights are not finite.
bool mean_value_layout(const Patch& patch, const std::vector<bool>& fixed,
                       std::vector<Eigen::Vector2d>& uv);

/// Twice the signed area of the 2D triangle (a, b, c); positive when counter-clockwise.
double signed_double_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const Eigen::Vector2d& c);

/// A point of a layout: a face and barycentric coordinates (non-negative, sum one).
struct LayoutLocation {
  int face = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  double distance = 0;  ///< from the query point to the located point (0 when inside)
};

/// The face of the layout containing `point`, or, if none does (a point cut off when a
/// boundary vertex is removed), the closest point of the layout.
LayoutLocation locate_in_layout(const std::vector<Eigen::Vector2d>& uv,
                                const std::vector<std::array<int, 3>>& faces,
                                const Eigen::Vector2d& point);

}  // namespace psq
