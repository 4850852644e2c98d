// The cantilever strip of jobs/scenes/cantilever.toml with mid-edge bending instead of hinges,
// solved statically, against Euler–Bernoulli beam theory: δ = F L³ / (3 E I), I = b h³/12.
//
// The system is built by hand (membrane + mid-edge bending − f·x, pinned clamp) so that both
// splits and several resolutions can be compared; scenes choose the halves split with
// `bending = "midedge"` (tests/sim/cantilever_test.cpp runs the scene itself).
//
// With ν = 0 a plate strip and a beam agree exactly. With ν > 0 a strip this narrow (Searle's
// parameter b²/(R h) ≈ 0.02 ≪ 1 at this load) bends like a beam, E I, with free anticlastic
// curvature; only next to the clamp, which forbids that curvature, is it stiffer, towards the
// plate value D b = E I/(1 − ν²).

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "engine/elastic/lame.hpp"
#include "engine/elastic/membrane.hpp"
#include "engine/elastic/midedge_bending.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/solver/newton.hpp"

namespace psq {
namespace {

constexpr double kLength = 0.2, kWidth = 0.02, kForce = 1e-3;
constexpr double kClampX = -0.095;  ///< every vertex at x ≤ this is pinned: two columns or more
constexpr double kTipX = 0.1;

Material strip_material(double poisson_ratio) {
  Material m;
  m.youngs_modulus = 2e9;
  m.poisson_ratio = poisson_ratio;
  m.thickness = 1e-3;
  return m;
}

/// E(x) = Ψ_membrane(x) + W_midedge(x) − f·x: the static equilibrium of the loaded strip.
class StaticStrip : public Objective {
 public:
  StaticStrip(const TriMesh& rest, const Material& material, MidedgeSplit split,
              Eigen::VectorXd force)
      : membrane_(rest, material),
        bending_(rest, MeshTopology::build(rest), material, 0, split),
        force_(std::move(force)) {}

  [[nodiscard]] Eigen::Index size() const override { return force_.size(); }
  double value(const Eigen::VectorXd& x) override {
    return membrane_.value(x) + bending_.value(x) - force_.dot(x);
  }
  void gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
    g = -force_;
    membrane_.add_gradient(x, g);
    bending_.add_gradient(x, g);
  }
  void hessian(const Eigen::VectorXd& x, HessianBlocks& h) override {
    h.diagonal = Eigen::VectorXd::Zero(size());
    h.batches.resize(2);
    membrane_.hessian(x, h.batches[0]);
    bending_.hessian(x, h.batches[1]);
  }

 private:
  MembraneEnergy membrane_;
  MidedgeBendingEnergy bending_;
  Eigen::VectorXd force_;
};

/// Tip deflection over the beam value F L³/(3 E I), L the free length from the clamp.
double tip_deflection_ratio(double edge_length, double poisson_ratio,
                            MidedgeSplit split = MidedgeSplit::halves) {
  SheetGenerator spec;
  spec.structured = true;
  spec.width = kLength;
  spec.height = kWidth;
  spec.edge_length = edge_length;
  const TriMesh rest = make_structured_sheet(spec);
  const Material material = strip_material(poisson_ratio);

  // The tip line load: each tip vertex carries the half edges beside it, like the scene's
  // line load; the clamp pins whole columns.
  Eigen::VectorXd force = Eigen::VectorXd::Zero(3 * rest.vertex_count());
  std::vector<int> pinned, tip;
  for (int v = 0; v < rest.vertex_count(); ++v) {
    if (rest.vertices(v, 0) < kClampX + 1e-9) pinned.push_back(v);
    if (rest.vertices(v, 0) > kTipX - 1e-9) tip.push_back(v);
  }
  for (int v : tip) {
    const bool corner = std::abs(std::abs(rest.vertices(v, 1)) - 0.5 * kWidth) < 1e-9;
    force[3 * v + 2] = -kForce * (corner ? 0.5 : 1.0) / static_cast<double>(tip.size() - 1);
  }

  StaticStrip strip(rest, material, split, force);
  Eigen::VectorXd x = flat(rest.vertices);
  NewtonSettings settings;
  // metres: 1e-5 of the deflection. At 1e-6 of it (1e-9 m) this stiff strip's Newton steps
  // reach their rounding floor, which lies differently on CPUs whose BLAS kernels round
  // differently: there the solve stagnates instead of converging.
  settings.tolerance = 1e-8;
  const NewtonResult result =
      NewtonSolver().minimize(strip, x, DofMap(rest.vertex_count(), pinned), settings);
  EXPECT_TRUE(result.converged) << "edge " << edge_length << ", nu " << poisson_ratio;

  double deflection = 0.0;
  for (int v : tip) deflection -= x[3 * v + 2];
  deflection /= static_cast<double>(tip.size());
  const double free_length = kTipX - kClampX;
  const double beam_stiffness =
      material.youngs_modulus * kWidth * std::pow(material.thickness, 3) / 12;
  const double beam = kForce * std::pow(free_length, 3) / (3.0 * beam_stiffness);
  std::cout << "[ midedge  ] " << (split == MidedgeSplit::halves ? "halves" : "patch fit")
            << ": cantilever edge " << edge_length * 1e3 << " mm, nu " << poisson_ratio
            << ": tip deflection / (F L^3 / 3EI) = " << deflection / beam
            << ", / (F L^3 / 3Db) = " << deflection / beam * (1 - poisson_ratio * poisson_ratio)
            << " (" << result.iterations << " Newton iterations)\n";
  return deflection / beam;
}

TEST(MidedgeCantilever, TipDeflectionMatchesEulerBernoulliWithinFivePercentWithoutPoisson) {
  for (double edge : {0.005, 0.0025})
    EXPECT_NEAR(tip_deflection_ratio(edge, 0.0), 1.0, 0.05) << edge;
}

TEST(MidedgeCantilever, WithPoissonTheStripLiesBetweenBeamAndPlate) {
  // Beam: ratio 1 (anticlastic curvature free). Plate in cylindrical bending: 1 − ν² = 0.91.
  const double nu = 0.3;
  for (double edge : {0.005, 0.0025}) {
    const double ratio = tip_deflection_ratio(edge, nu);
    EXPECT_GT(ratio, (1 - nu * nu) * 0.95) << edge;
    EXPECT_LT(ratio, 1.05) << edge;
  }
}

TEST(MidedgeCantilever, PatchFitIsTooSoftOnTheCheckerboardGrid) {
  // A twist alternating from cell row to cell row couples to bending through the asymmetric
  // patches (docs/midedge-bending.md): measured 1.50 at both resolutions. Pinned down here so
  // that a fix shows up.
  EXPECT_GT(tip_deflection_ratio(0.005, 0.0, MidedgeSplit::patch_fit), 1.3);
}

}  // namespace
}  // namespace psq
