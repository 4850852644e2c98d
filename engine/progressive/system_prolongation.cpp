#include "engine/progressive/system_prolongation.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace psq {
namespace {

/// The rows of shell block [first, first + count) of a flat position vector.
Eigen::Map<const Positions> block_rows(const Eigen::VectorXd& x, int first, int count) {
  return {x.data() + 3 * Eigen::Index(first), count, 3};
}

}  // namespace

ShellProlongation identity_prolongation(const TriMesh& rest) {
  std::vector<SurfaceLocation> locations(rest.vertex_count());
  for (int t = 0; t < rest.triangle_count(); ++t)
    for (int corner = 0; corner < 3; ++corner) {
      SurfaceLocation& location = locations[rest.triangles(t, corner)];
      if (location.triangle >= 0) continue;
      location.triangle = t;
      location.barycentric = Eigen::Vector3d::Unit(corner);
    }
  for (int v = 0; v < rest.vertex_count(); ++v)
    if (locations[v].triangle < 0)
      throw std::invalid_argument(
          fmt::format("identity_prolongation: vertex {} is in no triangle", v));
  return ShellProlongation(rest, std::move(locations), rest.vertices);
}

SystemProlongation::SystemProlongation(std::vector<ShellProlongation> shells,
                                       int collider_vertices)
    : collider_vertices_(collider_vertices) {
  for (ShellProlongation& map : shells) {
    const int coarse = map.coarse_vertex_count();
    const int targets = map.target_count();
    blocks_.push_back({std::move(map), coarse_vertices_, target_vertices_});
    coarse_vertices_ += coarse;
    target_vertices_ += targets;
  }
  shell_coarse_vertices_ = coarse_vertices_;
  shell_target_vertices_ = target_vertices_;
  coarse_vertices_ += collider_vertices;
  target_vertices_ += collider_vertices;
}

void SystemProlongation::copy_colliders(const Eigen::VectorXd& from, int from_first,
                                        Eigen::VectorXd& to, int to_first) const {
  const Eigen::Index count = 3 * Eigen::Index(collider_vertices_);
  to.segment(3 * Eigen::Index(to_first), count) = from.segment(3 * Eigen::Index(from_first), count);
}

Eigen::VectorXd SystemProlongation::apply(const Eigen::VectorXd& coarse) const {
  Eigen::VectorXd out(target_size());
  for (const Block& b : blocks_) {
    const Positions prolonged =
        b.map.apply(block_rows(coarse, b.first_coarse, b.map.coarse_vertex_count()));
    out.segment(3 * Eigen::Index(b.first_target), prolonged.size()) = flat(prolonged);
  }
  copy_colliders(coarse, shell_coarse_vertices_, out, shell_target_vertices_);
  return out;
}

Eigen::VectorXd SystemProlongation::apply_linear(const Eigen::VectorXd& coarse) const {
  Eigen::VectorXd out(target_size());
  for (const Block& b : blocks_) {
    const Eigen::Index rows = 3 * Eigen::Index(b.map.target_count());
    const Eigen::Index cols = 3 * Eigen::Index(b.map.coarse_vertex_count());
    out.segment(3 * Eigen::Index(b.first_target), rows) =
        b.map.linear_part() * coarse.segment(3 * Eigen::Index(b.first_coarse), cols);
  }
  copy_colliders(coarse, shell_coarse_vertices_, out, shell_target_vertices_);
  return out;
}

Eigen::VectorXd SystemProlongation::apply_linear_transpose(const Eigen::VectorXd& g) const {
  Eigen::VectorXd out(coarse_size());
  for (const Block& b : blocks_) {
    const Eigen::Index rows = 3 * Eigen::Index(b.map.target_count());
    const Eigen::Index cols = 3 * Eigen::Index(b.map.coarse_vertex_count());
    out.segment(3 * Eigen::Index(b.first_coarse), cols) =
        b.map.linear_part().transpose() * g.segment(3 * Eigen::Index(b.first_target), rows);
  }
  copy_colliders(g, shell_target_vertices_, out, shell_coarse_vertices_);
  return out;
}

Eigen::VectorXd SystemProlongation::apply_jacobian_transpose(const Eigen::VectorXd& coarse,
                                                             const Eigen::VectorXd& g) const {
  Eigen::VectorXd out(coarse_size());
  for (const Block& b : blocks_) {
    const Eigen::Index rows = 3 * Eigen::Index(b.map.target_count());
    const Eigen::Index cols = 3 * Eigen::Index(b.map.coarse_vertex_count());
    const Positions shell_coarse = block_rows(coarse, b.first_coarse, b.map.coarse_vertex_count());
    out.segment(3 * Eigen::Index(b.first_coarse), cols) = b.map.apply_jacobian_transpose(
        shell_coarse, g.segment(3 * Eigen::Index(b.first_target), rows));
  }
  copy_colliders(g, shell_target_vertices_, out, shell_coarse_vertices_);
  return out;
}

}  // namespace psq
