// build_hierarchy: staged CGAL edge collapse with the successive self-parameterization of
// Liu et al. 2021. The only translation unit of the hierarchy that includes CGAL.

// GCC 12 reports a false -Wmaybe-uninitialized inside the Eigen 4×4 matrices that CGAL's
// quadric policies copy (PlainObjectBase copy constructor); it concerns no code of ours.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Edge_collapse_visitor_base.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_probabilistic_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <array>
#include <map>
#include <numbers>
#include <optional>

#include "engine/core/error.hpp"
#include "engine/hierarchy/expansion_coloring.hpp"
#include "engine/hierarchy/mesh_hierarchy.hpp"
#include "engine/hierarchy/patch_layout.hpp"
#include "engine/hierarchy/triangle_quality.hpp"
#include "engine/mesh/mesh_io.hpp"

namespace psq {

namespace {

namespace SMS = CGAL::Surface_mesh_simplification;
using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Vertex = Mesh::Vertex_index;
using Face = Mesh::Face_index;
/// Probabilistic plane quadrics (Trettner & Kobbelt 2020): the positional variance keeps the
/// quadric of a flat region invertible, so sheets get a well-posed placement; triangle
/// quality is enforced by our own filter, which makes the triangle variant's shape term
/// unnecessary, and the plane variant is the cheaper of the two.
using Quadrics = SMS::GarlandHeckbert_probabilistic_plane_policies<Mesh, Kernel>;

constexpr double kDegree = std::numbers::pi / 180;
/// Smallest twice-area of a triangle in the unit-circle layout of a patch.
constexpr double kMinLayoutDoubleArea = 1e-12;
/// A patch is projected onto its mean plane only if no face shrinks below this fraction of
/// its area there (faces tilted less than ~75° from the plane).
constexpr double kMinProjectedAreaFraction = 0.25;

Eigen::Vector3d to_eigen(const Point& p) { return {p.x(), p.y(), p.z()}; }

Eigen::Vector3d face_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  return (b - a).cross(c - a).normalized();
}

/// A point tracked through the collapses: barycentric coordinates on the current face,
/// ordered like `corners` (vertex indices), since faces keep no stable corner order.
struct TrackedPoint {
  int face = -1;
  std::array<Vertex, 3> corners;
  Eigen::Vector3d barycentric;
  int finest_vertex = -1;    ///< the finest vertex it is, or -1
  int snapshot_vertex = -1;  ///< the vertex of the last snapshot it is, or -1
};

/// Where the collapse of an edge places the result: free (quadric optimum) or at endpoint
/// 0 or 1, which then survives with its attributes.
enum class Keep { kFree, kV0, kV1 };

/// The outcome of a collapse computed in the filter, applied once CGAL has collapsed.
struct CollapseTrial {
  Vertex v0, v1;
  Keep keep = Keep::kFree;
  std::vector<Face> old_faces;
  std::vector<Vertex> local_vertices;  ///< local id → vertex; the new vertex is the last id
  std::vector<std::array<int, 3>> new_faces;
  struct Relocation {
    int point;
    int new_face;
    Eigen::Vector3d barycentric;
  };
  std::vector<Relocation> relocations;
};

class Decimator {
 public:
  Decimator(const TriMesh& finest, const std::vector<int>& pin_group);

  /// Collapses until `target` vertices remain or no collapse is allowed.
  void decimate_to(int target);
  [[nodiscard]] int vertex_count() const { return vertex_count_; }
  /// The current mesh as a level; locates the tracked points on it; then tracks the level's
  /// own vertices (for the next coarser level's next_finer).
  HierarchyLevel snapshot();

  // Policies called by CGAL.
  [[nodiscard]] std::optional<Keep> placement_rule(Vertex v0, Vertex v1, bool border_edge) const;
  bool try_collapse(Vertex v0, Vertex v1, Keep keep, const Eigen::Vector3d& position);
  void commit(Vertex v0, Vertex v1, Vertex survivor);

 private:
  [[nodiscard]] bool is_corner(Vertex v) const;
  [[nodiscard]] bool removable_into(Vertex removed, Vertex kept, bool border_edge) const;
  [[nodiscard]] std::vector<Face> star_of_edge(Vertex v0, Vertex v1) const;
  [[nodiscard]] std::array<Vertex, 3> face_vertices(Face f) const;
  void track_vertex(Vertex v, int finest_vertex, int snapshot_vertex);
  void rebuild_face_points();

