#include "engine/sim/friction_term.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "engine/core/error.hpp"
#include "engine/sim/contact_term.hpp"
#include "engine/solver/solver_stats.hpp"

namespace psq {
namespace {

/// ε_v as a fraction of the rest state's bounding-box diagonal per unit time when the scene does
/// not set it: slips below about a thousandth of the scene per unit of pseudo-time count as
/// sticking, the same scale as the default d̂, so a resting contact creeps by at most ~1e-3 of
/// the scene size per unit time.
constexpr double kDefaultSlipVelocityFraction = 1e-3;

/// Body numbers by name, shells first, then colliders (contact_surface's numbering).
int body_index(const Scene& scene, const std::string& name) {
  int index = 0;
  for (const Shell& shell : scene.shells) {
    if (shell.name == name) return index;
    ++index;
  }
  for (const Collider& collider : scene.colliders) {
    if (collider.name == name) return index;
    ++index;
  }
  throw InputError(fmt::format("{}: [[contact.pair]] bodies: no shell or collider is named '{}'",
                               scene.source.string(), name));
}

/// The body of each stencil side: vertex 0 (a point or an edge's end) and the first vertex of
/// the other side (a triangle's or the other edge's).
std::array<int, 2> pair_bodies(const ContactPair& pair, const std::vector<int>& vertex_body) {
  return {vertex_body[pair.vertices[0]], vertex_body[pair.vertices[pair.edge_edge ? 2 : 1]]};
}

}  // namespace

BodyFrictionTable::BodyFrictionTable(const Scene& scene)
    : body_count_(static_cast<int>(scene.shells.size() + scene.colliders.size())),
      coefficients_(static_cast<std::size_t>(body_count_ * body_count_), scene.contact.friction) {
  for (const BodyPairFriction& pair : scene.contact.pair_friction) {
    const int a = body_index(scene, pair.bodies[0]);
    const int b = body_index(scene, pair.bodies[1]);
    coefficients_[static_cast<std::size_t>(a * body_count_ + b)] = pair.friction;
    coefficients_[static_cast<std::size_t>(b * body_count_ + a)] = pair.friction;
  }
}

bool BodyFrictionTable::any_friction() const {
  return std::any_of(coefficients_.begin(), coefficients_.end(), [](double mu) { return mu > 0; });
}

bool friction_enabled(const Scene& scene) {
  return contact_enabled(scene) && BodyFrictionTable(scene).any_friction();
}

double friction_slip_velocity(const ShellSystem& system) {
  return system.scene().contact.friction_slip_velocity.value_or(
      kDefaultSlipVelocityFraction * bounding_box_diagonal(system.rest_mesh().vertices));
}

FrictionTerm::FrictionTerm(const ShellSystem& system, double time_step)
    : coefficients_(system.scene()),
      slip_threshold_(friction_slip_velocity(system) * time_step),
      potential_({}, flat(system.rest_mesh().vertices), slip_threshold_) {}

void FrictionTerm::lag(ContactPotential& contact, const Eigen::VectorXd& lagged_state,
                       const Eigen::VectorXd& step_start) {
  const ScopedTimer timer(seconds_);
  const std::vector<int>& vertex_body = contact.surface().vertex_body;
  const BarrierBand& band = contact.parameters().band;
  std::vector<LaggedFrictionContact> lagged;
  for (const ContactPair& pair : contact.active_pairs(lagged_state)) {
    const auto [a, b] = pair_bodies(pair, vertex_body);
    const double mu = coefficients_.between(a, b);
    if (mu == 0) continue;
    lagged.push_back(lag_friction_contact(
        pair.edge_edge ? ContactKind::EdgeEdge : ContactKind::PointTriangle, pair.vertices,
        lagged_state, band, contact.stiffness(), mu, barrier_weight(pair, lagged_state)));
  }
  potential_ = FrictionPotential(lagged, step_start, slip_threshold_);
}

double FrictionTerm::value(const Eigen::VectorXd& x) {
  const ScopedTimer timer(seconds_);
  return potential_.value(x);
}

void FrictionTerm::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  const ScopedTimer timer(seconds_);
  potential_.add_gradient(x, g);
}

// Its blocks are PSD as they stand (friction_mollifier_hessian), so there is nothing to project.
void FrictionTerm::hessian(const Eigen::VectorXd& x, const std::vector<bool>& /*fixed_vertices*/,
                           bool /*project_psd*/, Eigen::VectorXd& /*diagonal*/,
                           ElementMatrices& blocks) {
  const ScopedTimer timer(seconds_);
  potential_.hessian(x, blocks);
}

}  // namespace psq
