#pragma once

namespace psq {

/// Shell material. Plane-stress Lamé parameters are derived from E and ν where needed.
struct Material {
  double youngs_modulus = 1e6;  ///< E [Pa]
  double poisson_ratio = 0.3;   ///< ν, in (-1, 0.5)
  double density = 1000.0;      ///< ρ [kg/m³]
  double thickness = 1e-3;      ///< h [m]
};

}  // namespace psq
