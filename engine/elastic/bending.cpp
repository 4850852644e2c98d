#include "engine/elastic/bending.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>

#include "engine/core/error.hpp"
#include "engine/elastic/element_loop.hpp"
#include "engine/elastic/lame.hpp"

namespace psq {

double bending_stiffness(const Material& material) { return bending_modulus(material) / 6.0; }

HingeRest hinge_rest(const HingePositions& rest) {
  const Eigen::Vector3d e = rest.col(1) - rest.col(0);
  const double twice_area0 = e.cross(rest.col(2) - rest.col(0)).norm();
  const double twice_area1 = e.cross(rest.col(3) - rest.col(0)).norm();
  return {dihedral_angle(rest), 6.0 * e.squaredNorm() / (twice_area0 + twice_area1)};
}

double hinge_angle_deviation(const HingePositions& x, const HingeRest& rest) {
  return angle_difference(dihedral_angle(x), rest.angle);
}

double hinge_energy(const HingePositions& x, const HingeRest& rest, double stiffness) {
  const std::optional<double> theta = regular_dihedral_angle(x);
  if (!theta) return std::numeric_limits<double>::infinity();
  const double deviation = angle_difference(*theta, rest.angle);
  return stiffness * rest.weight * deviation * deviation;
}

HingeVector hinge_gradient(const HingePositions& x, const HingeRest& rest, double stiffness) {
  const auto [theta, gradient] = dihedral_angle_and_gradient(x);
  return 2.0 * stiffness * rest.weight * angle_difference(theta, rest.angle) * gradient;
}

HingeMatrix hinge_hessian(const HingePositions& x, const HingeRest& rest, double stiffness,
                          bool project_psd) {
  const HingeRelativeVector g = dihedral_angle_gradient(x).tail<9>();
  HingeRelativeMatrix h = 2.0 * stiffness * rest.weight * g * g.transpose();
  if (!project_psd)
    h += 2.0 * stiffness * rest.weight * hinge_angle_deviation(x, rest) *
         dihedral_angle_relative_hessian(x);
  return expand_translation_invariant(h);
}

BendingEnergy::BendingEnergy(const TriMesh& rest, const MeshTopology& topology,
                             const Material& material, int vertex_offset)
    : stiffness_(bending_stiffness(material)),
      vertex_offset_(vertex_offset),
      vertex_count_(rest.vertex_count()) {
  stencils_.reserve(4 * topology.hinges.size());
  rest_.reserve(topology.hinges.size());
  for (std::size_t h = 0; h < topology.hinges.size(); ++h) {
    const Hinge& hinge = topology.hinges[h];
    const int local[4] = {hinge.v0, hinge.v1, hinge.opposite0, hinge.opposite1};
    HingePositions corners;
    for (int a = 0; a < 4; ++a) {
      corners.col(a) = rest.vertices.row(local[a]).transpose();
      stencils_.push_back(vertex_offset + local[a]);
    }
    if (is_degenerate_hinge(corners))
      throw InputError(fmt::format(
          "bending: rest hinge {} (edge {}–{}) has a zero-length edge or a collapsed face", h,
          hinge.v0, hinge.v1));
    rest_.push_back(hinge_rest(corners));
  }
}

void BendingEnergy::check(const Eigen::VectorXd& x) const {
  check_positions(x, vertex_offset_, vertex_count_, "bending");
}

double BendingEnergy::value(const Eigen::VectorXd& x) const {
  check(x);
  return parallel_element_sum(rest_.size(), [&](std::size_t h) {
    return hinge_energy(element_positions<4>(x, stencils_, h), rest_[h], stiffness_);
  });
}

void BendingEnergy::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) const {
  check(x);
  add_element_gradients<4>(
      stencils_,
      [&](std::size_t h) {
        return hinge_gradient(element_positions<4>(x, stencils_, h), rest_[h], stiffness_);
      },
      g);
}

void BendingEnergy::hessian(const Eigen::VectorXd& x, ElementMatrices& out,
                            bool project_psd) const {
  check(x);
  fill_element_hessians<4>(
      stencils_,
      [&](std::size_t h) {
        return hinge_hessian(element_positions<4>(x, stencils_, h), rest_[h], stiffness_,
                             project_psd);
      },
      out);
}

}  // namespace psq
