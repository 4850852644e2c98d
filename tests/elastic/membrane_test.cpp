#include "engine/elastic/membrane.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "elastic/elastic_test_meshes.hpp"
#include "engine/core/error.hpp"
#include "engine/core/psd_projection.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

const PlaneStressLame kLame = plane_stress_lame(test::test_material());
const double kThickness = test::test_material().thickness;

/// A rest triangle in a random orientation (the rest frame must not matter).
TrianglePositions rest_triangle(std::mt19937& rng) {
  TrianglePositions x;
  x << 0.0, 1.0, 0.3,  //
      0.0, 0.1, 0.9,   //
      0.0, 0.0, 0.0;
  return (test::random_rotation(rng) * x).colwise() + Eigen::Vector3d(0.2, 0.5, -0.4);
}

/// Deformed states covering stretch, compression (indefinite Hessian), shear, a nearly
/// degenerate sliver and equal principal stretches (where singular vectors are arbitrary).
std::vector<DeformationGradient> test_deformations(std::mt19937& rng) {
  std::vector<DeformationGradient> fs;
  const Eigen::Matrix3d r = test::random_rotation(rng);
  const auto embed = [&](double a, double b, double shear) {
    DeformationGradient f;
    f << a, shear, 0.0, b, 0.0, 0.0;
    return DeformationGradient(r * f);
  };
  fs.push_back(embed(1.3, 1.1, 0.0));
  fs.push_back(embed(0.7, 0.9, 0.0));
  fs.push_back(embed(1.2, 0.6, 0.4));
  fs.push_back(embed(1.0, 0.02, 0.1));
  fs.push_back(embed(0.8, 0.8, 0.0));
  fs.push_back(embed(1.0, 1.0, 0.0));
  fs.push_back(DeformationGradient::Random() + embed(1.0, 1.0, 0.0));
  return fs;
}

Eigen::VectorXd vec(const DeformationGradient& f) { return f.reshaped(); }
DeformationGradient unvec(const Eigen::VectorXd& v) { return v.reshaped(3, 2); }

/// The triangle that rest_triangle becomes under the deformation gradient f (plus a shift).
TrianglePositions deformed_triangle(const TrianglePositions& rest, const DeformationGradient& f) {
  const MembraneRest r = membrane_rest(rest);
  const Eigen::Matrix<double, 3, 2> edges = f * r.rest_frame_inverse.inverse();
  TrianglePositions x;
  x.col(0) = Eigen::Vector3d(1.0, 2.0, 3.0);
  x.col(1) = x.col(0) + edges.col(0);
  x.col(2) = x.col(0) + edges.col(1);
  return x;
}

Eigen::VectorXd as_vector(const TrianglePositions& x) { return x.reshaped(); }
TrianglePositions as_triangle(const Eigen::VectorXd& v) { return v.reshaped(3, 3); }

TEST(MembraneDensity, StressMatchesFiniteDifferences) {
  std::mt19937 rng(1);
  for (const DeformationGradient& f : test_deformations(rng)) {
    const Eigen::VectorXd fd = fd_gradient(
        [](const Eigen::VectorXd& v) { return membrane_density(unvec(v), kLame); }, vec(f), 1e-7);
    // Floor at the stress scale μ: at rest (a rotation) the stress vanishes.
    EXPECT_LT(relative_error(vec(membrane_stress(f, kLame)), fd, kLame.mu), 1e-6) << f;
  }
}

TEST(MembraneDensity, StressDerivativeMatchesFiniteDifferences) {
  std::mt19937 rng(2);
  for (const DeformationGradient& f : test_deformations(rng)) {
    const Eigen::MatrixXd fd = fd_jacobian(
        [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return vec(membrane_stress(unvec(v), kLame));
        },
        vec(f), 1e-7);
    EXPECT_LT(relative_error(membrane_stress_derivative(f, kLame, false), fd), 1e-6) << f;
  }
}

TEST(MembraneDensity, AnalyticProjectionEqualsTheNumericalOne) {
  std::mt19937 rng(3);
  bool some_indefinite = false;
  for (const DeformationGradient& f : test_deformations(rng)) {
    Eigen::MatrixXd numerical = membrane_stress_derivative(f, kLame, false);
    some_indefinite |= test::min_eigenvalue(numerical) < 0;
    project_to_psd(numerical);
    EXPECT_LT(relative_error(membrane_stress_derivative(f, kLame, true), numerical), 1e-10) << f;
  }
  EXPECT_TRUE(some_indefinite) << "no test state exercises the projection";
}

