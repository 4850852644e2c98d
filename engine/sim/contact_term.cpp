#include "engine/sim/contact_term.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace psq {
namespace {

/// d̂ as a fraction of the rest state's bounding-box diagonal when the scene does not set it.
constexpr double kDefaultActivationFraction = 1e-3;

/// κ doubles while the smallest gap keeps shrinking below this fraction of d̂. IPC's ε_g
/// (1e-9 l on squared distances, about 3e-5 l on gaps at l = 1 m) is of this order for the
/// default d̂ = 1e-3 l; gaps far smaller leave the CCD creeping along sliding contacts.
constexpr double kStiffeningGapFraction = 1e-2;

/// κ_max = 100 κ_min in IPC, with κ_min from the vertex masses. Thin stiff shells (a 0.1 mm
/// aluminium wall) have tiny masses but large elastic forces, and κ pinned at that bound lets
/// gaps collapse until the CCD creeps; updates may therefore reach this many times further.
constexpr double kStiffnessRangeWidening = 1e4;

void append_edges(const MeshTopology& topology, int first_vertex,
                  std::vector<std::array<int, 2>>& edges) {
  for (const auto& e : topology.edges) edges.push_back({e[0] + first_vertex, e[1] + first_vertex});
}

/// The mean mass of a DOF of the system's shells (colliders have none).
double shell_average_mass(const ShellSystem& system) {
  int shell_vertices = 0;
  for (const ShellBlock& shell : system.shells()) shell_vertices += shell.vertex_count;
  return system.dof_masses().head(3 * shell_vertices).sum() / (3.0 * shell_vertices);
}

}  // namespace

bool contact_enabled(const Scene& scene) {
  return scene.contact.enabled.value_or(scene.shells.size() + scene.colliders.size() > 1 ||
                                        scene.contact.self_contact);
}

ContactSurface contact_surface(const ShellSystem& system, bool self_contact) {
  ContactSurface surface;
  surface.rest = system.rest_mesh().vertices;
  surface.triangles = system.rest_mesh().triangles;
  surface.vertex_body.assign(system.rest_mesh().vertex_count(), 0);
  int body = 0;
  for (const ShellBlock& shell : system.shells()) {
    append_edges(shell.topology, shell.first_vertex, surface.edges);
    std::fill_n(surface.vertex_body.begin() + shell.first_vertex, shell.vertex_count, body++);
  }
  const int shell_count = body;
  for (const ColliderBlock& collider : system.colliders()) {
    append_edges(collider.topology, collider.first_vertex, surface.edges);
    std::fill_n(surface.vertex_body.begin() + collider.first_vertex, collider.vertex_count, body++);
  }
  surface.may_touch = [shell_count, self_contact](int a, int b) {
    if (a >= shell_count && b >= shell_count) return false;
    return a != b || self_contact;
  };
  return surface;
}

ContactParameters contact_parameters(const ShellSystem& system) {
  const ContactSettings& settings = system.scene().contact;
  ContactParameters parameters;
  parameters.band.activation_distance = settings.activation_distance.value_or(
      kDefaultActivationFraction * bounding_box_diagonal(system.rest_mesh().vertices));
  parameters.band.thickness = settings.thickness;
  parameters.ccd.rescaling = settings.ccd_rescaling;
  parameters.ccd.ratio_bound = settings.ccd_ratio_bound;
  parameters.ccd.max_iterations = settings.ccd_max_iterations;
  parameters.skip_when_apart = settings.skip_when_apart;
  return parameters;
}

ContactTerm::ContactTerm(const ShellSystem& system)
    : ContactTerm(contact_surface(system, system.scene().contact.self_contact),
                  contact_parameters(system), system.scene().contact.stiffness,
                  bounding_box_diagonal(system.rest_mesh().vertices), shell_average_mass(system)) {}

