#include "progressive/nested_grids.hpp"

#include <Eigen/LU>
#include <numbers>
#include <stdexcept>

#include "engine/mesh/mesh_io.hpp"

namespace psq::test {
namespace {

int columns(const GridSpec& spec) { return spec.closed_u ? spec.nu : spec.nu + 1; }
int vertex_id(const GridSpec& spec, int i, int j) {
  return j * columns(spec) + (spec.closed_u ? i % spec.nu : i);
}

/// Triangles as (i, j) parameter corners, unwrapped (i may equal nu on a closed grid).
std::vector<std::array<Eigen::Vector2i, 3>> cell_triangles(const GridSpec& spec) {
  std::vector<std::array<Eigen::Vector2i, 3>> out;
  for (int j = 0; j < spec.nv; ++j)
    for (int i = 0; i < spec.nu; ++i) {
      const Eigen::Vector2i a(i, j), b(i + 1, j), c(i + 1, j + 1), d(i, j + 1);
      if ((i + j) % 2 == 0) {
        out.push_back({a, b, c});
        out.push_back({a, c, d});
      } else {
        out.push_back({a, b, d});
        out.push_back({b, c, d});
      }
    }
  return out;
}

Eigen::Vector2d parameter(const GridSpec& spec, const Eigen::Vector2i& ij) {
  return {double(ij.x()) / spec.nu, double(ij.y()) / spec.nv};
}

/// Barycentric coordinates of p in the 2D triangle (a, b, c).
Eigen::Vector3d barycentric(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  Eigen::Matrix2d m;
  m << b - a, c - a;
  const Eigen::Vector2d st = m.inverse() * (p - a);
  return {1.0 - st.x() - st.y(), st.x(), st.y()};
}

}  // namespace

TriMesh grid_mesh(const GridSpec& spec) {
  TriMesh mesh;
  mesh.vertices.resize(columns(spec) * (spec.nv + 1), 3);
  for (int j = 0; j <= spec.nv; ++j)
    for (int i = 0; i < columns(spec); ++i) {
      const Eigen::Vector2d uv = parameter(spec, {i, j});
      mesh.vertices.row(vertex_id(spec, i, j)) = spec.shape(uv.x(), uv.y()).transpose();
    }
  const auto triangles = cell_triangles(spec);
  mesh.triangles.resize(static_cast<int>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      mesh.triangles(int(t), k) = vertex_id(spec, triangles[t][k].x(), triangles[t][k].y());
  return mesh;
}

GridSpec refined(const GridSpec& coarse) {
  GridSpec fine = coarse;
  fine.nu *= 2;
  fine.nv *= 2;
  return fine;
}

MeshHierarchy nested_hierarchy(const GridSpec& coarse, const std::vector<int>& fine_pin_group) {
  const GridSpec fine = refined(coarse);
  MeshHierarchy hierarchy;
  hierarchy.levels.resize(2);
  HierarchyLevel& low = hierarchy.levels[0];
  HierarchyLevel& high = hierarchy.levels[1];
  low.rest = grid_mesh(coarse);
  high.rest = grid_mesh(fine);
  if (static_cast<int>(fine_pin_group.size()) != high.rest.vertex_count())
    throw std::invalid_argument("nested_hierarchy: one pin group per fine vertex");
  high.pin_group = fine_pin_group;
  low.pin_group.assign(low.rest.vertex_count(), kFreeVertex);
  for (int j = 0; j <= coarse.nv; ++j)
    for (int i = 0; i < columns(coarse); ++i)
      low.pin_group[vertex_id(coarse, i, j)] = fine_pin_group[vertex_id(fine, 2 * i, 2 * j)];

  const auto triangles = cell_triangles(coarse);
  low.finest.resize(high.rest.vertex_count());
  for (int j = 0; j <= fine.nv; ++j)
    for (int i = 0; i < columns(fine); ++i) {
      const Eigen::Vector2d p = parameter(fine, {i, j});
      double best = -1e300;
      SurfaceLocation& location = low.finest[vertex_id(fine, i, j)];
      for (std::size_t t = 0; t < triangles.size(); ++t) {
        const auto& c = triangles[t];
        const Eigen::Vector3d b = barycentric(p, parameter(coarse, c[0]), parameter(coarse, c[1]),
                                              parameter(coarse, c[2]));
        if (b.minCoeff() > best) {
          best = b.minCoeff();
          location = {int(t), b.cwiseMax(0.0) / b.cwiseMax(0.0).sum()};
        }
      }
    }
  low.next_finer = low.finest;
  high.finest.resize(high.rest.vertex_count());
  for (int t = 0; t < high.rest.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      high.finest[high.rest.triangles(t, k)] = {t, Eigen::Vector3d::Unit(k)};
  return hierarchy;
}

void use_mesh_file(Scene& scene, const TriMesh& mesh, const std::filesystem::path& dir,
                   const std::string& name) {
  const auto path = dir / (name + ".obj");
  write_mesh(path, mesh);
  scene.shells.at(0).mesh = MeshSource{};
  scene.shells[0].mesh.kind = MeshSource::Kind::File;
  scene.shells[0].mesh.file = path;
}

Shape sheet_shape(double width, double height) {
  return [=](double u, double v) {
    return Eigen::Vector3d(-0.5 * width + width * u, -0.5 * height + height * v, 0.0);
  };
}

Shape cylinder_shape(double radius, double height) {
  return [=](double u, double v) {
    const double angle = 2 * std::numbers::pi * u;
    return Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), height * v);
  };
}

}  // namespace psq::test
