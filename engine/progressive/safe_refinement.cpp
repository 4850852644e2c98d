#include "engine/progressive/safe_refinement.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "engine/contact/additive_ccd.hpp"
#include "engine/contact/broad_phase.hpp"
#include "engine/contact/contact_potential.hpp"
#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/progressive/target_relaxation.hpp"
#include "engine/sim/contact_term.hpp"

namespace psq {
namespace {

/// The first perturbation moves a cluster's farthest child by g/kPerturbationDivisor: an order
/// of magnitude below the gap (§4.4.2), so that only the patch itself can intersect.
constexpr double kPerturbationDivisor = 10.0;
/// The smallest perturbation, relative to the bounding-box diagonal: IPC can leave gaps far below
/// d̂ in tight contact, and a perturbation below about 1e-13 of the coordinates is lost to
/// rounding.
constexpr double kPerturbationFloor = 1e-7;
/// Layouts tried per cluster (the anchors, then shrunk: the anchors, the targets, the fitted rest
/// layout and random rotations of it) before the cluster is expanded one vertex at a time.
constexpr int kClusterLayoutTries = 9;
/// The smallest distance between elements of a shrunk layout, relative to its size: the rest
/// layout, a piece of a good mesh, keeps about its edge ratio.
constexpr double kSmallestShrunkGap = 1e-2;
/// Directions tried per vertex when a cluster is expanded one vertex at a time: first about
/// its anchor's offset and its sector, then spread evenly over the sphere.
constexpr int kBiasedDirectionTries = 64;
constexpr int kVertexDirectionTries = 512;
/// ACCD ratio bounds (§4.4.2): pairs closer than g keep 99.9 % of their gap, others 10 %.
constexpr double kCloseRatioBound = 0.999;
constexpr double kFarRatioBound = 0.1;
/// ACCD iterations per pair and round of an advance. A capped query stops its pair where it got
/// (safe, only shorter): with r = 0.999 a closing pair may take thousands of iterations to its
/// bound, and the advance needs no more than a safe fraction.
constexpr int kAdvanceCcdIterations = 200;
/// Additive CCD rounds per advance; each round stops at least one pair's vertices, so the cap
/// only ends advances whose limiting pairs keep changing.
constexpr int kMaxAdvanceRounds = 200;
/// Halvings of an advance that folds neighbouring triangles through each other before the
/// folding vertices are stopped instead.
constexpr int kMaxFoldHalvings = 20;

using Clock = std::chrono::steady_clock;
double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Row v of a position matrix or of a map of one (a template: a map bound to const Positions&
/// would be copied whole on every call).
template <class PositionMatrix>
Eigen::Vector3d row(const PositionMatrix& p, int v) {
  return p.row(v).transpose();
}

/// The level-(l+1) surface with some clusters not yet expanded: each fine vertex is represented
/// by itself once expanded, else by its cluster's first child; triangles and edges whose
/// representatives coincide are dropped, duplicates merged, and the vertices renumbered.
struct MixedMesh {
  std::vector<int> fine_vertex;  ///< per mixed vertex: the fine vertex it is
  Triangles triangles;
  std::vector<std::array<int, 2>> edges;
  std::vector<int> body;
  std::vector<int> triangle_body;

  MixedMesh(const ContactSurface& surface, const std::vector<int>& representative) {
    const int n = static_cast<int>(representative.size());
    std::vector<int> mixed(n, -1);
    const auto index = [&](int v) {
      const int r = representative[v];
      if (mixed[r] < 0) {
        mixed[r] = static_cast<int>(fine_vertex.size());
        fine_vertex.push_back(r);
      }
      return mixed[r];
    };
    std::set<std::array<int, 3>> seen_triangles;
    std::vector<std::array<int, 3>> kept;
    for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
      const std::array<int, 3> r{representative[surface.triangles(t, 0)],
                                 representative[surface.triangles(t, 1)],
                                 representative[surface.triangles(t, 2)]};
      if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) continue;
      std::array<int, 3> key = r;
      std::sort(key.begin(), key.end());
      if (!seen_triangles.insert(key).second) continue;
      kept.push_back({index(surface.triangles(t, 0)), index(surface.triangles(t, 1)),
                      index(surface.triangles(t, 2))});
    }
    std::set<std::array<int, 2>> seen_edges;
    for (const auto& e : surface.edges) {
      const int a = representative[e[0]], b = representative[e[1]];
      if (a == b || !seen_edges.insert({std::min(a, b), std::max(a, b)}).second) continue;
      edges.push_back({index(e[0]), index(e[1])});
    }
    triangles.resize(static_cast<Eigen::Index>(kept.size()), 3);
    for (std::size_t t = 0; t < kept.size(); ++t)
      for (int k = 0; k < 3; ++k) triangles(static_cast<Eigen::Index>(t), k) = kept[t][k];
    for (int v : fine_vertex) body.push_back(surface.vertex_body[v]);
    for (const auto& t : kept) triangle_body.push_back(body[t[0]]);
  }

