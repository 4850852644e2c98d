#pragma once
#include "engine/elastic/material.hpp"

namespace psq {

/// Plane-stress Lamé parameters of a thin sheet: μ = E/(2(1+ν)), λ = Eν/(1−ν²)
/// (not the 3D λ = Eν/((1+ν)(1−2ν)); see DESIGN.md §4).
struct PlaneStressLame {
  double mu;
  double lambda;
};
PlaneStressLame plane_stress_lame(const Material& material);

/// Kirchhoff–Love bending modulus D = E h³ / (12 (1 − ν²)).
double bending_modulus(const Material& material);

}  // namespace psq
