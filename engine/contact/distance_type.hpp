#pragma once
// The closest-feature sub-cases of the IPC contact distances (which pair of features of a
// point–triangle or edge–edge pair is closest), and the value–gradient–Hessian triple every
// contact kernel returns.
//
// Every distance in engine/contact is a SQUARED Euclidean distance, as in IPC: it is smooth
// where the unsigned distance is not (at zero) and needs no square root.

#include <Eigen/Core>

namespace psq {

/// Value, gradient and Hessian of a scalar function of a contact stencil's vertex positions,
/// ordered vertex by vertex (x, y, z of vertex 0, then vertex 1, …). Vertices the function
/// does not depend on have zero entries.
template <int Dofs>
struct StencilDerivatives {
  double value = 0;
  Eigen::Matrix<double, Dofs, 1> gradient = Eigen::Matrix<double, Dofs, 1>::Zero();
  Eigen::Matrix<double, Dofs, Dofs> hessian = Eigen::Matrix<double, Dofs, Dofs>::Zero();
};

/// Chain rule for f(g(x)) from f, f′, f″ evaluated at g(x) and g's derivatives:
///   ∇(f∘g) = f′ ∇g,   ∇²(f∘g) = f″ ∇g ∇gᵀ + f′ ∇²g.
template <int Dofs>
StencilDerivatives<Dofs> chain_rule(double f, double df, double d2f,
                                    const StencilDerivatives<Dofs>& g) {
  StencilDerivatives<Dofs> r;
  r.value = f;
  r.gradient = df * g.gradient;
  r.hessian = d2f * g.gradient * g.gradient.transpose() + df * g.hessian;
  return r;
}

/// Where on the edge (e0, e1) the point closest to p lies: an endpoint, or strictly inside
/// (then the distance is the distance to the edge's line).
enum class PointEdgeCase { Vertex0, Vertex1, Line };

/// Where on the triangle (t0, t1, t2) the point closest to p lies: a vertex, the inside of an
/// edge (Edge01 is t0–t1, Edge12 is t1–t2, Edge20 is t2–t0), or the inside of the face (then
/// the distance is the distance to the triangle's plane).
enum class PointTriangleCase { Vertex0, Vertex1, Vertex2, Edge01, Edge12, Edge20, Face };

/// Which features of edges a = (ea0, ea1) and b = (eb0, eb1) hold the closest pair of points:
/// two endpoints (A0B1 is ea0 and eb1), an endpoint and the inside of the other edge (A0EdgeB
/// is ea0 and the inside of b), or the insides of both (then the distance is the distance
/// between the edges' lines).
enum class EdgeEdgeCase { A0B0, A0B1, A1B0, A1B1, A0EdgeB, A1EdgeB, B0EdgeA, B1EdgeA, LineLine };

/// Two directions whose sine squared is below this are treated as collinear: nearly parallel
/// edges and sliver triangles are measured through their boundary (point–edge) sub-cases.
/// The line–line closest-point parameters lose digits like ε_mach/sin²θ (two digits are left
/// here, enough to classify), while the boundary route overestimates the squared distance of
/// parallel-ish edges by at most sin²θ·min(‖ea‖², ‖eb‖²): this threshold balances the two.
inline constexpr double kCollinearSineSquared = 1e-14;

/// The closest feature of the edge: α = (p − e0)·e/‖e‖² with e = e1 − e0; Vertex0 for α ≤ 0
/// (and for a zero-length edge), Vertex1 for α ≥ 1, Line otherwise.
PointEdgeCase point_edge_case(const Eigen::Vector3d& p, const Eigen::Vector3d& e0,
                              const Eigen::Vector3d& e1);

/// The closest feature of the triangle: Face when p projects inside the triangle (for each
/// edge (ti, tj), n·((tj − ti) × (p − ti)) ≥ 0 with n = (t1 − t0) × (t2 − t0)); otherwise
/// the closest point lies on the boundary and the case is that of the nearest of the three
/// edges (point_edge_case). Sliver triangles (sin² of the angle at t0 below
/// kCollinearSineSquared) never give Face. Outside Face, `boundary_distance` (when given)
/// receives the squared distance to the nearest edge, found on the way: the value
/// point_feature_distance gives for the case, to the bit.
PointTriangleCase point_triangle_case(const Eigen::Vector3d& p, const Eigen::Vector3d& t0,
                                      const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                                      double* boundary_distance = nullptr);

/// The closest features of two edges. The distance ‖ea0 + s u − eb0 − t v‖² (u = ea1 − ea0,
/// v = eb1 − eb0) is convex in (s, t): LineLine when its unconstrained minimiser lies strictly
/// inside [0, 1]², otherwise the minimum over the square is on its boundary and the case is
/// that of the nearest of the four endpoint–edge pairs. Near-parallel edges (sin²θ below
/// kCollinearSineSquared, zero-length edges included) always take the boundary route; there
/// `boundary_distance` (when given) receives the squared distance of the nearest pair, as for
/// point_triangle_case.
EdgeEdgeCase edge_edge_case(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                            const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                            double* boundary_distance = nullptr);

}  // namespace psq
