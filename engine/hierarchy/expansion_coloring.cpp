#include "engine/hierarchy/expansion_coloring.hpp"

#include <algorithm>

namespace psq {

std::vector<int> color_expansions(const Triangles& finer_triangles, const std::vector<int>& parent,
                                  int coarse_vertex_count) {
  std::vector<std::vector<int>> conflicts(coarse_vertex_count);
  for (int t = 0; t < finer_triangles.rows(); ++t) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        const int pa = parent[finer_triangles(t, a)], pb = parent[finer_triangles(t, b)];
        if (pa != pb) conflicts[pa].push_back(pb);
      }
    }
  }
  std::vector<int> color(coarse_vertex_count, -1);
  std::vector<char> taken;
  for (int v = 0; v < coarse_vertex_count; ++v) {
    taken.assign(conflicts[v].size() + 1, 0);
    for (const int w : conflicts[v]) {
      if (color[w] >= 0 && color[w] < static_cast<int>(taken.size())) taken[color[w]] = 1;
    }
    color[v] = static_cast<int>(std::find(taken.begin(), taken.end(), 0) - taken.begin());
  }
  return color;
}

}  // namespace psq