  Mesh mesh_;
  Mesh::Property_map<Vertex, int> pin_;
  Mesh::Property_map<Vertex, bool> finest_corner_;
  Mesh::Property_map<Vertex, Vertex> merged_into_;
  Positions finest_normals_;
  int finest_count_;
  int vertex_count_;
  std::vector<TrackedPoint> points_;  ///< finest vertices first, then the last snapshot's
  std::vector<std::vector<int>> face_points_;
  std::vector<Vertex> snapshot_vertices_;  ///< vertices of the last snapshot, in its order
  /// The collapses since the last snapshot, in order: (removed, survivor).
  std::vector<std::array<Vertex, 2>> stage_collapses_;
  /// False while the last snapshot is the finest mesh, whose vertices are the finest points.
  bool snapshot_tracked_separately_ = false;
  std::optional<CollapseTrial> trial_;
};

Decimator::Decimator(const TriMesh& finest, const std::vector<int>& pin_group)
    : finest_normals_(vertex_normals(finest)),
      finest_count_(finest.vertex_count()),
      vertex_count_(finest.vertex_count()) {
  for (int v = 0; v < finest.vertex_count(); ++v) {
    mesh_.add_vertex(Point(finest.vertices(v, 0), finest.vertices(v, 1), finest.vertices(v, 2)));
  }
  for (int t = 0; t < finest.triangle_count(); ++t) {
    const auto tri = finest.triangles.row(t);
    if (mesh_.add_face(Vertex(tri(0)), Vertex(tri(1)), Vertex(tri(2))) == Mesh::null_face()) {
      throw InputError(fmt::format("hierarchy: triangle {} of the finest mesh is not manifold", t));
    }
  }
  pin_ = mesh_.add_property_map<Vertex, int>("v:pin", kFreeVertex).first;
  finest_corner_ = mesh_.add_property_map<Vertex, bool>("v:corner", false).first;
  merged_into_ = mesh_.add_property_map<Vertex, Vertex>("v:merged", Mesh::null_vertex()).first;
  for (const Vertex v : mesh_.vertices()) {
    if (!pin_group.empty()) pin_[v] = pin_group[v.idx()];
    finest_corner_[v] = is_corner(v);
  }
  for (const Vertex v : mesh_.vertices()) {
    snapshot_vertices_.push_back(v);
    track_vertex(v, static_cast<int>(v.idx()), -1);
  }
  rebuild_face_points();
}

std::array<Vertex, 3> Decimator::face_vertices(Face f) const {
  std::array<Vertex, 3> corners;
  int k = 0;
  for (const Vertex v : mesh_.vertices_around_face(mesh_.halfedge(f))) corners[k++] = v;
  return corners;
}

void Decimator::track_vertex(Vertex v, int finest_vertex, int snapshot_vertex) {
  // Any face around the vertex holds it as a corner with weight one.
  for (const Face f : mesh_.faces_around_target(mesh_.halfedge(v))) {
    if (f == Mesh::null_face()) continue;
    TrackedPoint point;
    point.face = static_cast<int>(f.idx());
    point.corners = face_vertices(f);
    point.barycentric = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      if (point.corners[k] == v) point.barycentric[k] = 1;
    }
    point.finest_vertex = finest_vertex;
    point.snapshot_vertex = snapshot_vertex;
    points_.push_back(point);
    return;
  }
  throw InputError(fmt::format("hierarchy: vertex {} belongs to no triangle", v.idx()));
}

void Decimator::rebuild_face_points() {
  face_points_.assign(mesh_.number_of_faces() + mesh_.number_of_removed_faces(), {});
  for (int p = 0; p < static_cast<int>(points_.size()); ++p) {
    face_points_[points_[p].face].push_back(p);
  }
}

bool Decimator::is_corner(Vertex v) const {
  for (const auto h : mesh_.halfedges_around_target(mesh_.halfedge(v))) {
    if (!mesh_.is_border(h)) continue;
    // h runs along the boundary into v, next(h) out of it.
    const Eigen::Vector3d previous = to_eigen(mesh_.point(mesh_.source(h)));
    const Eigen::Vector3d here = to_eigen(mesh_.point(v));
    const Eigen::Vector3d next = to_eigen(mesh_.point(mesh_.target(mesh_.next(h))));
    const Eigen::Vector3d in = here - previous, out = next - here;
    const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
    return turn > kHierarchyCornerDegrees * kDegree;
  }
  return false;
}

