// A load–displacement curve in one run: the large-deflection cantilever under an end shear force
// (jobs/scenes/verification/cantilever_end_shear.toml, Sze, Liu & Lo 2004) with its load ramped
// over 20 frames, each settled to its static equilibrium, read through its probes: the tip's
// deflection against the published curve, and the clamp's reaction against the applied load.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>

#include "engine/scene/scene_reader.hpp"
#include "engine/sim/quasistatic.hpp"
#include "support/test_paths.hpp"

namespace psq {
namespace {

constexpr double kMaxLoad = 4.0;  ///< P_max, the scene's total end force (along −z)

/// The published curve at P/P_max = k/20, k = 1..20 (Sze, Liu & Lo 2004, §3.1): the tip's
/// deflection W and shortening −U.
constexpr std::array<double, 20> kDeflection = {
    0.663, 1.309, 1.922, 2.493, 3.015, 3.488, 3.912, 4.292, 4.631, 4.933,
    5.202, 5.444, 5.660, 5.855, 6.031, 6.190, 6.335, 6.467, 6.588, 6.698};
constexpr std::array<double, 20> kShortening = {
    0.026, 0.103, 0.224, 0.381, 0.563, 0.763, 0.971, 1.184, 1.396, 1.604,
    1.807, 2.002, 2.190, 2.370, 2.541, 2.705, 2.861, 3.010, 3.151, 3.286};

struct CurvePoint {
  double load_scale = 0;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  Eigen::Vector3d clamp = Eigen::Vector3d::Zero();
  bool converged = false;
};

const ProbeReading& reading(const FrameRecord& record, const std::string& name) {
  for (const ProbeReading& r : record.probes)
    if (r.name == name) return r;
  throw std::invalid_argument("no probe " + name);
}

/// The scene as written, every frame; its probes per frame.
const std::vector<CurvePoint>& curve() {
  static const std::vector<CurvePoint> points = [] {
    QuasistaticSimulation sim(
        read_scene(test::source_dir() / "jobs/scenes/verification/cantilever_end_shear.toml"));
    std::vector<CurvePoint> out;
    while (sim.frame() < sim.frame_count()) {
      const FrameRecord record = sim.step();
      out.push_back({record.load_scale, reading(record, "tip").value,
                     reading(record, "clamp_force").value, record.newton.converged});
    }
    return out;
  }();
  return points;
}

TEST(CantileverEndShear, OneRunTracesTheCurveAtTheRampedLoads) {
  ASSERT_EQ(curve().size(), kDeflection.size());
  for (std::size_t k = 0; k < curve().size(); ++k) {
    EXPECT_TRUE(curve()[k].converged) << "frame " << k + 1;
    EXPECT_NEAR(curve()[k].load_scale, (k + 1) / 20.0, 1e-12);
  }
}

// Mid-edge bending on a strip bent along its grid lines: docs/verification.md gives 2 % at 8
// cells across (first order in the mesh). The scene's mesh has 8 cells across; measured, W is
// 1.0–2.0 % too large (1.97 % at the first point, where the reference's three digits are worth
// 0.08 %), −U within 0.85 % of W. Errors are printed for the docs' table.
TEST(CantileverEndShear, TipDisplacementsMeetThePublishedCurve) {
  for (std::size_t k = 0; k < curve().size(); ++k) {
    const double deflection = -curve()[k].tip.z(), shortening = -curve()[k].tip.x();
    const double w_error = deflection / kDeflection[k] - 1, u_error = shortening / kShortening[k] - 1;
    std::cout << "P/Pmax " << (k + 1) / 20.0 << ": W " << deflection << " (" << 100 * w_error
              << " %), -U " << shortening << " (" << 100 * u_error << " %)\n";
    EXPECT_LT(std::abs(w_error), 0.02) << "P/P_max = " << (k + 1) / 20.0;
    // −U is second order in the deflection and small at small loads, so its error is judged
    // against W there: the error of −U in units of W.
    EXPECT_LT(std::abs(shortening - kShortening[k]) / kDeflection[k], 0.02)
        << "P/P_max = " << (k + 1) / 20.0;
  }
}

// The clamp carries the applied load: at each equilibrium its reaction is the end force. The
// frames settle to ‖d‖∞/Δt < 1e-3 (the default tolerance); measured, the reaction is within
// 2.1e-5 of the force (relative) at every frame.
TEST(CantileverEndShear, TheClampCarriesTheRampedEndForce) {
  for (std::size_t k = 0; k < curve().size(); ++k) {
    const double force = kMaxLoad * (k + 1) / 20.0;
    const Eigen::Vector3d& reaction = curve()[k].clamp;
    EXPECT_NEAR(reaction.z(), -force, 1e-4 * force) << "frame " << k + 1;
    EXPECT_NEAR(reaction.x(), 0.0, 1e-4 * force) << "frame " << k + 1;
    EXPECT_NEAR(reaction.y(), 0.0, 1e-4 * force) << "frame " << k + 1;
  }
}

}  // namespace
}  // namespace psq