TEST(MembraneTriangle, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(4);
  const TrianglePositions rest = rest_triangle(rng);
  const MembraneRest r = membrane_rest(rest);
  for (const DeformationGradient& f : test_deformations(rng)) {
    const TrianglePositions x = deformed_triangle(rest, f);
    const Eigen::VectorXd fd_g = fd_gradient(
        [&](const Eigen::VectorXd& v) {
          return membrane_triangle_energy(as_triangle(v), r, kLame, kThickness);
        },
        as_vector(x), 1e-7);
    const double force_scale = kLame.mu * kThickness * r.area;
    EXPECT_LT(
        relative_error(membrane_triangle_gradient(x, r, kLame, kThickness), fd_g, force_scale),
        1e-6);
    const Eigen::MatrixXd fd_h = fd_jacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return membrane_triangle_gradient(as_triangle(v), r, kLame, kThickness);
        },
        as_vector(x), 1e-7);
    EXPECT_LT(relative_error(membrane_triangle_hessian(x, r, kLame, kThickness, false), fd_h),
              1e-6);
  }
}

TEST(MembraneTriangle, ProjectedHessianIsPsdAndUnchangedWhenAlreadyPsd) {
  std::mt19937 rng(5);
  const TrianglePositions rest = rest_triangle(rng);
  const MembraneRest r = membrane_rest(rest);
  for (const DeformationGradient& f : test_deformations(rng)) {
    const TrianglePositions x = deformed_triangle(rest, f);
    const TriangleMatrix full = membrane_triangle_hessian(x, r, kLame, kThickness, false);
    const TriangleMatrix projected = membrane_triangle_hessian(x, r, kLame, kThickness, true);
    // Eigenvalues within rounding of zero (at rest, the bending-like modes) count as PSD.
    const double tolerance = 1e-12 * full.norm();
    EXPECT_GE(test::min_eigenvalue(projected), -tolerance);
    if (test::min_eigenvalue(full) >= -tolerance)
      EXPECT_LT(relative_error(projected, full), 1e-12);
    else
      EXPECT_GT(relative_error(projected, full), 1e-6);
  }
}

TEST(MembraneTriangle, PureStretchMatchesClosedForm) {
  // F = diag(s, 1): ‖F‖² = s² + 1, J = s, so Ψ = h A [μ/2 (s² − 1) − μ ln s + λ/2 (ln s)²].
  std::mt19937 rng(6);
  const TrianglePositions rest = rest_triangle(rng);
  const MembraneRest r = membrane_rest(rest);
  for (double s : {0.5, 0.9, 1.0, 1.4, 2.5}) {
    DeformationGradient f;
    f << s, 0, 0, 1, 0, 0;
    const double expected = kThickness * r.area *
                            (0.5 * kLame.mu * (s * s - 1) - kLame.mu * std::log(s) +
                             0.5 * kLame.lambda * std::log(s) * std::log(s));
    EXPECT_NEAR(membrane_triangle_energy(deformed_triangle(rest, f), r, kLame, kThickness),
                expected, 1e-12 * kThickness * r.area * kLame.mu + 1e-12 * std::abs(expected));
  }
}

TEST(MembraneTriangle, DegenerateStateHasInfiniteEnergyAndNoDerivatives) {
  std::mt19937 rng(7);
  const TrianglePositions rest = rest_triangle(rng);
  const MembraneRest r = membrane_rest(rest);
  TrianglePositions collinear;
  collinear << 0, 1, 2, 0, 1, 2, 0, 0, 0;
  EXPECT_EQ(membrane_triangle_energy(collinear, r, kLame, kThickness),
            std::numeric_limits<double>::infinity());
  EXPECT_THROW(membrane_triangle_gradient(collinear, r, kLame, kThickness), NumericalError);
  EXPECT_THROW(membrane_triangle_hessian(collinear, r, kLame, kThickness, true), NumericalError);
}

// ---------------------------------------------------------------------------------------------
// Whole meshes.

/// A structured width×height rectangle with `cells` squares along x.
TriMesh rectangle(double width, double height, int cells) {
  SheetGenerator spec;
  spec.structured = true;
  spec.width = width;
  spec.height = height;
  spec.edge_length = width / cells;
  return make_structured_sheet(spec);
}