bool Decimator::removable_into(Vertex removed, Vertex kept, bool border_edge) const {
  if (mesh_.is_border(removed)) {
    if (!border_edge || !mesh_.is_border(kept)) return false;
    if (finest_corner_[removed] || is_corner(removed)) return false;
  }
  return pin_[removed] == kFreeVertex || pin_[kept] == pin_[removed];
}

std::optional<Keep> Decimator::placement_rule(Vertex v0, Vertex v1, bool border_edge) const {
  const auto constrained = [&](Vertex v) { return mesh_.is_border(v) || pin_[v] != kFreeVertex; };
  if (!constrained(v0) && !constrained(v1)) return Keep::kFree;
  if (removable_into(v0, v1, border_edge)) return Keep::kV1;
  if (removable_into(v1, v0, border_edge)) return Keep::kV0;
  return std::nullopt;
}

std::vector<Face> Decimator::star_of_edge(Vertex v0, Vertex v1) const {
  std::vector<Face> faces;
  for (const Vertex v : {v0, v1}) {
    for (const Face f : mesh_.faces_around_target(mesh_.halfedge(v))) {
      if (f != Mesh::null_face() && std::find(faces.begin(), faces.end(), f) == faces.end()) {
        faces.push_back(f);
      }
    }
  }
  return faces;
}

/// One 2D layout of the patch before a collapse and of the patch after it (its last vertex
/// is the new one), with the same boundary polygon, so that points carry over by position.
/// Nearly flat patches are projected onto their mean plane (almost isometric: the map barely
/// moves points); others get the boundary on a circle and mean-value interiors (always valid,
/// more distorted). `kept`: the local endpoint the result is placed at, or −1 (free).
bool shared_layout(const Patch& before, const Patch& after, int kept,
                   std::vector<Eigen::Vector2d>& uv) {
  const std::vector<int> loop_before = patch_boundary_loop(before);
  const std::vector<int> loop_after = patch_boundary_loop(after);
  if (loop_before.empty() || loop_after.empty()) return false;
  const int new_vertex = static_cast<int>(before.positions.size());
  std::vector<bool> on_loop(new_vertex + 1, false);
  for (const int v : loop_before) on_loop[v] = true;
  bool new_on_loop = false;
  for (const int v : loop_after) {
    if (v == new_vertex) {
      new_on_loop = true;
    } else if (!on_loop[v]) {
      return false;  // a vertex would join the boundary
    }
  }
  // On the patch boundary the result must be the kept endpoint, at its old place.
  if (new_on_loop && (kept < 0 || !on_loop[kept])) return false;

  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& f : before.faces) {
    normal += (before.positions[f[1]] - before.positions[f[0]])
                  .cross(before.positions[f[2]] - before.positions[f[0]]);
  }
  if (normal.norm() > 0) {
    uv = projected_layout(after.positions, normal.normalized());
    if (faces_fit_layout(uv, before, kMinProjectedAreaFraction) &&
        faces_fit_layout(uv, after, kMinProjectedAreaFraction)) {
      return true;
    }
  }

  uv = circle_layout(before, loop_before);
  if (!mean_value_layout(before, on_loop, uv)) return false;
  uv.push_back(new_on_loop ? uv[kept] : Eigen::Vector2d::Zero());
  if (!new_on_loop) {
    std::vector<bool> fixed(new_vertex + 1, true);
    fixed[new_vertex] = false;
    if (!mean_value_layout(after, fixed, uv)) return false;
  }
  for (const Patch* patch : {&before, &after}) {
    for (const auto& f : patch->faces) {
      if (signed_double_area(uv[f[0]], uv[f[1]], uv[f[2]]) < kMinLayoutDoubleArea) return false;
    }
  }
  return true;
}