  [[nodiscard]] BroadPhase broad_phase(const BodyPairRule& may_touch) const {
    return BroadPhase(triangles, edges, body, may_touch);
  }

  [[nodiscard]] Positions positions(const Positions& fine) const {
    Positions p(static_cast<Eigen::Index>(fine_vertex.size()), 3);
    for (std::size_t m = 0; m < fine_vertex.size(); ++m)
      p.row(static_cast<Eigen::Index>(m)) = fine.row(fine_vertex[m]);
    return p;
  }
};

/// The vertices (fine numbering when `fine`, else the mixed mesh's) of the triangles that
/// intersect (pairs of bodies that may touch) or are degenerate in the mixed mesh at mixed
/// positions p; empty when it is clean.
std::vector<int> intersecting_vertices(const MixedMesh& mesh, const Positions& p,
                                       const BodyPairRule& may_touch, bool fine) {
  const IntersectionReport report = find_intersections(p, mesh.triangles);
  std::vector<int> vertices;
  const auto add_triangle = [&](int t) {
    for (int k = 0; k < 3; ++k) {
      const int m = mesh.triangles(t, k);
      vertices.push_back(fine ? mesh.fine_vertex[m] : m);
    }
  };
  for (const auto& [a, b] : report.intersecting_pairs) {
    if (!may_touch(mesh.triangle_body[a], mesh.triangle_body[b])) continue;
    add_triangle(a);
    add_triangle(b);
  }
  for (int t : report.degenerate_triangles) add_triangle(t);
  return vertices;
}

/// The same at fine positions y, in fine numbering.
std::vector<int> intersecting_vertices(const MixedMesh& mesh, const Positions& y,
                                       const BodyPairRule& may_touch) {
  return intersecting_vertices(mesh, mesh.positions(y), may_touch, true);
}

/// Whether the triangles of the mixed mesh at y around fine vertex `vertex` are clean: none
/// degenerate, none intersecting a triangle (of a body that may touch) whose box overlaps theirs.
bool vertex_patch_clean(const MixedMesh& mesh, const Positions& y, int vertex,
                        const BodyPairRule& may_touch) {
  const Positions p = mesh.positions(y);
  const auto found = std::find(mesh.fine_vertex.begin(), mesh.fine_vertex.end(), vertex);
  const int m = static_cast<int>(found - mesh.fine_vertex.begin());
  const auto box_of = [&](Eigen::Index t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) box.extend(row(p, mesh.triangles(t, k)));
    return box;
  };
  std::vector<int> incident, nearby;
  Eigen::AlignedBox3d around;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t)
    if (mesh.triangles(t, 0) == m || mesh.triangles(t, 1) == m || mesh.triangles(t, 2) == m) {
      incident.push_back(static_cast<int>(t));
      around.extend(box_of(t));
    }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t)
    if (std::find(incident.begin(), incident.end(), t) == incident.end() &&
        around.intersects(box_of(t)))
      nearby.push_back(static_cast<int>(t));
  std::vector<int> local = incident;
  local.insert(local.end(), nearby.begin(), nearby.end());
  Triangles triangles(static_cast<Eigen::Index>(local.size()), 3);
  for (std::size_t i = 0; i < local.size(); ++i)
    triangles.row(static_cast<Eigen::Index>(i)) = mesh.triangles.row(local[i]);
  const IntersectionReport report = find_intersections(p, triangles);
  const auto is_incident = [&](int i) { return i < static_cast<int>(incident.size()); };
  for (int t : report.degenerate_triangles)
    if (is_incident(t)) return false;
  for (const auto& [a, b] : report.intersecting_pairs)
    if ((is_incident(a) || is_incident(b)) &&
        may_touch(mesh.triangle_body[local[a]], mesh.triangle_body[local[b]]))
      return false;
  return true;
}

/// The i-th of n directions spread evenly over the unit sphere (a Fibonacci lattice).
Eigen::Vector3d sphere_direction(int i, int n) {
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z};
}

bool contains(const std::vector<int>& vertices, int vertex) {
  return std::find(vertices.begin(), vertices.end(), vertex) != vertices.end();
}

/// The fine vertices of the pairs (of bodies that may touch) of the mixed mesh, whose broad
/// phase is `broad`, closer than `reach` at fine positions y.
std::vector<int> close_vertices(const MixedMesh& mesh, const BroadPhase& broad, const Positions& y,
                                double reach) {
  const Positions p = mesh.positions(y);
  const Eigen::VectorXd x = flat(p);
  std::vector<int> vertices;
  for (const ContactPair& pair : candidate_pairs(broad.distance_candidates(p, reach), broad))
    if (std::sqrt(pair_distance(pair, x)) < reach)
      for (int k : pair.vertices) vertices.push_back(mesh.fine_vertex[k]);
  return vertices;
}

