#include "engine/progressive/relaxation_patch.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <span>

namespace psq {
namespace {

Eigen::Vector3d row_of(const Positions& p, int v) { return p.row(v).transpose(); }

Eigen::AlignedBox3d box_of_vertices(const Positions& x, std::span<const int> vertices) {
  Eigen::AlignedBox3d box;
  for (int v : vertices) box.extend(row_of(x, v));
  return box;
}

Eigen::AlignedBox3d grown(Eigen::AlignedBox3d box, double by) {
  box.min().array() -= by;
  box.max().array() += by;
  return box;
}

}  // namespace

double Confinement::max_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) const {
  double step = 1.0;
  for (std::size_t v = 0; v < box_of.size(); ++v) {
    if (box_of[v] < 0) continue;
    const Eigen::AlignedBox3d& box = boxes[box_of[v]];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index i = 3 * static_cast<Eigen::Index>(v) + k;
      if (dx[i] > 0.0) step = std::min(step, std::max(0.0, (box.max()[k] - x[i]) / dx[i]));
      if (dx[i] < 0.0) step = std::min(step, std::max(0.0, (box.min()[k] - x[i]) / dx[i]));
    }
  }
  return step;
}

RelaxationPatch relaxation_patch(const ContactSurface& surface, const Positions& x,
                                 const Positions& target, const std::vector<bool>& freed,
                                 double reach) {
  const int n = static_cast<int>(x.rows());
  std::vector<std::vector<int>> primitives;  // triangles, then edges
  primitives.reserve(static_cast<std::size_t>(surface.triangles.rows()) + surface.edges.size());
  for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t)
    primitives.push_back({surface.triangles(t, 0), surface.triangles(t, 1), surface.triangles(t, 2)});
  for (const auto& e : surface.edges) primitives.push_back({e[0], e[1]});

  // Clusters: freed vertices joined through the primitives they share.
  std::vector<int> cluster_root(n);
  std::iota(cluster_root.begin(), cluster_root.end(), 0);
  const auto root = [&](int v) {
    while (cluster_root[v] != v) v = cluster_root[v] = cluster_root[cluster_root[v]];
    return v;
  };
  const auto first_freed = [&](const std::vector<int>& primitive) {
    for (int v : primitive)
      if (freed[v]) return v;
    return -1;
  };
  for (const auto& primitive : primitives) {
    const int a = first_freed(primitive);
    if (a < 0) continue;
    for (int v : primitive)
      if (freed[v]) cluster_root[root(v)] = root(a);
  }
  std::vector<int> cluster(n, -1);
  std::vector<Eigen::AlignedBox3d> boxes;
  std::vector<double> farthest_target;
  for (int v = 0; v < n; ++v) {
    if (!freed[v]) continue;
    const int r = root(v);
    if (cluster[r] < 0) {
      cluster[r] = static_cast<int>(boxes.size());
      boxes.emplace_back();
      farthest_target.push_back(0.0);
    }
    const int c = cluster[v] = cluster[r];
    boxes[c].extend(row_of(x, v));
    boxes[c].extend(row_of(target, v));
    farthest_target[c] = std::max(farthest_target[c], (x.row(v) - target.row(v)).norm());
  }
  for (const auto& primitive : primitives) {
    const int a = first_freed(primitive);
    if (a >= 0) boxes[cluster[a]].extend(box_of_vertices(x, primitive));
  }
  for (std::size_t c = 0; c < boxes.size(); ++c) boxes[c] = grown(boxes[c], farthest_target[c] + reach);

  // The primitives within the reach of a cluster's box, and their vertices in their order.
  std::vector<bool> kept(primitives.size(), false), in_patch(n, false);
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    const Eigen::AlignedBox3d box = grown(box_of_vertices(x, primitives[i]), reach);
    kept[i] = std::any_of(boxes.begin(), boxes.end(),
                          [&](const Eigen::AlignedBox3d& b) { return b.intersects(box); });
    if (kept[i])
      for (int v : primitives[i]) in_patch[v] = true;
  }
  RelaxationPatch patch;
  std::vector<int> patch_index(n, -1);
  for (int v = 0; v < n; ++v) {
    if (!in_patch[v]) continue;
    patch_index[v] = static_cast<int>(patch.vertex.size());
    patch.vertex.push_back(v);
  }
  const auto m = static_cast<Eigen::Index>(patch.vertex.size());
  patch.surface.may_touch = surface.may_touch;
  patch.surface.rest.resize(m, 3);
  patch.confinement.boxes = std::move(boxes);
  for (Eigen::Index k = 0; k < m; ++k) {
    const int v = patch.vertex[k];
    patch.surface.rest.row(k) = surface.rest.row(v);
    patch.surface.vertex_body.push_back(surface.vertex_body[v]);
    patch.freed.push_back(freed[v]);
    patch.surface.held.push_back(!freed[v]);
    patch.confinement.box_of.push_back(cluster[v]);
  }
  const auto triangle_count = static_cast<std::size_t>(surface.triangles.rows());
  std::vector<std::array<int, 3>> triangles;
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    if (!kept[i]) continue;
    const auto& p = primitives[i];
    if (i < triangle_count)
      triangles.push_back({patch_index[p[0]], patch_index[p[1]], patch_index[p[2]]});
    else
      patch.surface.edges.push_back({patch_index[p[0]], patch_index[p[1]]});
  }
  patch.surface.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) patch.surface.triangles(static_cast<Eigen::Index>(t), k) = triangles[t][k];
  return patch;
}

}  // namespace psq