bool Decimator::try_collapse(Vertex v0, Vertex v1, Keep keep, const Eigen::Vector3d& position) {
  CollapseTrial trial{v0, v1, keep, star_of_edge(v0, v1), {}, {}, {}};
  std::map<Vertex, int> local;
  Patch before;
  const auto local_id = [&](Vertex v) {
    const auto [it, inserted] = local.emplace(v, static_cast<int>(trial.local_vertices.size()));
    if (inserted) {
      trial.local_vertices.push_back(v);
      before.positions.push_back(to_eigen(mesh_.point(v)));
    }
    return it->second;
  };
  for (const Face f : trial.old_faces) {
    const auto corners = face_vertices(f);
    before.faces.push_back({local_id(corners[0]), local_id(corners[1]), local_id(corners[2])});
  }
  const int new_vertex = static_cast<int>(trial.local_vertices.size());
  trial.local_vertices.push_back(Mesh::null_vertex());

  // The patch after: the same faces but the two around the edge, v0 and v1 → new vertex.
  const int l0 = local.at(v0), l1 = local.at(v1);
  Patch after{before.positions, {}};
  after.positions.push_back(position);
  std::vector<int> source_face;  // the old face each new face comes from
  for (int f = 0; f < static_cast<int>(before.faces.size()); ++f) {
    auto face = before.faces[f];
    const auto has = [&](int v) { return std::find(face.begin(), face.end(), v) != face.end(); };
    if (has(l0) && has(l1)) continue;
    for (int& v : face) {
      if (v == l0 || v == l1) v = new_vertex;
    }
    after.faces.push_back(face);
    source_face.push_back(f);
  }
  const int kept = keep == Keep::kV0 ? l0 : keep == Keep::kV1 ? l1 : -1;
  std::vector<Eigen::Vector2d> uv;
  if (after.faces.empty() || !shared_layout(before, after, kept, uv)) return false;

  // Shape and orientation of every new face, in the layout and in space.
  double worst_old_angle = kHierarchyMinAngleDegrees * kDegree;
  for (const auto& f : before.faces) {
    worst_old_angle = std::min(
        worst_old_angle,
        minimum_angle(before.positions[f[0]], before.positions[f[1]], before.positions[f[2]]));
  }
  std::vector<Eigen::Vector3d> new_normals;
  for (std::size_t f = 0; f < after.faces.size(); ++f) {
    const auto& face = after.faces[f];
    const Eigen::Vector3d& a = after.positions[face[0]];
    const Eigen::Vector3d& b = after.positions[face[1]];
    const Eigen::Vector3d& c = after.positions[face[2]];
    if (minimum_angle(a, b, c) < worst_old_angle) return false;
    const auto& old = before.faces[source_face[f]];
    const Eigen::Vector3d old_normal =
        face_normal(before.positions[old[0]], before.positions[old[1]], before.positions[old[2]]);
    new_normals.push_back(face_normal(a, b, c));
    if (new_normals.back().dot(old_normal) < std::cos(kHierarchyMaxNormalChangeDegrees * kDegree)) {
      return false;
    }
  }

  // Carry every tracked point of the old faces to the new ones through the layout.
  for (const Face f : trial.old_faces) {
    for (const int p : face_points_[f.idx()]) {
      const TrackedPoint& point = points_[p];
      Eigen::Vector2d at = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) at += point.barycentric[k] * uv[local.at(point.corners[k])];
      const LayoutLocation location = locate_in_layout(uv, after.faces, at);
      if (point.finest_vertex >= 0 &&
          new_normals[location.face].dot(finest_normals_.row(point.finest_vertex)) <= 0) {
        return false;  // the new face would face away from the finest surface it covers
      }
      trial.relocations.push_back({p, location.face, location.barycentric});
    }
  }
  trial.new_faces = std::move(after.faces);
  trial_ = std::move(trial);
  return true;
}

void Decimator::commit(Vertex v0, Vertex v1, Vertex survivor) {
  if (!trial_ || trial_->v0 != v0 || trial_->v1 != v1) {
    throw NumericalError("hierarchy: a collapse was carried out without its checked trial");
  }
  CollapseTrial& trial = *trial_;
  const Vertex removed = survivor == v0 ? v1 : v0;
  merged_into_[removed] = survivor;
  stage_collapses_.push_back({removed, survivor});
  if (trial.keep != Keep::kFree) {
    const Vertex kept = trial.keep == Keep::kV0 ? v0 : v1;
    pin_[survivor] = pin_[kept];
    finest_corner_[survivor] = finest_corner_[kept];
  }
  --vertex_count_;
  trial.local_vertices.back() = survivor;

  std::map<std::array<Vertex, 3>, Face> face_of_corners;
  for (const Face f : mesh_.faces_around_target(mesh_.halfedge(survivor))) {
    if (f == Mesh::null_face()) continue;
    auto corners = face_vertices(f);
    std::sort(corners.begin(), corners.end());
    face_of_corners[corners] = f;
  }
  std::vector<Face> new_face_handles;
  std::vector<std::array<Vertex, 3>> new_face_corners;
  for (const auto& face : trial.new_faces) {
    std::array<Vertex, 3> corners{trial.local_vertices[face[0]], trial.local_vertices[face[1]],
                                  trial.local_vertices[face[2]]};
    auto sorted = corners;
    std::sort(sorted.begin(), sorted.end());
    const auto it = face_of_corners.find(sorted);
    if (it == face_of_corners.end()) {
      throw NumericalError("hierarchy: a collapsed face is missing from the mesh");
    }
    new_face_handles.push_back(it->second);
    new_face_corners.push_back(corners);
  }
  for (const Face f : trial.old_faces) face_points_[f.idx()].clear();
  for (const auto& r : trial.relocations) {
    TrackedPoint& point = points_[r.point];
    point.face = static_cast<int>(new_face_handles[r.new_face].idx());
    point.corners = new_face_corners[r.new_face];
    point.barycentric = r.barycentric;
    face_points_[point.face].push_back(r.point);
  }
  trial_.reset();
}