/// The rounds of an additive CCD advance (§4.4.4) of mixed positions p by d over the candidate
/// `pairs`: each round moves all by the smallest safe fraction and then stops the vertices of the
/// limiting pairs. A pair that its last query found free over its whole motion, none of whose
/// vertices stopped since, goes on along the rest of that motion: it is not asked again while
/// its gap bound (ratio bound times gap) has not grown. With `check_folds`, each round is also
/// checked exactly: the CCD sees no pair of neighbouring triangles, and the motion, blind to
/// physics, may fold two of them through each other across their shared edge; the step is then
/// halved, and the vertices of a fold that remains are stopped. Returns the rounds taken.
int advance_rounds(const MixedMesh& mesh, const BodyPairRule& may_touch,
                   const AdditiveCcdSettings& ccd, double gap,
                   const std::vector<ContactPair>& pairs, bool check_folds, Positions& p,
                   Positions d) {
  // Per pair, the gap bound its last query certified the whole motion with (−1: none).
  std::vector<double> certified(pairs.size(), -1.0);
  std::vector<char> stopped(static_cast<std::size_t>(p.rows()), 0);
  int rounds = 0;
  for (; rounds < kMaxAdvanceRounds && !d.isZero(0.0); ++rounds) {
    const Positions end = p + d;
    const Eigen::VectorXd x0 = flat(p), x1 = flat(end);
    const auto moving = [&](const std::array<int, 4>& vertices) {
      for (int v : vertices)
        if (!d.row(v).isZero(0.0)) return true;
      return false;
    };
    std::vector<double> toi(pairs.size(), 1.0);
    tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t i) {
      const ContactPair& pair = pairs[i];
      if (!moving(pair.vertices)) return;
      const double gap0 = std::sqrt(pair_distance(pair, x0)) - ccd.min_distance;
      AdditiveCcdSettings settings = ccd;
      settings.ratio_bound = gap0 < gap ? kCloseRatioBound : kFarRatioBound;
      const double bound = settings.ratio_bound * gap0;
      if (certified[i] >= 0.0 && bound <= certified[i]) return;
      const PairPositions start = stencil_positions(pair.vertices, x0);
      const PairPositions stop = stencil_positions(pair.vertices, x1);
      const CcdResult result = pair.edge_edge ? edge_edge_ccd(start, stop, settings)
                                              : point_triangle_ccd(start, stop, settings);
      if (result.collision) {
        toi[i] = result.toi;
        certified[i] = -1.0;
      } else {
        certified[i] = bound;
      }
    });
    double alpha = toi.empty() ? 1.0 : *std::min_element(toi.begin(), toi.end());
    std::vector<int> folded;
    for (int halvings = 0; check_folds && alpha > 0.0; ++halvings) {
      folded = intersecting_vertices(mesh, p + alpha * d, may_touch, false);
      if (folded.empty()) break;
      if (halvings == kMaxFoldHalvings) {
        alpha = 0.0;
        break;
      }
      alpha *= 0.5;
    }
    p += alpha * d;
    if (alpha >= 1.0) break;
    std::fill(stopped.begin(), stopped.end(), 0);
    for (int m : folded) stopped[m] = 1;
    for (std::size_t i = 0; i < toi.size(); ++i)
      if (toi[i] <= alpha)
        for (int k : pairs[i].vertices) stopped[k] = 1;
    d *= 1.0 - alpha;
    for (std::size_t m = 0; m < stopped.size(); ++m)
      if (stopped[m]) d.row(static_cast<Eigen::Index>(m)).setZero();
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const auto& v = pairs[i].vertices;
      if (stopped[v[0]] || stopped[v[1]] || stopped[v[2]] || stopped[v[3]]) certified[i] = -1.0;
    }
  }
  return rounds;
}

