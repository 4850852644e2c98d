#include "engine/hierarchy/shell_prolongation.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "engine/core/error.hpp"

namespace psq {

namespace {

constexpr const char* kSource = "shell prolongation";
/// Largest violation of b ≥ 0 and Σb = 1 accepted from a location (round-off of the map).
constexpr double kBarycentricTolerance = 1e-9;

void check_location(const SurfaceLocation& location, int target, int triangle_count) {
  const auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}: target {}: {}", kSource, target, what));
  };
  if (location.triangle < 0 || location.triangle >= triangle_count) {
    fail(fmt::format("triangle {} is not in [0, {})", location.triangle, triangle_count));
  }
  const Eigen::Vector3d& b = location.barycentric;
  if (!b.allFinite() || b.minCoeff() < -kBarycentricTolerance ||
      std::abs(b.sum() - 1) > kBarycentricTolerance) {
    fail(fmt::format("barycentric coordinates ({}, {}, {}) are not a convex combination", b.x(),
                     b.y(), b.z()));
  }
}

/// Compressed lists: entries of group g are entries[start[g] .. start[g+1]).
void build_groups(int group_count, const std::vector<int>& group_of_entry, std::vector<int>& start,
                  std::vector<int>& entries) {
  start.assign(group_count + 1, 0);
  for (const int g : group_of_entry) ++start[g + 1];
  for (int g = 0; g < group_count; ++g) start[g + 1] += start[g];
  entries.resize(group_of_entry.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t e = 0; e < group_of_entry.size(); ++e) {
    entries[fill[group_of_entry[e]]++] = static_cast<int>(e);
  }
}

}  // namespace

ShellProlongation::ShellProlongation(const TriMesh& coarse_rest,
                                     std::vector<SurfaceLocation> locations,
                                     const Positions& target_rest)
    : coarse_vertex_count_(coarse_rest.vertex_count()),
      triangles_(coarse_rest.triangles),
      locations_(std::move(locations)) {
  const int target_count = static_cast<int>(locations_.size());
  if (target_rest.rows() != target_count) {
    throw InputError(fmt::format("{}: {} locations but {} target rest positions", kSource,
                                 target_count, target_rest.rows()));
  }
  const int triangle_count = coarse_rest.triangle_count();
  slot_of_triangle_.assign(triangle_count, -1);
  for (int i = 0; i < target_count; ++i) {
    check_location(locations_[i], i, triangle_count);
    slot_of_triangle_[locations_[i].triangle] = 0;
  }
  for (int t = 0; t < triangle_count; ++t) {
    if (slot_of_triangle_[t] < 0) continue;
    slot_of_triangle_[t] = static_cast<int>(used_triangles_.size());
    used_triangles_.push_back(t);
  }

  const int slot_count = static_cast<int>(used_triangles_.size());
  std::vector<RestTriangleFrame> rest_frames(slot_count);
  b_inverse_.resize(slot_count);
  for (int s = 0; s < slot_count; ++s) {
    const auto tri = triangles_.row(used_triangles_[s]);
    if (!rest_triangle_frame(coarse_rest.vertices.row(tri(0)), coarse_rest.vertices.row(tri(1)),
                             coarse_rest.vertices.row(tri(2)), rest_frames[s])) {
      throw InputError(fmt::format("{}: coarse rest triangle {} has zero area", kSource,
                                   used_triangles_[s]));
    }
    b_inverse_[s] = rest_frames[s].b_inverse;
  }

  normal_offsets_.resize(target_count);
  in_plane_offsets_.resize(target_count);
  std::vector<int> slot_of_target(target_count);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(9 * static_cast<std::size_t>(target_count));
  for (int i = 0; i < target_count; ++i) {
    const SurfaceLocation& location = locations_[i];
    const auto tri = triangles_.row(location.triangle);
    Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      anchor += location.barycentric[k] * coarse_rest.vertices.row(tri(k)).transpose();
      for (int c = 0; c < 3; ++c) {
        entries.emplace_back(3 * i + c, 3 * tri(k) + c, location.barycentric[k]);
      }
    }
    const int slot = slot_of_triangle_[location.triangle];
    const RestTriangleFrame& frame = rest_frames[slot];
    const Eigen::Vector3d d = target_rest.row(i).transpose() - anchor;
    normal_offsets_[i] = frame.normal.dot(d);
    in_plane_offsets_[i] = Eigen::Vector2d(frame.e1.dot(d), frame.e2.dot(d));
    slot_of_target[i] = slot;
  }
  linear_part_.resize(3 * target_count, 3 * coarse_vertex_count_);
  linear_part_.setFromTriplets(entries.begin(), entries.end());
  build_groups(slot_count, slot_of_target, target_start_, targets_);

  std::vector<int> vertex_of_corner(3 * static_cast<std::size_t>(slot_count));
  for (int s = 0; s < slot_count; ++s) {
    for (int k = 0; k < 3; ++k) vertex_of_corner[3 * s + k] = triangles_(used_triangles_[s], k);
  }
  build_groups(coarse_vertex_count_, vertex_of_corner, corner_start_, corners_);
}