// CGAL policies: thin adapters onto the Decimator.

struct Placement {
  const Quadrics& quadrics;
  const Decimator& decimator;
  template <typename Profile>
  boost::optional<Point> operator()(const Profile& profile) const {
    const bool border_edge = profile.is_v0_v1_a_border() || profile.is_v1_v0_a_border();
    const std::optional<Keep> keep = decimator.placement_rule(profile.v0(), profile.v1(),
                                                              border_edge);
    if (!keep) return boost::none;
    if (*keep == Keep::kV0) return profile.p0();
    if (*keep == Keep::kV1) return profile.p1();
    return quadrics(profile);
  }
};

struct Filter {
  Decimator& decimator;
  template <typename Profile>
  boost::optional<Point> operator()(const Profile& profile,
                                    boost::optional<Point> placement) const {
    if (!placement) return placement;
    const bool border_edge = profile.is_v0_v1_a_border() || profile.is_v1_v0_a_border();
    const std::optional<Keep> keep = decimator.placement_rule(profile.v0(), profile.v1(),
                                                              border_edge);
    if (!keep || !decimator.try_collapse(profile.v0(), profile.v1(), *keep, to_eigen(*placement))) {
      return boost::none;
    }
    return placement;
  }
};

struct Visitor : SMS::Edge_collapse_visitor_base<Mesh> {
  Decimator* decimator;
  explicit Visitor(Decimator& d) : decimator(&d) {}
  template <typename Profile>
  void OnCollapsed(const Profile& profile, const Vertex& survivor) {
    decimator->commit(profile.v0(), profile.v1(), survivor);
  }
};

struct StopAtVertexCount {
  const Decimator& decimator;
  int target;
  template <typename Profile>
  bool operator()(const double&, const Profile&, std::size_t, std::size_t) const {
    return decimator.vertex_count() <= target;
  }
};

void Decimator::decimate_to(int target) {
  Quadrics quadrics(mesh_);
  SMS::edge_collapse(mesh_, StopAtVertexCount{*this, target},
                     CGAL::parameters::get_cost(quadrics)
                         .get_placement(Placement{quadrics, *this})
                         .filter(Filter{*this})
                         .visitor(Visitor(*this)));
}