/// x ↦ s x, y ↦ t y applied to a flat mesh.
Eigen::VectorXd scaled(const TriMesh& mesh, double s, double t) {
  Positions p = mesh.vertices;
  p.col(0) *= s;
  p.col(1) *= t;
  return flat(p);
}

/// The lateral stretch t minimizing the energy of `mesh` stretched by s along x, by
/// golden-section search (the energy is convex in t).
double optimal_lateral_stretch(const MembraneEnergy& energy, const TriMesh& mesh, double s) {
  const auto energy_at = [&](double t) { return energy.value(scaled(mesh, s, t)); };
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = 0.2, b = 1.5;
  while (b - a > 1e-10) {
    const double c = b - golden * (b - a), d = a + golden * (b - a);
    if (energy_at(c) < energy_at(d))
      b = d;
    else
      a = c;
  }
  return 0.5 * (a + b);
}

TEST(MembraneEnergy, UniaxialStretchWithFreeContractionMatchesPlaneStressTheory) {
  // Stretch s along x, lateral stretch t along y: F = diag(s, t), J = s t and
  //   ψ(t) = μ/2 (s² + t² − 2) − μ ln(s t) + λ/2 ln²(s t).
  // The free lateral stretch minimizes ψ: ∂ψ/∂t = μ t − μ/t + λ ln(s t)/t = 0, i.e.
  //   μ (t² − 1) + λ ln(s t) = 0,
  // whose left side increases with t, so bisection finds the unique root t*. The mesh energy
  // at its numerical optimum over t must be h·A·ψ(t*).
  const Material material = test::test_material();
  const TriMesh mesh = rectangle(1.0, 0.5, 4);
  const MembraneEnergy energy(mesh, material);
  const double area = 0.5, mu = kLame.mu, lambda = kLame.lambda;
  for (double s : {0.8, 1.2, 1.6}) {
    double lo = 0.2, hi = 1.5;
    while (hi - lo > 1e-14) {
      const double mid = 0.5 * (lo + hi);
      if (mu * (mid * mid - 1) + lambda * std::log(s * mid) > 0)
        hi = mid;
      else
        lo = mid;
    }
    const double t_star = 0.5 * (lo + hi);
    const double log_j = std::log(s * t_star);
    const double expected =
        material.thickness * area *
        (0.5 * mu * (s * s + t_star * t_star - 2) - mu * log_j + 0.5 * lambda * log_j * log_j);

    const double t_mesh = optimal_lateral_stretch(energy, mesh, s);
    EXPECT_NEAR(t_mesh, t_star, 1e-6) << "s = " << s;
    EXPECT_NEAR(energy.value(scaled(mesh, s, t_mesh)), expected, 1e-9 * expected) << "s = " << s;
  }
}

TEST(MembraneEnergy, SmallUniaxialStrainRecoversYoungsModulusAndPoissonRatio) {
  // Linear plane stress under uniaxial tension: stress E ε, lateral strain −ν ε and energy
  // h A E ε²/2, up to relative corrections of order ε.
  const Material material = test::test_material();
  const TriMesh mesh = rectangle(1.0, 0.5, 4);
  const MembraneEnergy energy(mesh, material);
  const double eps = 1e-4;
  const double t = optimal_lateral_stretch(energy, mesh, 1 + eps);
  EXPECT_NEAR((1 - t) / eps, material.poisson_ratio, 1e-3);
  const double expected = material.thickness * 0.5 * material.youngs_modulus * eps * eps / 2;
  EXPECT_NEAR(energy.value(scaled(mesh, 1 + eps, t)), expected, 2e-3 * expected);
}

TEST(MembraneEnergy, CurvedRestStateHasZeroEnergyAndGradient) {
  std::mt19937 rng(8);
  const TriMesh rest = test::curved_sheet(6, 0.3, rng);
  const MembraneEnergy energy(rest, test::test_material());
  const Eigen::VectorXd x = flat(rest.vertices);
  // Scale of a unit strain: μ h times the element area (energy) or edge length (force).
  const double edge = 1.0 / 6;
  EXPECT_NEAR(energy.value(x), 0.0, 1e-12 * kLame.mu * kThickness);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  energy.add_gradient(x, g);
  EXPECT_LT(g.lpNorm<Eigen::Infinity>(), 1e-12 * kLame.mu * kThickness * edge);
}