/// One batch's additive CCD advance (§4.4.4) of the mixed mesh's vertices at y by the
/// displacements `delta` (rows per fine vertex; zero rows stay). y is updated, and the rounds and
/// any redone advance are counted in `stats`. Folds are rare, and the exact check of the whole
/// mesh costs a round more than its CCD, so the rounds run unchecked and the end state is
/// checked once; only an advance that ends folded is redone with every round checked.
void advance(const MixedMesh& mesh, const BodyPairRule& may_touch, const AdditiveCcdSettings& ccd,
             double gap, Positions& y, const Positions& delta, RefinementStats& stats) {
  const BroadPhase broad = mesh.broad_phase(may_touch);
  const Positions start = mesh.positions(y);
  const Positions d = mesh.positions(delta);
  // Reach g: a pair the broad phase culls then stays farther than g, whatever its motion. Each
  // round's motion lies within the first one's (a vertex goes on along its segment, or stops
  // on it), so the first round's candidates serve them all.
  const std::vector<ContactPair> pairs =
      candidate_pairs(broad.swept_candidates(start, start + d, ccd.min_distance + gap), broad);
  Positions p = start;
  stats.ccd_rounds += advance_rounds(mesh, may_touch, ccd, gap, pairs, false, p, d);
  if (!intersecting_vertices(mesh, p, may_touch, false).empty()) {
    ++stats.folded_advances;
    p = start;
    stats.ccd_rounds += advance_rounds(mesh, may_touch, ccd, gap, pairs, true, p, d);
  }
  for (std::size_t m = 0; m < mesh.fine_vertex.size(); ++m)
    y.row(mesh.fine_vertex[m]) = p.row(static_cast<Eigen::Index>(m));
}

/// The smallest distance between primitives of the mixed mesh at y that may touch, capped at
/// `cap`.
double mixed_gap(const MixedMesh& mesh, const BodyPairRule& may_touch, const Positions& y,
                 double cap) {
  const BroadPhase broad = mesh.broad_phase(may_touch);
  return broad.clearance(mesh.positions(y), 0.0, cap);
}

/// The patch relaxation of one batch (§4.4.4): the batch's vertices of the mixed mesh's pairs
/// closer than g are relaxed toward their targets (relax_free_vertices) on the mixed surface,
/// the rest held. Without it a batch whose clusters its advance stopped near their parents
/// leaves gaps far below g, and each later batch's perturbation, bounded by the gap, shrinks with
/// them. The CCD keeps pairs apart but sees no neighbouring triangles folding across their
/// shared edge, so a relaxation that ends with a fold or a degenerate triangle is discarded.
RelaxationStats relax_batch(const MixedMesh& mesh, const ContactSurface& surface,
                            const ContactParameters& parameters, double bbox_diagonal,
                            const std::vector<bool>& movable, double gap, const Positions& goal,
                            Positions& y) {
  ContactSurface mixed_surface;
  mixed_surface.triangles = mesh.triangles;
  mixed_surface.edges = mesh.edges;
  mixed_surface.vertex_body = mesh.body;
  mixed_surface.may_touch = surface.may_touch;
  mixed_surface.rest = mesh.positions(surface.rest);
  Positions p = mesh.positions(y);
  const Eigen::VectorXd x = flat(p);
  const int m = static_cast<int>(mesh.fine_vertex.size());
  std::vector<bool> freed(m, false);
  ContactPotential whole(mixed_surface, parameters);
  for (const ContactPair& pair : whole.active_pairs(x))
    if (std::sqrt(pair_distance(pair, x)) < gap)
      for (int k : pair.vertices)
        if (k >= 0 && movable[mesh.fine_vertex[k]]) freed[k] = true;
  RelaxationStats stats;
  try {
    stats = relax_on_patch(mixed_surface, parameters, std::nullopt, bbox_diagonal, freed,
                           mesh.positions(goal), gap, p);
  } catch (const NumericalError&) {
    // A pair left nearly coincident by a vertex-by-vertex split gives the CCD no step: the
    // batch stays as its advance left it, intersection-free, and the later advances and the
    // final relaxation take it from there.
    return stats;
  }
  if (stats.vertices == 0) return stats;
  if (!intersecting_vertices(mesh, p, surface.may_touch, false).empty()) {
    stats.vertices = 0;  // its work is counted, but no vertex was relaxed
    return stats;
  }
  for (int k = 0; k < m; ++k) y.row(mesh.fine_vertex[k]) = p.row(k);
  return stats;
}

/// Adds a relaxation's work to the refinement's statistics.
void add(RefinementStats& stats, const RelaxationStats& relaxation) {
  stats.relaxed_vertices += relaxation.vertices;
  stats.relax_iterations += relaxation.iterations;
  stats.relax_seconds += relaxation.seconds;
}

/// The random numbers of a retry, seeded by the level, the vertex and the try, so that a
/// resumed run repeats them.
std::mt19937_64 seeded_random(int level, int vertex, int tries) {
  return std::mt19937_64(static_cast<std::uint64_t>(level) * 1'000'003u +
                         static_cast<std::uint64_t>(vertex) * 65'537u +
                         static_cast<std::uint64_t>(static_cast<std::int64_t>(tries) + 1));
}

}  // namespace