ContactTerm::ContactTerm(ContactSurface surface, const ContactParameters& parameters,
                         std::optional<double> fixed_stiffness, double bbox_diagonal,
                         double average_mass)
    : potential_(std::move(surface), parameters),
      fixed_stiffness_(fixed_stiffness.has_value()),
      bbox_diagonal_(bbox_diagonal),
      average_mass_(average_mass),
      previous_min_distance_(std::numeric_limits<double>::infinity()) {
  stiffness_.value = fixed_stiffness.value_or(0.0);
  stiffness_.max = stiffness_.value;
  potential_.set_stiffness(stiffness_.value);
}

void ContactTerm::initialize_stiffness(const Eigen::VectorXd& x,
                                       const Eigen::VectorXd& base_gradient,
                                       const std::vector<bool>& free, double inertia_weight) {
  previous_min_distance_ = potential_.min_distance(x);
  if (fixed_stiffness_) return;
  Eigen::VectorXd energy = base_gradient;
  Eigen::VectorXd barrier = potential_.unit_gradient(x);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!free[i]) energy[i] = barrier[i] = 0.0;
  const BarrierStiffness initial =
      initial_barrier_stiffness(bbox_diagonal_, potential_.parameters().band,
                                inertia_weight * average_mass_, energy, barrier);
  // κ never drops between frames: pairs resting in contact keep the stiffness they needed.
  stiffness_.max = std::max(stiffness_.max, kStiffnessRangeWidening * initial.max);
  stiffness_.value = std::max(stiffness_.value, initial.value);
  potential_.set_stiffness(stiffness_.value);
}

bool ContactTerm::update_stiffness(const Eigen::VectorXd& x, bool steps_cut_by_ccd) {
  const double min_distance = potential_.min_distance(x);
  const BarrierBand& band = potential_.parameters().band;
  const double gap_scale = kStiffeningGapFraction * band.activation_distance / bbox_diagonal_;
  const BarrierStiffness updated =
      update_barrier_stiffness(stiffness_, previous_min_distance_, min_distance, bbox_diagonal_,
                               band, gap_scale, steps_cut_by_ccd);
  previous_min_distance_ = min_distance;
  if (fixed_stiffness_ || updated.value == stiffness_.value) return false;
  stiffness_ = updated;
  potential_.set_stiffness(stiffness_.value);
  return true;
}

void ContactTerm::scale_stiffness(double factor) {
  if (fixed_stiffness_) return;
  stiffness_.value *= factor;
  stiffness_.max = std::max(stiffness_.max, stiffness_.value);
  potential_.set_stiffness(stiffness_.value);
}

namespace {
constexpr const char* kStiffnessName = "contact.stiffness";
constexpr const char* kMaxStiffnessName = "contact.max_stiffness";
constexpr const char* kPreviousMinDistanceName = "contact.previous_min_distance";
}  // namespace

void ContactTerm::save_state(std::map<std::string, double>& state) const {
  state[kStiffnessName] = stiffness_.value;
  state[kMaxStiffnessName] = stiffness_.max;
  // Infinite while no pair is within reach; checkpoints hold finite scalars only, so that
  // distance is written as its absence (docs/stress.md: a contact-free frame's snapshot was
  // refused).
  if (std::isfinite(previous_min_distance_))
    state[kPreviousMinDistanceName] = previous_min_distance_;
}

void ContactTerm::load_state(const std::map<std::string, double>& state) {
  load_named(state, kStiffnessName, stiffness_.value);
  load_named(state, kMaxStiffnessName, stiffness_.max);
  previous_min_distance_ = std::numeric_limits<double>::infinity();
  load_named(state, kPreviousMinDistanceName, previous_min_distance_);
  potential_.set_stiffness(stiffness_.value);
}

void ContactTerm::hessian(const Eigen::VectorXd& x, const std::vector<bool>& fixed_vertices,
                          bool project_psd, Eigen::VectorXd& /*diagonal*/,
                          ElementMatrices& blocks) {
  potential_.hessian(x, blocks, project_psd, fixed_vertices);
}

}  // namespace psq
