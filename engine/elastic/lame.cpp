#include "engine/elastic/lame.hpp"

namespace psq {

PlaneStressLame plane_stress_lame(const Material& m) {
  const double nu = m.poisson_ratio;
  return {m.youngs_modulus / (2.0 * (1.0 + nu)), m.youngs_modulus * nu / (1.0 - nu * nu)};
}

double bending_modulus(const Material& m) {
  const double h = m.thickness;
  return m.youngs_modulus * h * h * h / (12.0 * (1.0 - m.poisson_ratio * m.poisson_ratio));
}

}  // namespace psq
