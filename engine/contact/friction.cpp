#include "engine/contact/friction.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/friction_mollifier.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"
#include "engine/elastic/element_loop.hpp"

namespace psq {
namespace {

StencilPositions gather_stencil(const Eigen::VectorXd& x, const std::array<int, 4>& vertices) {
  StencilPositions s;
  for (int i = 0; i < 4; ++i) s.col(i) = x.segment<3>(3 * vertices[i]);
  return s;
}

/// μλ, the friction force of a sliding contact.
double sliding_force(const LaggedFrictionContact& contact) {
  return contact.friction_coefficient * contact.normal_force;
}

}  // namespace

double normal_force_magnitude(double squared_distance, const BarrierBand& band,
                              double barrier_stiffness, double barrier_weight) {
  const double s = band.barrier_argument(squared_distance);
  if (!(s > 0))
    throw NumericalError(fmt::format(
        "friction: normal force requested at squared distance {:.6g}, within the thickness "
        "(ξ² = {:.6g})",
        squared_distance, band.thickness * band.thickness));
  return 2 * barrier_stiffness * barrier_weight * std::sqrt(squared_distance) *
         std::abs(barrier_first_derivative(s, band.barrier_activation()));
}

LaggedFrictionContact lag_friction_contact(ContactKind kind, const std::array<int, 4>& vertices,
                                           const Eigen::VectorXd& lagged_positions,
                                           const BarrierBand& band, double barrier_stiffness,
                                           double friction_coefficient, double barrier_weight) {
  const StencilPositions x = gather_stencil(lagged_positions, vertices);
  const bool point_triangle = kind == ContactKind::PointTriangle;
  const double distance = point_triangle
                              ? point_triangle_distance(x.col(0), x.col(1), x.col(2), x.col(3))
                              : edge_edge_distance(x.col(0), x.col(1), x.col(2), x.col(3));
  return {vertices, point_triangle ? point_triangle_frame(x) : edge_edge_frame(x),
          friction_coefficient,
          normal_force_magnitude(distance, band, barrier_stiffness, barrier_weight)};
}

Eigen::Vector2d tangential_displacement(const ContactFrame& frame,
                                        const StencilPositions& displacement) {
  return frame.basis.transpose() * (displacement * frame.weights);
}

double friction_dissipation(const LaggedFrictionContact& contact,
                            const StencilPositions& displacement, double slip_threshold) {
  const Eigen::Vector2d u = tangential_displacement(contact.frame, displacement);
  return sliding_force(contact) * friction_mollifier(u.norm(), slip_threshold);
}

StencilDerivatives<12> friction_dissipation_derivatives(const LaggedFrictionContact& contact,
                                                        const StencilPositions& displacement,
                                                        double slip_threshold) {
  const TangentBasis& basis = contact.frame.basis;
  const Eigen::Vector4d& w = contact.frame.weights;
  const Eigen::Vector2d u = tangential_displacement(contact.frame, displacement);
  const double scale = sliding_force(contact);

  StencilDerivatives<12> d;
  d.value = scale * friction_mollifier(u.norm(), slip_threshold);
  const Eigen::Vector3d force = scale * basis * friction_mollifier_gradient(u, slip_threshold);
  const Eigen::Matrix3d stiffness =
      scale * basis * friction_mollifier_hessian(u, slip_threshold) * basis.transpose();
  for (int i = 0; i < 4; ++i) {
    d.gradient.segment<3>(3 * i) = w[i] * force;
    for (int j = 0; j < 4; ++j) d.hessian.block<3, 3>(3 * i, 3 * j) = w[i] * w[j] * stiffness;
  }
  return d;
}

FrictionPotential::FrictionPotential(const std::vector<LaggedFrictionContact>& contacts,
                                     Eigen::VectorXd step_start, double slip_threshold)
    : step_start_(std::move(step_start)), slip_threshold_(slip_threshold) {
  if (!(slip_threshold > 0 && std::isfinite(slip_threshold)))
    throw InputError(fmt::format(
        "friction: slip threshold ε_v·Δt = {} must be a positive length (set a positive "
        "friction velocity threshold ε_v)",
        slip_threshold));
  const Eigen::Index vertex_count = step_start_.size() / 3;
  for (const LaggedFrictionContact& contact : contacts) {
    if (!(sliding_force(contact) > 0)) continue;
    for (int v : contact.vertices)
      if (v < 0 || v >= vertex_count)
        throw std::invalid_argument(
            fmt::format("friction: contact vertex {} outside the {} vertices", v, vertex_count));
    contacts_.push_back(contact);
    stencils_.insert(stencils_.end(), contact.vertices.begin(), contact.vertices.end());
  }
}

StencilPositions FrictionPotential::displacement(const Eigen::VectorXd& x, std::size_t c) const {
  const auto& vertices = contacts_[c].vertices;
  return gather_stencil(x, vertices) - gather_stencil(step_start_, vertices);
}

StencilDerivatives<12> FrictionPotential::contact_derivatives(const Eigen::VectorXd& x,
                                                              std::size_t c) const {
  return friction_dissipation_derivatives(contacts_[c], displacement(x, c), slip_threshold_);
}

void FrictionPotential::check(const Eigen::VectorXd& x) const {
  if (x.size() != step_start_.size())
    throw std::invalid_argument("friction: position vector and step start differ in size");
  check_positions(x, 0, static_cast<int>(x.size() / 3), "friction");
}

double FrictionPotential::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(contacts_.size(), [&](std::size_t c) {
    return friction_dissipation(contacts_[c], displacement(x, c), slip_threshold_);
  });
}

void FrictionPotential::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  add_element_gradients<4>(
      stencils_, [&](std::size_t c) { return contact_derivatives(x, c).gradient; }, g);
}

void FrictionPotential::hessian(const Eigen::VectorXd& x, ElementMatrices& out) const {
  check(x);
  fill_element_hessians<4>(
      stencils_, [&](std::size_t c) { return contact_derivatives(x, c).hessian; }, out);
}

}  // namespace psq
