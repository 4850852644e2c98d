#include "engine/scene/vertex_selection.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "engine/core/error.hpp"

namespace psq {
namespace {

std::string format_point(const Eigen::Vector3d& p) {
  return fmt::format("[{:g}, {:g}, {:g}]", p.x(), p.y(), p.z());
}

std::string describe(const VertexSelector& selector) {
  switch (selector.kind) {
    case VertexSelector::Kind::Box:
      return fmt::format("box {}..{}", format_point(selector.box_min),
                         format_point(selector.box_max));
    case VertexSelector::Kind::BoundaryLoop:
      return fmt::format("boundary_loop {}", selector.boundary_loop);
    case VertexSelector::Kind::List:
      return fmt::format("vertices [{}]", fmt::join(selector.indices, ", "));
  }
  return {};
}

std::string mesh_extent(const TriMesh& mesh) {
  if (mesh.vertex_count() == 0) return "the mesh has no vertices";
  const Eigen::Vector3d lo = mesh.vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = mesh.vertices.colwise().maxCoeff().transpose();
  return fmt::format("the mesh ({} vertices) spans {}..{}", mesh.vertex_count(), format_point(lo),
                     format_point(hi));
}

/// Throws an InputError located at the selector, e.g.
/// "scene.toml:14: pin 'left' of shell 'sheet' selects no vertex; box [..]..[..]; the mesh ...".
[[noreturn]] void fail(const VertexSelector& selector, const TriMesh& mesh, const std::string& what,
                       const std::string& problem) {
  const std::string message =
      fmt::format("{} {}; {}; {}", what, problem, describe(selector), mesh_extent(mesh));
  if (selector.source_file.empty()) throw InputError(message);
  throw InputError(located_message(selector.source_file.string(), selector.source_line, message));
}

std::vector<int> select_in_box(const VertexSelector& selector, const TriMesh& mesh) {
  const double slack = 1e-9 * bounding_box_diagonal(mesh.vertices);
  const Eigen::Array3d lo = selector.box_min.array() - slack;
  const Eigen::Array3d hi = selector.box_max.array() + slack;
  std::vector<int> selected;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Array3d p = mesh.vertices.row(v).transpose().array();
    if ((p >= lo).all() && (p <= hi).all()) selected.push_back(v);
  }
  return selected;
}

}  // namespace

std::vector<std::vector<int>> boundary_loops_by_size(const MeshTopology& topology) {
  std::vector<std::vector<int>> loops = topology.boundary_loops;
  std::stable_sort(loops.begin(), loops.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return loops;
}

std::vector<int> select_vertices(const VertexSelector& selector, const TriMesh& mesh,
                                 const MeshTopology& topology, const std::string& what) {
  std::vector<int> selected;
  switch (selector.kind) {
    case VertexSelector::Kind::Box:
      selected = select_in_box(selector, mesh);
      break;
    case VertexSelector::Kind::BoundaryLoop: {
      const auto loops = boundary_loops_by_size(topology);
      if (selector.boundary_loop < 0 || selector.boundary_loop >= static_cast<int>(loops.size()))
        fail(selector, mesh, what,
             fmt::format("selects a boundary loop that does not exist (the mesh has {} boundary "
                         "loop{}, numbered from 0, largest first)",
                         loops.size(), loops.size() == 1 ? "" : "s"));
      selected = loops[selector.boundary_loop];
      break;
    }
    case VertexSelector::Kind::List:
      for (int v : selector.indices)
        if (v < 0 || v >= mesh.vertex_count())
          fail(selector, mesh, what,
               fmt::format("selects vertex {}, which is out of range (valid: 0..{})", v,
                           mesh.vertex_count() - 1));
      selected = selector.indices;
      break;
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  if (selected.empty()) fail(selector, mesh, what, "selects no vertex");
  return selected;
}

}  // namespace psq