int ShellProlongation::target_count() const { return static_cast<int>(locations_.size()); }

int ShellProlongation::coarse_vertex_count() const { return coarse_vertex_count_; }

const Eigen::SparseMatrix<double>& ShellProlongation::linear_part() const { return linear_part_; }

void ShellProlongation::check_coarse(const Positions& coarse) const {
  if (coarse.rows() != coarse_vertex_count_) {
    throw InputError(fmt::format("{}: {} coarse positions given, the coarse level has {}",
                                 kSource, coarse.rows(), coarse_vertex_count_));
  }
  if (!coarse.allFinite()) {
    throw NumericalError(fmt::format("{}: non-finite coarse position", kSource));
  }
}

std::vector<DeformedTriangleFrame> ShellProlongation::deformed_frames(
    const Positions& coarse) const {
  check_coarse(coarse);
  std::vector<DeformedTriangleFrame> frames(used_triangles_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, frames.size(), 256), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      const auto tri = triangles_.row(used_triangles_[s]);
      frames[s] = deformed_triangle_frame(coarse.row(tri(0)), coarse.row(tri(1)),
                                          coarse.row(tri(2)), b_inverse_[s]);
    }
  });
  return frames;
}

Positions ShellProlongation::offsets(const Positions& coarse) const {
  const std::vector<DeformedTriangleFrame> frames = deformed_frames(coarse);
  Positions result(target_count(), 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, target_count(), 1024), [&](const auto& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      const DeformedTriangleFrame& frame = frames[slot_of_triangle_[locations_[i].triangle]];
      result.row(i) = shell_offset(frame, normal_offsets_[i], in_plane_offsets_[i]).transpose();
    }
  });
  return result;
}

Positions ShellProlongation::apply(const Positions& coarse) const {
  Positions result = offsets(coarse);
  flat(result) += linear_part_ * flat(coarse);
  return result;
}

Eigen::VectorXd ShellProlongation::apply_jacobian_transpose(const Positions& coarse,
                                                            const Eigen::VectorXd& g) const {
  if (g.size() != 3 * static_cast<Eigen::Index>(target_count())) {
    throw InputError(fmt::format("{}: gradient of size {} for {} targets", kSource, g.size(),
                                 target_count()));
  }
  const std::vector<DeformedTriangleFrame> frames = deformed_frames(coarse);
  // Per triangle, the targets enter the chain rule only through three sums (see
  // offset_gradient), so each triangle's 3×3 vertex gradient costs one small closed form.
  std::vector<Eigen::Matrix3d> triangle_gradients(frames.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, frames.size(), 256), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      Eigen::Vector3d q = Eigen::Vector3d::Zero();
      Matrix32d k = Matrix32d::Zero();
      Eigen::Matrix3d linear = Eigen::Matrix3d::Zero();  // column c: Σ_i b_ic g_i
      for (int e = target_start_[s]; e < target_start_[s + 1]; ++e) {
        const int i = targets_[e];
        const Eigen::Vector3d gi = g.segment<3>(3 * i);
        q += normal_offsets_[i] * gi;
        k += gi * in_plane_offsets_[i].transpose();
        linear += gi * locations_[i].barycentric.transpose();
      }
      triangle_gradients[s] = offset_gradient(frames[s], b_inverse_[s], q, k) + linear;
    }
  });
  Eigen::VectorXd result(3 * static_cast<Eigen::Index>(coarse_vertex_count_));
  tbb::parallel_for(tbb::blocked_range<int>(0, coarse_vertex_count_, 1024), [&](const auto& r) {
    for (int v = r.begin(); v != r.end(); ++v) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int e = corner_start_[v]; e < corner_start_[v + 1]; ++e) {
        sum += triangle_gradients[corners_[e] / 3].col(corners_[e] % 3);
      }
      result.segment<3>(3 * v) = sum;
    }
  });
  return result;
}

namespace {

void check_level(const MeshHierarchy& hierarchy, int level, int highest, const char* what) {
  if (level < 0 || level > highest) {
    throw InputError(fmt::format("{}: level {} is not in [0, {}] for a hierarchy of {} levels",
                                 what, level, highest, hierarchy.level_count()));
  }
}

}  // namespace

ShellProlongation direct_prolongation(const MeshHierarchy& hierarchy, int level) {
  check_level(hierarchy, level, hierarchy.level_count() - 1, "direct prolongation");
  const HierarchyLevel& coarse = hierarchy.levels[level];
  return {coarse.rest, coarse.finest, hierarchy.finest().rest.vertices};
}

ShellProlongation level_prolongation(const MeshHierarchy& hierarchy, int level) {
  check_level(hierarchy, level, hierarchy.level_count() - 2, "level prolongation");
  const HierarchyLevel& coarse = hierarchy.levels[level];
  return {coarse.rest, coarse.next_finer, hierarchy.levels[level + 1].rest.vertices};
}

}  // namespace psq
