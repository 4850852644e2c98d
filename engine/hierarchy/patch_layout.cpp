#include "engine/hierarchy/patch_layout.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace psq {

namespace {

/// Barycentric coordinates this far below zero still count as inside (round-off).
constexpr double kInsideTolerance = 1e-12;

Eigen::Vector3d clamped(Eigen::Vector3d b) {
  b = b.cwiseMax(0.0);
  return b / b.sum();
}

/// Closest point of segment (corner a → corner b of a face) to p, as barycentric weights.
LayoutLocation closest_on_edge(const Eigen::Vector2d& pa, const Eigen::Vector2d& pb, int a, int b,
                               const Eigen::Vector2d& p) {
  const Eigen::Vector2d ab = pb - pa;
  const double length2 = ab.squaredNorm();
  const double s = length2 > 0 ? std::clamp((p - pa).dot(ab) / length2, 0.0, 1.0) : 0.0;
  LayoutLocation location;
  location.barycentric[a] = 1 - s;
  location.barycentric[b] = s;
  location.distance = (pa + s * ab - p).norm();
  return location;
}

}  // namespace

std::vector<int> patch_boundary_loop(const Patch& patch) {
  // A directed edge is on the boundary when its reverse belongs to no face.
  std::unordered_map<long long, int> directed;
  const auto key = [](int a, int b) { return (static_cast<long long>(a) << 32) | b; };
  for (const auto& f : patch.faces) {
    for (int k = 0; k < 3; ++k) directed[key(f[k], f[(k + 1) % 3])] = 1;
  }
  std::unordered_map<int, int> next;
  for (const auto& f : patch.faces) {
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      if (directed.count(key(b, a))) continue;
      if (!next.emplace(a, b).second) return {};  // a vertex where the boundary pinches
    }
  }
  if (next.empty()) return {};
  std::vector<int> loop{next.begin()->first};
  while (true) {
    const auto it = next.find(loop.back());
    if (it == next.end()) return {};
    if (it->second == loop.front()) break;
    if (loop.size() >= next.size()) return {};
    loop.push_back(it->second);
  }
  if (loop.size() != next.size()) return {};  // more than one loop
  return loop;
}

std::vector<Eigen::Vector2d> projected_layout(const std::vector<Eigen::Vector3d>& positions,
                                              const Eigen::Vector3d& normal) {
  Eigen::Index axis = 0;
  normal.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d u = normal.cross(Eigen::Vector3d::Unit(axis)).normalized();
  const Eigen::Vector3d v = normal.cross(u);
  std::vector<Eigen::Vector2d> uv;
  uv.reserve(positions.size());
  for (const auto& p : positions) uv.emplace_back(p.dot(u), p.dot(v));
  return uv;
}

bool faces_fit_layout(const std::vector<Eigen::Vector2d>& uv, const Patch& patch,
                      double fraction) {
  for (const auto& f : patch.faces) {
    const double spatial = (patch.positions[f[1]] - patch.positions[f[0]])
                               .cross(patch.positions[f[2]] - patch.positions[f[0]])
                               .norm();
    if (!(signed_double_area(uv[f[0]], uv[f[1]], uv[f[2]]) >= fraction * spatial)) return false;
  }
  return true;
}

std::vector<Eigen::Vector2d> circle_layout(const Patch& patch, const std::vector<int>& loop) {
  std::vector<double> arc(loop.size() + 1, 0.0);
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const int a = loop[k], b = loop[(k + 1) % loop.size()];
    arc[k + 1] = arc[k] + (patch.positions[b] - patch.positions[a]).norm();
  }
  std::vector<Eigen::Vector2d> uv(patch.positions.size(), Eigen::Vector2d::Zero());
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const double angle = 2 * std::numbers::pi * arc[k] / arc.back();
    uv[loop[k]] = Eigen::Vector2d(std::cos(angle), std::sin(angle));
  }
  return uv;
}

bool mean_value_layout(const Patch& patch, const std::vector<bool>& fixed,
                       std::vector<Eigen::Vector2d>& uv) {
  const int n = static_cast<int>(patch.positions.size());
  std::vector<int> unknown(n, -1);
  int count = 0;
  for (int v = 0; v < n; ++v) {
    if (!fixed[v]) unknown[v] = count++;
  }
  if (count == 0) return true;
  Eigen::MatrixXd system = Eigen::MatrixXd::Zero(count, count);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(count, 2);
  const auto add_weight = [&](int i, int j, double w) {
    system(unknown[i], unknown[i]) += w;
    if (unknown[j] >= 0) {
      system(unknown[i], unknown[j]) -= w;
    } else {
      rhs.row(unknown[i]) += w * uv[j].transpose();
    }
  };
  for (const auto& f : patch.faces) {
    for (int k = 0; k < 3; ++k) {
      const int i = f[k], j = f[(k + 1) % 3], l = f[(k + 2) % 3];
      if (unknown[i] < 0) continue;
      const Eigen::Vector3d to_j = patch.positions[j] - patch.positions[i];
      const Eigen::Vector3d to_l = patch.positions[l] - patch.positions[i];
      const double angle = std::atan2(to_j.cross(to_l).norm(), to_j.dot(to_l));
      const double half_tan = std::tan(0.5 * angle);
      add_weight(i, j, half_tan / to_j.norm());
      add_weight(i, l, half_tan / to_l.norm());
    }
  }
  if (!system.allFinite() || !rhs.allFinite()) return false;
  const Eigen::MatrixXd solution = system.partialPivLu().solve(rhs);
  if (!solution.allFinite()) return false;
  for (int v = 0; v < n; ++v) {
    if (unknown[v] >= 0) uv[v] = solution.row(unknown[v]).transpose();
  }
  return true;
}

double signed_double_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a;
  return ab.x() * ac.y() - ab.y() * ac.x();
}

LayoutLocation locate_in_layout(const std::vector<Eigen::Vector2d>& uv,
                                const std::vector<std::array<int, 3>>& faces,
                                const Eigen::Vector2d& point) {
  LayoutLocation best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const Eigen::Vector2d& p0 = uv[faces[f][0]];
    const Eigen::Vector2d& p1 = uv[faces[f][1]];
    const Eigen::Vector2d& p2 = uv[faces[f][2]];
    const double area = signed_double_area(p0, p1, p2);
    const Eigen::Vector3d b(signed_double_area(point, p1, p2) / area,
                            signed_double_area(p0, point, p2) / area,
                            signed_double_area(p0, p1, point) / area);
    if (b.minCoeff() >= -kInsideTolerance) return {f, clamped(b), 0.0};
    const Eigen::Vector2d corners[3] = {p0, p1, p2};
    for (int k = 0; k < 3; ++k) {
      LayoutLocation candidate =
          closest_on_edge(corners[k], corners[(k + 1) % 3], k, (k + 1) % 3, point);
      if (candidate.distance < best.distance) {
        candidate.face = f;
        best = candidate;
      }
    }
  }
  return best;
}

}  // namespace psq