TEST(MembraneEnergy, GradientAndHessianMatchFiniteDifferencesOnACurvedMesh) {
  std::mt19937 rng(9);
  const TriMesh rest = test::curved_sheet(4, 0.3, rng);
  const MembraneEnergy energy(rest, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(rest.vertices), 0.05, rng);
  const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(y.size());
    energy.add_gradient(y, g);
    return g;
  };
  const Eigen::VectorXd fd_g =
      fd_gradient([&](const Eigen::VectorXd& y) { return energy.value(y); }, x, 1e-7);
  EXPECT_LT(relative_error(gradient(x), fd_g), 1e-6);

  ElementMatrices blocks;
  energy.hessian(x, blocks, false);
  const Eigen::MatrixXd h = test::dense_hessian(blocks, x.size());
  EXPECT_LT(relative_error(h, fd_jacobian(gradient, x, 1e-7)), 1e-6);

  energy.hessian(x, blocks, true);
  const Eigen::MatrixXd projected = test::dense_hessian(blocks, x.size());
  EXPECT_GE(test::min_eigenvalue(projected), -1e-12 * projected.norm());
}

TEST(MembraneEnergy, RigidMotionsChangeNeitherEnergyNorForceMagnitudes) {
  std::mt19937 rng(10);
  const TriMesh rest = test::curved_sheet(5, 0.3, rng);
  const MembraneEnergy energy(rest, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(rest.vertices), 0.05, rng);
  const Eigen::Matrix3d r = test::random_rotation(rng);
  const Eigen::VectorXd y = test::rigidly_moved(x, r, Eigen::Vector3d(3.0, -1.0, 0.5));
  const double e = energy.value(x);
  EXPECT_NEAR(energy.value(y), e, 1e-12 * e);
  // Forces rotate with the body.
  Eigen::VectorXd gx = Eigen::VectorXd::Zero(x.size()), gy = Eigen::VectorXd::Zero(x.size());
  energy.add_gradient(x, gx);
  energy.add_gradient(y, gy);
  EXPECT_LT(relative_error(gy, test::rigidly_moved(gx, r, Eigen::Vector3d::Zero())), 1e-10);
}

TEST(MembraneEnergy, WorksAtAVertexOffsetAndReusesHessianStorage) {
  std::mt19937 rng(11);
  const TriMesh rest = test::curved_sheet(3, 0.3, rng);
  const int offset = 5, n = rest.vertex_count();
  const MembraneEnergy alone(rest, test::test_material());
  const MembraneEnergy shifted(rest, test::test_material(), offset);
  const Eigen::VectorXd x = test::randomly_perturbed(flat(rest.vertices), 0.05, rng);
  Eigen::VectorXd scene = Eigen::VectorXd::Random(3 * (n + offset + 2));
  scene.segment(3 * offset, 3 * n) = x;

  EXPECT_EQ(shifted.value(scene), alone.value(x));
  Eigen::VectorXd g_alone = Eigen::VectorXd::Zero(x.size());
  Eigen::VectorXd g_scene = Eigen::VectorXd::Zero(scene.size());
  alone.add_gradient(x, g_alone);
  shifted.add_gradient(scene, g_scene);
  EXPECT_EQ(g_scene.segment(3 * offset, 3 * n), g_alone);
  EXPECT_EQ(g_scene.head(3 * offset).norm() + g_scene.tail(6).norm(), 0.0);

  ElementMatrices blocks;
  shifted.hessian(scene, blocks);
  ASSERT_EQ(blocks.stencil_size, 3);
  ASSERT_EQ(blocks.element_count(), static_cast<std::size_t>(rest.triangle_count()));
  for (int t = 0; t < rest.triangle_count(); ++t)
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(blocks.vertices[3 * t + a], offset + rest.triangles(t, a));
  const double* storage = blocks.values.data();
  shifted.hessian(scene, blocks);
  EXPECT_EQ(blocks.values.data(), storage);
}

TEST(MembraneEnergy, RejectsDegenerateRestTrianglesAndNonFinitePositions) {
  TriMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  mesh.triangles.resize(1, 3);
  mesh.triangles << 0, 1, 2;
  EXPECT_THROW(MembraneEnergy(mesh, test::test_material()), InputError);

  mesh.vertices(2, 1) = 1.0;
  const MembraneEnergy energy(mesh, test::test_material());
  Eigen::VectorXd x = flat(mesh.vertices);
  x[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)energy.value(x), NumericalError);
}

}  // namespace
}  // namespace psq