Eigen::VectorXd safe_initialize(const ShellSystem& fine, const std::vector<int>& parent,
                                const std::vector<int>& color, const Eigen::VectorXd& coarse_x,
                                const std::vector<std::array<int, 2>>& collapses,
                                const Eigen::VectorXd& anchors, const Eigen::VectorXd& target,
                                int level, RefinementStats& stats,
                                const RefinementProgress& progress) {
  const Clock::time_point start = Clock::now();
  const auto tell = [&](const std::string& phase) {
    if (progress) progress(phase);
  };
  stats = RefinementStats{};
  stats.level = level;
  const ContactSurface surface = contact_surface(fine, fine.scene().contact.self_contact);
  const ContactParameters parameters = contact_parameters(fine);
  AdditiveCcdSettings ccd = parameters.ccd;
  ccd.min_distance = parameters.band.thickness;
  ccd.max_iterations = kAdvanceCcdIterations;
  const double cap = parameters.band.thickness + parameters.band.activation_distance;
  const double bbox_diagonal = bounding_box_diagonal(fine.rest_mesh().vertices);
  const double perturbation_floor = kPerturbationFloor * bbox_diagonal;
  const int n = static_cast<int>(parent.size());
  // A vertex with any fixed component is held whole by the local relaxations: they only make
  // room, and the level's own solve then moves its free components.
  std::vector<bool> pinned(n, false);
  for (const PinnedVertex& pin : fine.pinned()) pinned[pin.vertex] = true;
  const int coarse_count = static_cast<int>(color.size());
  const Eigen::Map<const Positions> coarse = as_positions(coarse_x);
  const Eigen::Map<const Positions> goal = as_positions(target);
  const Eigen::Map<const Positions> anchor = as_positions(anchors);

  std::vector<std::vector<int>> neighbours(n);
  for (const auto& e : surface.edges) {
    neighbours[e[0]].push_back(e[1]);
    neighbours[e[1]].push_back(e[0]);
  }
  std::vector<std::vector<int>> children(coarse_count);
  for (int v = 0; v < n; ++v) children[parent[v]].push_back(v);
  // Per coarse vertex, its cluster's collapses (indices into `collapses`, in order), and the
  // survivor each removed vertex is merged into while its collapse is not undone (−1: split).
  std::vector<std::vector<int>> cluster_collapses(coarse_count);
  for (std::size_t c = 0; c < collapses.size(); ++c)
    cluster_collapses[parent[collapses[c][0]]].push_back(static_cast<int>(c));
  std::vector<int> merged_into(n, -1);
  const auto root = [&](int v) {
    while (merged_into[v] >= 0) v = merged_into[v];
    return v;
  };
  Positions y(n, 3);
  std::vector<int> representative(n);
  for (int v = 0; v < n; ++v) {
    y.row(v) = coarse.row(parent[v]);
    representative[v] = children[parent[v]].front();
  }
  const auto expand = [&](int k) {
    for (int v : children[k]) representative[v] = v;
  };
  std::map<int, std::vector<int>> batches;  // colour → clusters of two or more children
  for (int k = 0; k < coarse_count; ++k) {
    if (children[k].size() > 1)
      batches[color[k]].push_back(k);
    else
      expand(k);
  }

  // The children of k in `out` at parent + s·R·(layout offset), the farthest at `radius` (at
  // most the layout's own size, s ≤ 1): the layout is the anchors or the targets about the
  // parent, or the children's rest positions about their centroid.
  enum class Layout { anchors, targets, rest };
  struct ClusterLayout {
    Eigen::Matrix3d rotation;
    Layout layout;
  };
  std::map<int, ClusterLayout> layouts;  // the last layout each cluster was placed by
  const Positions& fine_rest = fine.rest_mesh().vertices;
  const auto place_into = [&](Positions& out, int k, const Eigen::Matrix3d& rotation, double radius,
                              Layout layout) {
    const Eigen::Vector3d centre = row(coarse, k);
    Eigen::Vector3d origin = centre;
    if (layout == Layout::rest) {
      origin.setZero();
      for (int v : children[k]) origin += row(fine_rest, v);
      origin /= static_cast<double>(children[k].size());
    }
    const auto offset = [&](int v) -> Eigen::Vector3d {
      switch (layout) {
        case Layout::anchors:
          return row(anchor, v) - origin;
        case Layout::targets:
          return row(goal, v) - origin;
        case Layout::rest:
          break;
      }
      return row(fine_rest, v) - origin;
    };
    double farthest = 0.0;
    for (int v : children[k]) farthest = std::max(farthest, offset(v).norm());
    const double scale = farthest > 0.0 ? std::min(1.0, radius / farthest) : 0.0;
    for (int v : children[k]) out.row(v) = (centre + scale * (rotation * offset(v))).transpose();
  };
  const auto place = [&](int k, const Eigen::Matrix3d& rotation, double radius, Layout layout) {
    place_into(y, k, rotation, radius, layout);
    layouts[k] = {rotation, layout};
  };
  // The rotation that best maps the children's rest layout onto their target layout (Kabsch).
  const auto fitted_rotation = [&](int k) {
    Eigen::Vector3d rest_mean = Eigen::Vector3d::Zero(), goal_mean = Eigen::Vector3d::Zero();
    for (int v : children[k]) {
      rest_mean += row(fine_rest, v);
      goal_mean += row(goal, v);
    }
    rest_mean /= static_cast<double>(children[k].size());
    goal_mean /= static_cast<double>(children[k].size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (int v : children[k])
      covariance += (row(goal, v) - goal_mean) * (row(fine_rest, v) - rest_mean).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
    flip(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
    return Eigen::Matrix3d(svd.matrixU() * flip * svd.matrixV().transpose());
  };

  // The refinement's safe gap g (§4.4.2) is measured once, on x_l: the ratio bounds keep pairs
  // closer than g where they are. Measured again before each batch it would shrink with every
  // batch's advance (pairs at g may end at g/10), and the gaps with it, geometrically.
  Clock::time_point phase = Clock::now();
  const double safe_gap = mixed_gap(MixedMesh(surface, representative), surface.may_touch, y, cap);
  stats.gap_seconds += since(phase);
  stats.smallest_gap = std::numeric_limits<double>::infinity();
  for (const auto& [batch_color, clusters] : batches) {
    tell(fmt::format("batch {} of {}: {} clusters", stats.batches + 1, batches.size(),
                     clusters.size()));
    phase = Clock::now();
    const double gap = mixed_gap(MixedMesh(surface, representative), surface.may_touch, y, cap);
    stats.gap_seconds += since(phase);
    if (!(gap > ccd.min_distance))
      throw NumericalError(fmt::format(
          "refinement to level {}: the state being expanded has primitives {} m apart, at or "
          "within the contact thickness, so no safe perturbation exists",
          level, gap));
    stats.smallest_gap = std::min(stats.smallest_gap, gap);
    ++stats.batches;
    stats.expansions += static_cast<int>(clusters.size());

    phase = Clock::now();
    // Below a floor the perturbation would be lost to rounding; the exact checks, not the
    // bound, then keep it intersection-free.
    const double radius =
        std::max((gap - ccd.min_distance) / kPerturbationDivisor, perturbation_floor);
    // Each cluster is first placed at its anchors themselves: its piece of the deformed level-l
    // surface, resampled. Where the exact check passes, no perturbation is needed, and the
    // patch's pairs start as far apart as the surface's own elements.
    for (int k : clusters) {
      expand(k);
      place(k, Eigen::Matrix3d::Identity(), std::numeric_limits<double>::infinity(),
            Layout::anchors);
    }
    std::set<int> failing;
    const MixedMesh expanded(surface, representative);  // the layouts move vertices only
    const BroadPhase expanded_broad = expanded.broad_phase(surface.may_touch);
    for (int tries = 0;; ++tries) {
      failing.clear();
      std::vector<int> bad = intersecting_vertices(expanded, y, surface.may_touch);
      // The anchors may lie on the level-l edges that the neighbouring, not yet expanded
      // clusters' triangles share, or next to another layer: they must keep pairs at least as
      // far apart as a perturbation would. A shrunk layout must not bring its own elements
      // much closer than its size (anchors of two children can nearly coincide on a folded
      // surface): such a gap would bound the next batch's perturbation and the solve's barrier.
      const std::vector<int> close = close_vertices(
          expanded, expanded_broad, y, tries == 0 ? radius : kSmallestShrunkGap * radius);
      bad.insert(bad.end(), close.begin(), close.end());
      for (int v : bad)
        if (children[parent[v]].size() > 1 && color[parent[v]] == batch_color)
          failing.insert(parent[v]);
      if (failing.empty() || tries == kClusterLayoutTries) break;
      for (int k : failing) {
        ++stats.perturbation_retries;
        if (tries == 0 || tries == 1) {
          place(k, Eigen::Matrix3d::Identity(), radius,
                tries == 0 ? Layout::anchors : Layout::targets);
          continue;
        }
        if (tries == 2) {
          place(k, fitted_rotation(k), radius, Layout::rest);
          continue;
        }
        std::mt19937_64 random = seeded_random(level, k, tries);
        std::normal_distribution<double> normal;
        const Eigen::Quaterniond q(normal(random), normal(random), normal(random), normal(random));
        place(k, q.normalized().toRotationMatrix(), radius, Layout::rest);
      }
    }
    // Clusters no layout suits are expanded by undoing their collapses one at a time, latest
    // first (single edge expansions, §4.4.1): back to the parent's position, then each removed
    // vertex splits off its survivor (taking along the vertices merged into it) toward its
    // anchor's offset from the survivor's, then into the sector of its neighbours outside the
    // survivor's group, then in directions turned further and further at random, its triangles
    // checked exactly after each try.
    // Merging a cluster back can bring its fan against a neighbouring cluster's perturbation
    // that was checked against the cluster's failed layout only: such clusters are merged back
    // and replayed too.
    const auto merge_back = [&](int k) {
      const Eigen::Vector3d centre = row(coarse, k);
      for (int v : children[k]) y.row(v) = centre.transpose();
      for (int c : cluster_collapses[k]) merged_into[collapses[c][0]] = collapses[c][1];
      for (int v : children[k]) representative[v] = root(v);
    };
    for (int k : failing) merge_back(k);
    while (!failing.empty()) {
      std::set<int> more;
      for (int v : intersecting_vertices(MixedMesh(surface, representative), y, surface.may_touch))
        if (children[parent[v]].size() > 1 && color[parent[v]] == batch_color &&
            !failing.contains(parent[v]))
          more.insert(parent[v]);
      if (more.empty()) break;
      for (int k : more) {
        merge_back(k);
        failing.insert(k);
      }
    }
    // Splits `group` (the removed vertex and the vertices still merged into it) off the
    // survivor, in the directions above; false, with the group back at the survivor, when none
    // leaves the patch clean.
    const auto split_off = [&](int removed, int survivor, const std::vector<int>& group) {
      const MixedMesh mixed(surface, representative);
      const BroadPhase mixed_broad = mixed.broad_phase(surface.may_touch);
      const Eigen::Vector3d from = row(y, survivor);
      std::mt19937_64 random = seeded_random(level, removed, -1);
      std::normal_distribution<double> normal;
      std::uniform_real_distribution<double> length(0.5, 1.0);
      Eigen::Vector3d sector = Eigen::Vector3d::Zero();
      for (int w : neighbours[removed])
        if (representative[w] != representative[survivor] && representative[w] != removed)
          sector += (row(y, representative[w]) - from).normalized();
      const Eigen::Vector3d toward_anchor = row(anchor, removed) - row(anchor, survivor);
      const Eigen::Matrix3d stratified_rotation =
          Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random))
              .normalized()
              .toRotationMatrix();
      for (int tries = 0; tries < kVertexDirectionTries; ++tries) {
        Eigen::Vector3d direction = toward_anchor;
        if (tries >= kBiasedDirectionTries) {
          direction =
              stratified_rotation * sphere_direction(tries - kBiasedDirectionTries,
                                                     kVertexDirectionTries - kBiasedDirectionTries);
        } else if (tries > 0 || !(direction.norm() > 0.0)) {
          const Eigen::Vector3d noise(normal(random), normal(random), normal(random));
          const double spread =
              tries <= 1 ? 0.0 : static_cast<double>(tries) / kBiasedDirectionTries;
          direction = sector.normalized() + 2.0 * spread * noise.normalized();
          if (!(sector.norm() > 0.0) || !(direction.norm() > 0.0)) direction = noise;
        }
        const double reach = (tries <= 1 ? 1.0 : length(random)) * radius;
        for (int v : group) y.row(v) = (from + reach * direction.normalized()).transpose();
        // A split that leaves its vertex almost on another element passes the exact check on
        // rounding alone (the patch folded flat onto its neighbours, a rounding error off their
        // plane), and its gap would stall every later CCD advance.
        if (vertex_patch_clean(mixed, y, removed, surface.may_touch) &&
            !contains(close_vertices(mixed, mixed_broad, y, kSmallestShrunkGap * reach), removed))
          return true;
        ++stats.perturbation_retries;
      }
      for (int v : group) y.row(v) = from.transpose();
      return false;
    };
    const auto update_representatives = [&](int k) {
      for (int v : children[k]) representative[v] = root(v);
    };
    // Splits the removed vertex of a collapse off its survivor: with the vertices still merged
    // into it, else alone (a fan folded about the survivor can leave no direction in which the
    // group's whole wedge of triangles parts from the rest; its other vertices then stay with
    // the survivor, to split off later each with its own smaller wedge), else alone off another
    // expanded neighbour in the cluster. False, with the vertex merged into its survivor again,
    // when none works.
    const auto split = [&](int k, int removed, int survivor) {
      merged_into[removed] = -1;
      update_representatives(k);
      std::vector<int> group;
      for (int v : children[k])
        if (representative[v] == removed) group.push_back(v);
      if (split_off(removed, survivor, group)) return true;
      for (int v : group)
        if (v != removed) merged_into[v] = survivor;
      update_representatives(k);
      if (group.size() > 1 && split_off(removed, survivor, {removed})) return true;
      for (int w : neighbours[removed]) {
        if (w == survivor || parent[w] != k || representative[w] != w) continue;
        y.row(removed) = y.row(w);
        if (split_off(removed, w, {removed})) return true;
      }
      merged_into[removed] = survivor;
      update_representatives(k);
      y.row(removed) = y.row(survivor);
      return false;
    };
    for (int k : failing) {
      // Latest collapse first; a split that fails waits until the cluster's other splits have
      // changed its neighbourhood, and is tried again while any of them succeeds.
      std::vector<std::array<int, 2>> waiting;
      for (auto c = cluster_collapses[k].rbegin(); c != cluster_collapses[k].rend(); ++c)
        if (!split(k, collapses[*c][0], collapses[*c][1])) waiting.push_back(collapses[*c]);
      while (!waiting.empty()) {
        std::vector<std::array<int, 2>> still;
        for (const auto& [removed, survivor] : waiting)
          if (!split(k, removed, survivor)) still.push_back({removed, survivor});
        if (still.size() == waiting.size())
          throw NumericalError(fmt::format(
              "refinement to level {}: no intersection-free perturbation of level-{} vertex {} "
              "found in {} tries while expanding level-{} vertex {}; use fewer levels or a "
              "larger [hierarchy] vertex_ratio",
              level, level, still.front()[0], kVertexDirectionTries, level - 1, k));
        waiting = std::move(still);
      }
    }
    const MixedMesh mixed(surface, representative);
    if (!failing.empty()) {
      const std::vector<int> bad = intersecting_vertices(mixed, y, surface.may_touch);
      if (!bad.empty())
        throw NumericalError(fmt::format(
            "refinement to level {}: the expansion of level-{} vertex {} intersects after its "
            "vertex-by-vertex perturbation; use fewer levels or a larger [hierarchy] "
            "vertex_ratio",
            level, level - 1, parent[bad.front()]));
    }
    stats.perturb_seconds += since(phase);

    phase = Clock::now();
    // Shrunk layouts first grow back to full size about their parents: a patch scaled about
    // its centre keeps its shape, so its own pairs only separate and only pairs with the rest of
    // the surface can limit the growth. Moved straight to the targets, any of the patch's close
    // pairs that closes in would stop its vertices there, and its gap would bound the next
    // batch's perturbation.
    Positions growth = Positions::Zero(n, 3);
    for (int k : clusters) {
      if (failing.contains(k)) continue;
      Positions full = y;
      place_into(full, k, layouts[k].rotation, std::numeric_limits<double>::infinity(),
                 layouts[k].layout);
      for (int v : children[k]) growth.row(v) = full.row(v) - y.row(v);
    }
    advance(mixed, surface.may_touch, ccd, safe_gap, y, growth, stats);
    Positions delta = Positions::Zero(n, 3);
    for (int k : clusters)
      for (int v : children[k]) delta.row(v) = goal.row(v) - y.row(v);
    advance(mixed, surface.may_touch, ccd, safe_gap, y, delta, stats);
    stats.ccd_seconds += since(phase);

    std::vector<bool> movable(n, false);
    for (int k : clusters)
      for (int v : children[k]) movable[v] = !pinned[v];
    add(stats, relax_batch(mixed, surface, parameters, bbox_diagonal, movable, safe_gap, goal, y));
  }

  // Every vertex the rest of the way, as far as it safely goes.
  const MixedMesh full(surface, representative);
  if (!std::isfinite(stats.smallest_gap)) stats.smallest_gap = safe_gap;
  tell("advance");
  phase = Clock::now();
  advance(full, surface.may_touch, ccd, safe_gap, y, goal - y, stats);
  stats.ccd_seconds += since(phase);

  // Vertices the advances stopped short, and pairs left closer than g, are relaxed (§4.4.3).
  tell("relaxation");
  Eigen::VectorXd relaxed = flat(y);
  const RelaxationStats relaxation = relax_toward_targets(fine, target, safe_gap, relaxed);
  y = as_positions(relaxed);
  add(stats, relaxation);

  tell("exact check");
  phase = Clock::now();
  const std::vector<int> bad = intersecting_vertices(full, y, surface.may_touch);
  if (!bad.empty())
    throw NumericalError(fmt::format(
        "refinement to level {}: the safe initialization ends intersecting at vertex {} (a bug: "
        "every advance is CCD-checked)",
        level, bad.front()));
  stats.final_gap = mixed_gap(full, surface.may_touch, y, cap);
  stats.check_seconds = since(phase);
  double total = 0.0;
  for (int v = 0; v < n; ++v) {
    const double distance = (y.row(v) - goal.row(v)).norm();
    stats.max_target_distance = std::max(stats.max_target_distance, distance);
    total += distance;
  }
  stats.mean_target_distance = n > 0 ? total / n : 0.0;
  stats.seconds = since(start);
  return flat(y);
}

}  // namespace psq
