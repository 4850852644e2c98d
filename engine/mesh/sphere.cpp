#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include "engine/mesh/generators.hpp"
#include "engine/mesh/mesh_checks.hpp"

namespace psq {
namespace {

using Vector3 = Eigen::Vector3d;

/// The regular icosahedron (0, ±1, ±φ) and its cyclic permutations: 12 corners, and the 20
/// faces found as the mutually adjacent corner triples (edge length 2), wound outward.
struct Icosahedron {
  std::array<Vector3, 12> corners;
  std::vector<std::array<int, 3>> faces;
};

Icosahedron make_icosahedron() {
  Icosahedron ico;
  const double phi = std::numbers::phi;
  int n = 0;
  for (double a : {-1.0, 1.0})
    for (double b : {-phi, phi}) {
      ico.corners[n++] = Vector3(0, a, b);
      ico.corners[n++] = Vector3(a, b, 0);
      ico.corners[n++] = Vector3(b, 0, a);
    }
  const auto adjacent = [&](int i, int j) {
    return std::abs((ico.corners[i] - ico.corners[j]).norm() - 2.0) < 1e-9;
  };
  for (int i = 0; i < 12; ++i)
    for (int j = i + 1; j < 12; ++j)
      for (int k = j + 1; k < 12; ++k) {
        if (!(adjacent(i, j) && adjacent(j, k) && adjacent(i, k))) continue;
        const Vector3& a = ico.corners[i];
        const Vector3 normal = (ico.corners[j] - a).cross(ico.corners[k] - a);
        if (normal.dot(a) > 0)
          ico.faces.push_back({i, j, k});
        else
          ico.faces.push_back({i, k, j});
      }
  return ico;
}

/// A subdivision point identified by its integer weights on icosahedron corners, sorted by
/// corner, so that a point on a shared edge gets the same key from both faces.
using PointKey = std::array<std::pair<int, int>, 3>;

PointKey point_key(const std::array<int, 3>& face, const std::array<int, 3>& weights) {
  PointKey key;
  for (int c = 0; c < 3; ++c)
    key[c] = weights[c] == 0 ? std::pair{-1, 0} : std::pair{face[c], weights[c]};
  std::sort(key.begin(), key.end());
  return key;
}

void check_sphere(const SphereGenerator& spec) {
  require_positive("sphere", "radius", spec.radius);
  require_positive("sphere", "edge_length", spec.edge_length);
  require_edge_below("sphere", spec.edge_length, "diameter", 2 * spec.radius);
}

}  // namespace

TriMesh make_sphere(const SphereGenerator& spec) {
  check_sphere(spec);
  const Icosahedron ico = make_icosahedron();
  // Frequency k gives 20k² triangles; pick k so that their mean area 4πr²/(20k²) is that of
  // an equilateral triangle of side edge_length, √3/4·edge². (Splitting the corner-to-corner
  // arc into edges of edge_length instead gives edges about 9% too long: projection stretches
  // the middle of each face.)
  const double equal_area_frequency =
      spec.radius / spec.edge_length * std::sqrt(4 * std::numbers::pi / (5 * std::numbers::sqrt3));
  const int k = std::max(1, static_cast<int>(std::lround(equal_area_frequency)));

  std::map<PointKey, int> vertex_of;
  std::vector<Vector3> points;
  std::vector<std::array<int, 3>> triangles;
  for (const auto& face : ico.faces) {
    // Grid point (i, j) of the face is A + i/k (B − A) + j/k (C − A), projected on the sphere.
    const auto vertex = [&](int i, int j) {
      const std::array<int, 3> weights{k - i - j, i, j};
      const auto [it, inserted] = vertex_of.try_emplace(point_key(face, weights), 0);
      if (inserted) {
        it->second = static_cast<int>(points.size());
        Vector3 p = Vector3::Zero();
        for (int c = 0; c < 3; ++c) p += weights[c] * ico.corners[face[c]];
        points.push_back(spec.radius * p.normalized());
      }
      return it->second;
    };
    for (int j = 0; j < k; ++j)
      for (int i = 0; i + j < k; ++i) {
        triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)});
        if (i + j + 2 <= k)
          triangles.push_back({vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
      }
  }
  TriMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v)
    mesh.vertices.row(static_cast<Eigen::Index>(v)) = points[v];
  mesh.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f)
    mesh.triangles.row(static_cast<Eigen::Index>(f)) << triangles[f][0], triangles[f][1],
        triangles[f][2];
  return mesh;
}

}  // namespace psq