HierarchyLevel Decimator::snapshot() {
  HierarchyLevel level;
  std::map<Vertex, int> index;
  level.rest.vertices.resize(vertex_count_, 3);
  for (const Vertex v : mesh_.vertices()) {
    const int i = static_cast<int>(index.size());
    index[v] = i;
    level.rest.vertices.row(i) = to_eigen(mesh_.point(v)).transpose();
    level.pin_group.push_back(pin_[v]);
  }
  std::vector<int> triangle_of_face(face_points_.size(), -1);
  level.rest.triangles.resize(mesh_.number_of_faces(), 3);
  int t = 0;
  for (const Face f : mesh_.faces()) {
    const auto corners = face_vertices(f);
    for (int k = 0; k < 3; ++k) level.rest.triangles(t, k) = index.at(corners[k]);
    triangle_of_face[f.idx()] = t++;
  }

  level.finest.resize(finest_count_);
  level.next_finer.resize(snapshot_vertices_.size());
  for (std::size_t p = 0; p < points_.size(); ++p) {
    const TrackedPoint& point = points_[p];
    SurfaceLocation location;
    location.triangle = triangle_of_face[point.face];
    const auto tri = level.rest.triangles.row(location.triangle);
    for (int k = 0; k < 3; ++k) {
      const int corner = index.at(point.corners[k]);
      const int slot = corner == tri(0) ? 0 : corner == tri(1) ? 1 : 2;
      location.barycentric[slot] = point.barycentric[k];
    }
    if (point.finest_vertex >= 0) level.finest[point.finest_vertex] = location;
    if (point.snapshot_vertex >= 0) level.next_finer[point.snapshot_vertex] = location;
  }
  if (!snapshot_tracked_separately_) level.next_finer = level.finest;

  for (const Vertex finer : snapshot_vertices_) {
    Vertex v = finer;
    while (merged_into_[v] != Mesh::null_vertex()) v = merged_into_[v];
    level.parent.push_back(index.at(v));
  }
  std::map<Vertex, int> finer_index;
  for (std::size_t i = 0; i < snapshot_vertices_.size(); ++i)
    finer_index[snapshot_vertices_[i]] = static_cast<int>(i);
  for (const auto& [removed, survivor] : stage_collapses_)
    level.collapses.push_back({finer_index.at(removed), finer_index.at(survivor)});
  stage_collapses_.clear();

  // Track this level's vertices for the next coarser level; the older snapshot is done.
  points_.resize(finest_count_);
  snapshot_vertices_.assign(mesh_.vertices().begin(), mesh_.vertices().end());
  for (std::size_t i = 0; i < snapshot_vertices_.size(); ++i) {
    track_vertex(snapshot_vertices_[i], -1, static_cast<int>(i));
  }
  snapshot_tracked_separately_ = true;
  rebuild_face_points();
  return level;
}

void validate_settings(const TriMesh& finest, const std::vector<int>& pin_group,
                       const HierarchySettings& settings) {
  if (settings.levels < 1) {
    throw InputError(fmt::format("hierarchy: levels = {}: must be at least 1", settings.levels));
  }
  if (!(settings.vertex_ratio > 0 && settings.vertex_ratio < 1)) {
    throw InputError(fmt::format("hierarchy: vertex_ratio = {}: must lie strictly between 0 and 1",
                                 settings.vertex_ratio));
  }
  if (!pin_group.empty() && static_cast<int>(pin_group.size()) != finest.vertex_count()) {
    throw InputError(fmt::format("hierarchy: pin_group has {} entries for {} finest vertices",
                                 pin_group.size(), finest.vertex_count()));
  }
  validate_mesh(finest, "hierarchy: finest mesh");
}

HierarchyLevel finest_level(const TriMesh& finest, const std::vector<int>& pin_group) {
  HierarchyLevel level;
  level.rest = finest;
  level.pin_group = pin_group.empty() ? std::vector<int>(finest.vertex_count(), kFreeVertex)
                                      : pin_group;
  level.finest.resize(finest.vertex_count());
  for (int t = 0; t < finest.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      SurfaceLocation& location = level.finest[finest.triangles(t, k)];
      location.triangle = t;
      location.barycentric = Eigen::Vector3d::Unit(k);
    }
  }
  return level;
}

}  // namespace

MeshHierarchy build_hierarchy(const TriMesh& finest, const std::vector<int>& pin_group,
                              const HierarchySettings& settings) {
  validate_settings(finest, pin_group, settings);
  std::vector<HierarchyLevel> fine_to_coarse{finest_level(finest, pin_group)};
  Decimator decimator(finest, pin_group);
  for (int level = settings.levels - 2; level >= 0; --level) {
    const int finer_count = decimator.vertex_count();
    const int target = static_cast<int>(std::lround(settings.vertex_ratio * finer_count));
    decimator.decimate_to(target);
    if (decimator.vertex_count() == finer_count) {
      if (settings.allow_fewer_levels) break;
      throw InputError(fmt::format(
          "hierarchy: level {} would equal level {} ({} vertices): no edge can be collapsed "
          "under the boundary, pin and quality rules; use fewer levels",
          level, level + 1, finer_count));
    }
    HierarchyLevel coarse = decimator.snapshot();
    coarse.expansion_color = color_expansions(fine_to_coarse.back().rest.triangles, coarse.parent,
                                              coarse.rest.vertex_count());
    fine_to_coarse.push_back(std::move(coarse));
  }
  MeshHierarchy hierarchy;
  hierarchy.levels.assign(std::make_move_iterator(fine_to_coarse.rbegin()),
                          std::make_move_iterator(fine_to_coarse.rend()));
  return hierarchy;
}

}  // namespace psq
