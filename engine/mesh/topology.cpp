#include "engine/mesh/topology.hpp"

#include <algorithm>
#include <cstdint>
#include <fmt/format.h>
#include <unordered_map>

#include "engine/core/error.hpp"

namespace psq {

double bounding_box_diagonal(const Positions& p) {
  if (p.rows() == 0) return 0.0;
  return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
}

namespace {

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

std::vector<std::vector<int>> trace_boundary_loops(const TriMesh& mesh, const MeshTopology& topo) {
  // Each boundary edge, directed as in its only triangle, points to the next boundary vertex.
  std::unordered_map<int, int> next;
  for (std::size_t e = 0; e < topo.edges.size(); ++e) {
    if (topo.edge_faces[e][1] >= 0) continue;
    const int f = topo.edge_faces[e][0];
    for (int k = 0; k < 3; ++k) {
      if (topo.face_edges[f][k] != static_cast<int>(e)) continue;
      next[mesh.triangles(f, (k + 1) % 3)] = mesh.triangles(f, (k + 2) % 3);
    }
  }
  std::vector<std::vector<int>> loops;
  std::vector<int> starts;
  for (const auto& [from, to] : next) starts.push_back(from);
  std::sort(starts.begin(), starts.end());
  std::unordered_map<int, bool> visited;
  for (int start : starts) {
    if (visited[start]) continue;
    std::vector<int> loop;
    int v = start;
    while (!visited[v]) {
      visited[v] = true;
      loop.push_back(v);
      auto it = next.find(v);
      if (it == next.end()) break;
      v = it->second;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace

MeshTopology MeshTopology::build(const TriMesh& mesh, const std::string& source) {
  MeshTopology topo;
  const int nf = mesh.triangle_count();
  topo.face_edges.resize(nf);
  topo.vertex_neighbors.resize(mesh.vertex_count());
  std::unordered_map<std::uint64_t, int> edge_index;
  edge_index.reserve(static_cast<std::size_t>(nf) * 2);
  // Directed owner of each edge's first occurrence, to detect inconsistent orientation.
  std::vector<int> first_from;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(f, (k + 1) % 3);
      const int b = mesh.triangles(f, (k + 2) % 3);
      const auto [it, inserted] = edge_index.try_emplace(edge_key(a, b), static_cast<int>(topo.edges.size()));
      const int e = it->second;
      if (inserted) {
        topo.edges.push_back({std::min(a, b), std::max(a, b)});
        topo.edge_faces.push_back({f, -1});
        first_from.push_back(a);
      } else if (topo.edge_faces[e][1] >= 0) {
        throw InputError(fmt::format("{}: edge ({}, {}) is shared by more than two triangles "
                                     "(non-manifold), e.g. triangles {}, {} and {}",
                                     source, a, b, topo.edge_faces[e][0], topo.edge_faces[e][1], f));
      } else if (first_from[e] == a) {
        throw InputError(fmt::format("{}: triangles {} and {} orient their shared edge ({}, {}) the "
                                     "same way; the surface must be consistently oriented",
                                     source, topo.edge_faces[e][0], f, a, b));
      } else {
        topo.edge_faces[e][1] = f;
      }
      topo.face_edges[f][k] = e;
    }
  }
  for (std::size_t e = 0; e < topo.edges.size(); ++e) {
    const auto [a, b] = topo.edges[e];
    topo.vertex_neighbors[a].push_back(b);
    topo.vertex_neighbors[b].push_back(a);
    if (topo.edge_faces[e][1] < 0) continue;
    const int f0 = topo.edge_faces[e][0];
    const int f1 = topo.edge_faces[e][1];
    int k0 = 0;
    while (topo.face_edges[f0][k0] != static_cast<int>(e)) ++k0;
    int k1 = 0;
    while (topo.face_edges[f1][k1] != static_cast<int>(e)) ++k1;
    Hinge h{};
    h.v0 = mesh.triangles(f0, (k0 + 1) % 3);
    h.v1 = mesh.triangles(f0, (k0 + 2) % 3);
    h.opposite0 = mesh.triangles(f0, k0);
    h.opposite1 = mesh.triangles(f1, k1);
    h.face0 = f0;
    h.face1 = f1;
    topo.hinges.push_back(h);
  }
  for (auto& ring : topo.vertex_neighbors) std::sort(ring.begin(), ring.end());
  topo.boundary_loops = trace_boundary_loops(mesh, topo);
  return topo;
}

}  // namespace psq
