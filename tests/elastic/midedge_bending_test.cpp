#include "engine/elastic/midedge_bending.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "elastic/elastic_test_meshes.hpp"
#include "engine/elastic/bending.hpp"
#include "engine/core/error.hpp"
#include "engine/elastic/lame.hpp"
#include "engine/mesh/topology.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

using test::curved_shell;
using test::CurvedShell;
using test::fd_gradient;
using test::fd_jacobian;
using test::relative_error;

// ---------------------------------------------------------------------------------------------
// The patch: a face and its neighbours' far vertices.

/// A flat patch in the plane z = 0: the face (p0, p1, p2) and, across each edge, a far vertex
/// at a random position on the other side, so the neighbours are random triangles too.
MidedgePositions random_flat_patch(std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), along(0.1, 0.9), away(0.5, 1.2);
  MidedgePositions x = MidedgePositions::Zero();
  x.col(0) << jitter(rng), jitter(rng), 0.0;
  x.col(1) << 1.0 + jitter(rng), jitter(rng), 0.0;
  x.col(2) << 0.4 + jitter(rng), 0.9 + jitter(rng), 0.0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d a = x.col((i + 1) % 3), b = x.col((i + 2) % 3);
    Eigen::Vector3d outward = Eigen::Vector3d::UnitZ().cross(b - a);  // left of a→b: inside
    outward = -outward.normalized();
    x.col(3 + i) = a + along(rng) * (b - a) + away(rng) * outward;
  }
  return x;
}

/// Lifts a flat patch (z = 0) onto z = ½ vᵀ B v, v its in-plane position relative to p0 in the
/// patch frame of unfolded_patch.
MidedgePositions lifted(const MidedgePositions& flat_patch, const Eigen::Matrix2d& b) {
  const MidedgePatch frame = unfolded_patch(flat_patch, {true, true, true});
  MidedgePositions x = flat_patch;
  for (int k = 0; k < 6; ++k) x(2, k) = 0.5 * frame.col(k).dot(b * frame.col(k));
  return x;
}

Eigen::Matrix2d random_curvature(std::mt19937& rng) {
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  Eigen::Matrix2d b;
  b << entry(rng), entry(rng), 0.0, entry(rng);
  b(1, 0) = b(0, 1);
  return b;
}

TEST(MidedgePatch, UnfoldingKeepsTheDistancesToTheEdgeEnds) {
  std::mt19937 rng(1);
  const MidedgePositions x =
      test::random_rotation(rng) * lifted(random_flat_patch(rng), 0.8 * random_curvature(rng));
  const MidedgePatch patch = unfolded_patch(x, {true, true, true});
  const auto distance_kept = [&](int j, int k) {
    return std::abs((patch.col(j) - patch.col(k)).norm() - (x.col(j) - x.col(k)).norm()) < 1e-12;
  };
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    EXPECT_TRUE(distance_kept(i, a) && distance_kept(a, b) && distance_kept(3 + i, a) &&
                distance_kept(3 + i, b))
        << "edge " << i;
    // The far vertex lands across its edge from the face.
    const Eigen::Vector2d e = patch.col(b) - patch.col(a);
    const auto side = [&](int k) {
      const Eigen::Vector2d p = patch.col(k) - patch.col(a);
      return e.x() * p.y() - e.y() * p.x();
    };
    EXPECT_LT(side(i) * side(3 + i), 0.0) << "edge " << i;
  }
}

TEST(MidedgePatch, AngleMapPredictsTheDihedralAnglesOfAQuadraticSurface) {
  // First order in the curvature: on a patch of size 1 bent by ε B the angles are ε C β + O(ε²).
  std::mt19937 rng(2);
  const double epsilon = 1e-5;
  for (int trial = 0; trial < 20; ++trial) {
    const MidedgePositions flat_patch = random_flat_patch(rng);
    const Eigen::Matrix2d b = random_curvature(rng);
    const MidedgePositions x = lifted(flat_patch, epsilon * b);
    const Eigen::Vector3d beta(b(0, 0), b(1, 1), b(0, 1));
    const Eigen::Vector3d predicted =
        midedge_angle_map(unfolded_patch(flat_patch, {true, true, true}), {true, true, true}) *
        beta;
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(dihedral_angle(midedge_hinge(x, i)) / epsilon, predicted[i],
                  1e-3 * predicted.norm())
          << "trial " << trial << " edge " << i;
  }
}

/// The Kirchhoff–Love density of a constant curvature B: (D/2)[(κ1 + κ2)² − 2(1 − ν) κ1κ2].
double kirchhoff_love_density(const Eigen::Matrix2d& b, const Material& material) {
  const Eigen::Vector2d k = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(b).eigenvalues();
  return 0.5 * bending_modulus(material) *
         ((k[0] + k[1]) * (k[0] + k[1]) - 2.0 * (1.0 - material.poisson_ratio) * k[0] * k[1]);
}

TEST(MidedgePatch, InteriorFaceEnergyIsKirchhoffLoveForEveryConstantCurvature) {
  std::mt19937 rng(3);
  const double epsilon = 1e-5;
  for (double nu : {0.0, 0.3, -0.5}) {
    Material material = test::test_material();
    material.poisson_ratio = nu;
    for (int trial = 0; trial < 10; ++trial) {
      const MidedgePositions flat_patch = random_flat_patch(rng);
      const MidedgeRest rest =
          midedge_rest(flat_patch, {true, true, true}, material, MidedgeSplit::patch_fit);
      const Eigen::Matrix2d b = random_curvature(rng);
      const double area = 0.5 * (flat_patch.col(1) - flat_patch.col(0))
                                    .cross(flat_patch.col(2) - flat_patch.col(0))
                                    .norm();
      const double expected = area * kirchhoff_love_density(epsilon * b, material);
      EXPECT_NEAR(midedge_energy(lifted(flat_patch, epsilon * b), rest), expected,
                  2e-3 * std::abs(expected))
          << "nu " << nu << " trial " << trial;
    }
  }
}

TEST(MidedgePatch, BoundaryFaceTakesTheLeastEnergyCurvatureThatFitsItsAngles) {
  // With edge 2 on the boundary, the angles of edges 0 and 1 leave a line of curvatures
  // β = β0 + t n (C n = 0); W must be the minimum of ½ βᵀ Q β along it.
  std::mt19937 rng(4);
  const Material material = test::test_material();
  const std::array<bool, 3> interior{true, true, false};
  for (int trial = 0; trial < 5; ++trial) {
    const MidedgePositions flat_patch = random_flat_patch(rng);
    const MidedgeRest rest = midedge_rest(flat_patch, interior, material, MidedgeSplit::patch_fit);
    EXPECT_EQ(rest.stiffness.row(2).norm() + rest.stiffness.col(2).norm(), 0.0);
    const Eigen::Matrix3d c = midedge_angle_map(unfolded_patch(flat_patch, interior), interior);
    EXPECT_EQ(c.row(2).norm(), 0.0);
    const Eigen::Vector3d n = c.row(0).cross(c.row(1)).transpose();
    const Eigen::Vector3d beta0(0.3, -0.7, 0.2);
    const double area =
        0.5 *
        (flat_patch.col(1) - flat_patch.col(0)).cross(flat_patch.col(2) - flat_patch.col(0)).norm();
    const Eigen::Matrix3d q = curvature_energy_matrix(area, material);
    const double t = -n.dot(q * beta0) / n.dot(q * n);  // minimizes ½ (β0 + t n)ᵀ Q (β0 + t n)
    const Eigen::Vector3d best = beta0 + t * n;
    const Eigen::Vector3d angles = c * beta0;
    EXPECT_NEAR(0.5 * angles.dot(rest.stiffness * angles), 0.5 * best.dot(q * best),
                1e-9 * best.dot(q * best));
  }
}

TEST(MidedgePatch, CurvatureEnergyMatrixIsTheKirchhoffLoveDensityTimesArea) {
  std::mt19937 rng(5);
  Material material = test::test_material();
  material.poisson_ratio = 0.27;
  const Eigen::Matrix2d b = random_curvature(rng);
  const Eigen::Vector3d beta(b(0, 0), b(1, 1), b(0, 1));
  EXPECT_NEAR(0.5 * beta.dot(curvature_energy_matrix(2.5, material) * beta),
              2.5 * kirchhoff_love_density(b, material), 1e-12 * bending_modulus(material));
}

TEST(MidedgePatch, SixVerticesOnACircleHaveNoFittingCurvature) {
  // A regular hexagon cut into a central triangle and three ears: every vertex on one circle, so
  // some combination of angles needs a curvature no quadratic height field gives.
  MidedgePositions x;
  const int degrees[6] = {90, 210, 330, 270, 30, 150};  // p0, p1, p2, then the ear apexes
  for (int k = 0; k < 6; ++k) {
    const double a = degrees[k] * std::numbers::pi / 180.0;
    x.col(k) << std::cos(a), std::sin(a), 0.0;
  }
  EXPECT_THROW(patch_fit_stiffness(x, {true, true, true}, test::test_material()), NumericalError);
}

/// W = Ā·D/2·[ν tr(M)² + (1 − ν) tr(M²)], M = ā⁻¹ Σ_i d_i ∇λ_i∇λ_iᵀ, in the chart
/// (u, v) = (λ1, λ2) of the rest triangle: the definition, evaluated literally.
double continuum_face_energy(const Eigen::Matrix3d& rest, const Eigen::Vector3d& d,
                             const Material& material) {
  Eigen::Matrix<double, 3, 2> chart;
  chart << rest.col(1) - rest.col(0), rest.col(2) - rest.col(0);
  const Eigen::Matrix2d metric = chart.transpose() * chart;
  const double area = 0.5 * std::sqrt(metric.determinant());
  const Eigen::Vector2d grad_lambda[3] = {{-1.0, -1.0}, {1.0, 0.0}, {0.0, 1.0}};
  Eigen::Matrix2d second_form = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 3; ++i) second_form += d[i] * grad_lambda[i] * grad_lambda[i].transpose();
  const Eigen::Matrix2d m = metric.inverse() * second_form;
  const double nu = material.poisson_ratio;
  return area * 0.5 * bending_modulus(material) *
         (nu * m.trace() * m.trace() + (1.0 - nu) * (m * m).trace());
}

TEST(MidedgeHalves, StiffnessIsTheDensityOfTheAveragedNormalShapeOperator) {
  // Averaged mid-edge normals turn by θ_i/2 each: II = Σ_i h̄_i δθ_i ∇λ_i∇λ_iᵀ.
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> change(-1.0, 1.0);
  for (double nu : {0.0, 0.3, -0.4})
    for (const std::array<bool, 3> interior :
         {std::array<bool, 3>{true, true, true}, std::array<bool, 3>{false, true, true}}) {
      Material material = test::test_material();
      material.poisson_ratio = nu;
      const MidedgePositions patch = random_flat_patch(rng);
      const Eigen::Matrix3d triangle = test::random_rotation(rng) * patch.leftCols<3>();
      Eigen::Vector3d angles(change(rng), change(rng), change(rng));
      Eigen::Vector3d d;
      for (int i = 0; i < 3; ++i) {
        if (!interior[i]) angles[i] = 0.0;
        const Eigen::Vector3d edge = triangle.col((i + 2) % 3) - triangle.col((i + 1) % 3);
        const Eigen::Vector3d side = triangle.col(i) - triangle.col((i + 1) % 3);
        d[i] = edge.cross(side).norm() / edge.norm() * angles[i];  // h̄_i δθ_i
      }
      const double expected = continuum_face_energy(triangle, d, material);
      EXPECT_NEAR(
          0.5 * angles.dot(averaged_normal_stiffness(triangle, interior, material) * angles),
          expected, 1e-10 * expected);
    }
}

// ---------------------------------------------------------------------------------------------
// One element.

/// A face (p0, p1, p2) and its three neighbours' far vertices, each turned about its edge by
/// the given angle out of the face's plane, then moved rigidly; plus jitter.
MidedgePositions folded_element(const Eigen::Vector3d& folds, double jitter, std::mt19937& rng) {
  MidedgePositions x;
  x.col(0) << 0.0, 0.0, 0.0;
  x.col(1) << 1.0, 0.1, 0.0;
  x.col(2) << 0.3, 0.9, 0.0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d a = x.col((i + 1) % 3), b = x.col((i + 2) % 3);
    const Eigen::Vector3d axis = (b - a).normalized();
    // The neighbour's apex: reflect p_i across the edge, then turn it about the edge.
    const Eigen::Vector3d mid = 0.5 * (a + b);
    const Eigen::Vector3d reflected = 2.0 * (mid + (x.col(i) - mid).dot(axis) * axis) - x.col(i);
    x.col(3 + i) = a + Eigen::AngleAxisd(folds[i], axis) * (reflected - a);
  }
  std::uniform_real_distribution<double> noise(-jitter, jitter);
  for (Eigen::Index k = 0; k < x.size(); ++k) x(k) += noise(rng);
  return (test::random_rotation(rng) * x).colwise() + Eigen::Vector3d(0.5, -1.0, 2.0);
}

Eigen::VectorXd as_vector(const MidedgePositions& x) { return x.reshaped(); }
MidedgePositions as_element(const Eigen::VectorXd& v) { return v.reshaped(3, 6); }

const std::array<bool, 3> kInteriorPatterns[] = {
    {true, true, true}, {true, false, true}, {false, false, true}};

TEST(MidedgeElement, RestStateHasZeroEnergyAndForce) {
  std::mt19937 rng(5);
  for (const auto& interior : kInteriorPatterns) {
    const MidedgePositions x = folded_element({0.4, -0.8, 1.5}, 0.05, rng);
    const MidedgeRest rest = midedge_rest(x, interior, test::test_material());
    EXPECT_EQ(midedge_energy(x, rest), 0.0);
    EXPECT_LT(midedge_gradient(x, rest).norm(), 1e-12 * rest.stiffness.norm());
  }
}

TEST(MidedgeElement, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(6);
  const Eigen::Vector3d rest_folds[] = {{0.0, 0.0, 0.0}, {0.5, -0.3, 1.0}, {-2.5, 0.2, 0.1}};
  const Eigen::Vector3d folds[] = {{0.3, -0.2, 0.0}, {1.2, 2.9, -1.0}, {-3.0, 0.1, 2.0}};
  for (MidedgeSplit split : {MidedgeSplit::halves, MidedgeSplit::patch_fit})
    for (const auto& interior : kInteriorPatterns)
      for (const Eigen::Vector3d& rest_fold : rest_folds)
        for (const Eigen::Vector3d& fold : folds) {
          const MidedgeRest rest = midedge_rest(folded_element(rest_fold, 0.05, rng), interior,
                                                test::test_material(), split);
          const MidedgePositions x = folded_element(fold, 0.1, rng);
          const double scale = rest.stiffness.norm();
          const Eigen::VectorXd fd_g = fd_gradient(
              [&](const Eigen::VectorXd& v) { return midedge_energy(as_element(v), rest); },
              as_vector(x), 1e-6);
          EXPECT_LT(relative_error(midedge_gradient(x, rest), fd_g, scale), 1e-6);
          const Eigen::MatrixXd fd_h = fd_jacobian(
              [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
                return midedge_gradient(as_element(v), rest);
              },
              as_vector(x), 1e-6);
          EXPECT_LT(relative_error(midedge_hessian(x, rest, false), fd_h, scale), 1e-6);
        }
}

TEST(MidedgeElement, SolverHessianIsTheGaussNewtonTermAndPsd) {
  std::mt19937 rng(7);
  int indefinite = 0;
  for (const auto& interior : kInteriorPatterns)
    for (double amount : {0.3, 1.0, 2.5}) {
      const MidedgeRest rest = midedge_rest(folded_element({0.2, -0.1, 0.4}, 0.05, rng), interior,
                                            test::test_material());
      const MidedgePositions x = folded_element({amount, -amount, 0.5 * amount}, 0.1, rng);
      const MidedgeMatrix full = midedge_hessian(x, rest, false);
      const MidedgeMatrix solver = midedge_hessian(x, rest, true);
      EXPECT_GE(test::min_eigenvalue(solver), -1e-12 * full.norm());
      if (test::min_eigenvalue(full) < -1e-9 * full.norm()) ++indefinite;
    }
  EXPECT_GT(indefinite, 0) << "no test state has an indefinite full Hessian";
}

TEST(MidedgeElement, AtRestTheGaussNewtonTermIsTheExactHessian) {
  std::mt19937 rng(8);
  const MidedgePositions x = folded_element({0.7, -0.2, 1.1}, 0.05, rng);
  const MidedgeRest rest = midedge_rest(x, {true, true, true}, test::test_material());
  EXPECT_LT(relative_error(midedge_hessian(x, rest, true), midedge_hessian(x, rest, false)), 1e-12);
}

TEST(MidedgeElement, AngleChangeWrapsThroughPi) {
  // A neighbour folded from 3.0 to −3.0 radians turned by 2π − 6, not by 6.
  std::mt19937 rng(9);
  const std::array<bool, 3> one_edge{true, false, false};
  const MidedgeRest rest =
      midedge_rest(folded_element({3.0, 0.0, 0.0}, 0.0, rng), one_edge, test::test_material());
  const Eigen::Vector3d change =
      midedge_angle_change(folded_element({-3.0, 0.0, 0.0}, 0.0, rng), rest);
  EXPECT_NEAR(std::abs(change[0]), 2 * std::numbers::pi - 6.0, 1e-12);
}

TEST(MidedgeElement, DegenerateStateHasInfiniteEnergyAndNoDerivatives) {
  std::mt19937 rng(10);
  const MidedgePositions good = folded_element({0.2, 0.1, 0.0}, 0.0, rng);
  const MidedgeRest rest = midedge_rest(good, {true, true, true}, test::test_material());
  MidedgePositions x = good;
  x.col(3) = 0.5 * (x.col(1) + x.col(2));  // neighbour 0 collapses onto its edge
  EXPECT_EQ(midedge_energy(x, rest), std::numeric_limits<double>::infinity());
  EXPECT_THROW(midedge_gradient(x, rest), NumericalError);
  EXPECT_THROW(midedge_hessian(x, rest, true), NumericalError);
}

// ---------------------------------------------------------------------------------------------
// Whole meshes.

Eigen::VectorXd energy_gradient(const MidedgeBendingEnergy& energy, const Eigen::VectorXd& x) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  energy.add_gradient(x, g);
  return g;
}

TEST(MidedgeBendingEnergy, CurvedRestStateHasZeroEnergyAndGradient) {
  std::mt19937 rng(11);
  const CurvedShell shell = curved_shell(6, rng);
  const MidedgeBendingEnergy energy(shell.rest, shell.topology, test::test_material());
  EXPECT_EQ(energy.element_count(), shell.rest.triangle_count());  // no isolated corner faces
  const Eigen::VectorXd x = flat(shell.rest.vertices);
  EXPECT_EQ(energy.value(x), 0.0);
  EXPECT_EQ(energy_gradient(energy, x).lpNorm<Eigen::Infinity>(), 0.0);
  Positions flattened = shell.rest.vertices;
  flattened.col(2).setZero();
  EXPECT_GT(energy.value(flat(flattened)), 0.0);
}

TEST(MidedgeBendingEnergy, GradientAndHessianMatchFiniteDifferencesOnACurvedMesh) {
  std::mt19937 rng(12);
  const CurvedShell shell = curved_shell(4, rng);
  const MidedgeBendingEnergy energy(shell.rest, shell.topology, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  const auto gradient = [&](const Eigen::VectorXd& y) { return energy_gradient(energy, y); };
  const Eigen::VectorXd fd_g =
      fd_gradient([&](const Eigen::VectorXd& y) { return energy.value(y); }, x, 1e-6);
  EXPECT_LT(relative_error(gradient(x), fd_g), 1e-6);

  ElementMatrices blocks;
  energy.hessian(x, blocks, false);
  EXPECT_LT(relative_error(test::dense_hessian(blocks, x.size()), fd_jacobian(gradient, x, 1e-6)),
            1e-6);
  energy.hessian(x, blocks, true);
  const Eigen::MatrixXd projected = test::dense_hessian(blocks, x.size());
  EXPECT_GE(test::min_eigenvalue(projected), -1e-12 * projected.norm());
}

TEST(MidedgeBendingEnergy, RigidMotionsChangeNeitherEnergyNorForceMagnitudes) {
  std::mt19937 rng(13);
  const CurvedShell shell = curved_shell(5, rng);
  const MidedgeBendingEnergy energy(shell.rest, shell.topology, test::test_material());
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  const Eigen::Matrix3d r = test::random_rotation(rng);
  const Eigen::VectorXd y = test::rigidly_moved(x, r, Eigen::Vector3d(-2.0, 0.5, 4.0));
  const double e = energy.value(x);
  EXPECT_GT(e, 0.0);
  EXPECT_NEAR(energy.value(y), e, 1e-11 * e);
  EXPECT_LT(
      relative_error(energy_gradient(energy, y),
                     test::rigidly_moved(energy_gradient(energy, x), r, Eigen::Vector3d::Zero())),
      1e-10);
}

TEST(MidedgeBendingEnergy, WorksAtAVertexOffsetAndReusesHessianStorage) {
  std::mt19937 rng(14);
  const CurvedShell shell = curved_shell(3, rng);
  const int offset = 7, n = shell.rest.vertex_count();
  const MidedgeBendingEnergy alone(shell.rest, shell.topology, test::test_material());
  const MidedgeBendingEnergy shifted(shell.rest, shell.topology, test::test_material(), offset);
  const Eigen::VectorXd x = test::randomly_perturbed(flat(shell.rest.vertices), 0.05, rng);
  Eigen::VectorXd scene = Eigen::VectorXd::Random(3 * (n + offset + 3));
  scene.segment(3 * offset, 3 * n) = x;

  EXPECT_EQ(shifted.value(scene), alone.value(x));
  const Eigen::VectorXd g_scene = energy_gradient(shifted, scene);
  EXPECT_EQ(g_scene.segment(3 * offset, 3 * n), energy_gradient(alone, x));
  EXPECT_EQ(g_scene.head(3 * offset).norm() + g_scene.tail(9).norm(), 0.0);

  ElementMatrices blocks;
  shifted.hessian(scene, blocks);
  ASSERT_EQ(blocks.stencil_size, 6);
  ASSERT_EQ(static_cast<int>(blocks.element_count()), shifted.element_count());
  for (int v : blocks.vertices) {
    EXPECT_GE(v, offset);
    EXPECT_LT(v, offset + n);
  }
  const double* storage = blocks.values.data();
  shifted.hessian(scene, blocks);
  EXPECT_EQ(blocks.values.data(), storage);
}

TEST(MidedgeBendingEnergy, StencilsListTheFaceThenItsNeighboursAcrossEachEdge) {
  // Two triangles sharing the edge 1–2: each face has one interior edge (opposite its vertex 0
  // and 2 respectively); the boundary slots repeat the face's own corner.
  TriMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.2;
  mesh.triangles.resize(2, 3);
  mesh.triangles << 0, 1, 2, 3, 2, 1;
  const MeshTopology topology = MeshTopology::build(mesh);
  const MidedgeBendingEnergy energy(mesh, topology, test::test_material());
  ElementMatrices blocks;
  energy.hessian(flat(mesh.vertices), blocks);
  const std::vector<int> expected = {0, 1, 2, 3, 1, 2, 3, 2, 1, 0, 2, 1};
  EXPECT_EQ(blocks.vertices, expected);
}

TEST(MidedgeBendingEnergy, RejectsDegenerateRestFacesAndNonFinitePositions) {
  TriMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0.5, 0, 0, 0.5, -1, 0;  // vertex 2 on the shared edge
  mesh.triangles.resize(2, 3);
  mesh.triangles << 0, 1, 2, 1, 0, 3;
  const MeshTopology topology = MeshTopology::build(mesh);
  EXPECT_THROW(MidedgeBendingEnergy(mesh, topology, test::test_material()), InputError);

  mesh.vertices(2, 1) = 1.0;
  const MidedgeBendingEnergy energy(mesh, topology, test::test_material());
  Eigen::VectorXd x = flat(mesh.vertices);
  x[7] = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)energy.value(x), NumericalError);
}

// ---------------------------------------------------------------------------------------------
// Calibration against Kirchhoff–Love: no fitted constant, so these check the derivation.

TriMesh unit_sheet(double edge_length, bool structured) {
  SheetGenerator spec;
  spec.structured = structured;
  spec.width = 1.0;
  spec.height = 1.1;
  spec.edge_length = edge_length;
  return make_sheet(spec);
}

double mesh_area(const TriMesh& mesh) {
  double area = 0.0;
  for (int f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.triangles(f, 0));
    const Eigen::Vector3d b = mesh.vertices.row(mesh.triangles(f, 1));
    const Eigen::Vector3d c = mesh.vertices.row(mesh.triangles(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

/// Bending energy of a flat sheet (its own rest shape) moved to `mapped`, over `kirchhoff`.
const char* split_name(MidedgeSplit split) {
  return split == MidedgeSplit::halves ? "halves" : "patch fit";
}

/// Bending energy of a flat sheet (its own rest shape) moved by `map`.
template <class Map>
double mapped_energy(const TriMesh& sheet, const Material& material, MidedgeSplit split,
                     const Map& map) {
  const MidedgeBendingEnergy energy(sheet, MeshTopology::build(sheet), material, 0, split);
  Positions moved = sheet.vertices;
  for (int v = 0; v < sheet.vertex_count(); ++v)
    moved.row(v) = map(Eigen::Vector3d(sheet.vertices.row(v).transpose())).transpose();
  return energy.value(flat(moved));
}

/// Isometric wrap onto a cylinder of radius R, the sheet first turned in its plane, over the
/// Kirchhoff–Love energy (D/2)·A/R².
double cylinder_ratio(const TriMesh& sheet, MidedgeSplit split, double radius, bool along_x,
                      double turn_degrees = 0.0) {
  const Material material = test::test_material();
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(turn_degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  const double w = mapped_energy(sheet, material, split, [&](const Eigen::Vector3d& p) {
    return test::wrap_onto_cylinder(turn * p, radius, along_x);
  });
  const double ratio = w / (0.5 * bending_modulus(material) * mesh_area(sheet) / (radius * radius));
  std::cout << "[ midedge  ] " << split_name(split) << ": cylinder wrap, " << sheet.vertex_count()
            << " vertices, R " << radius << (along_x ? " around x" : " around y") << ", turned "
            << turn_degrees << " deg: W/W_KL = " << ratio << "\n";
  return ratio;
}

constexpr MidedgeSplit kSplits[] = {MidedgeSplit::halves, MidedgeSplit::patch_fit};

TEST(MidedgeCalibration, CylinderWrapOfStructuredGridsIsWithinFivePercent) {
  // Each grid triangle has exactly one edge along a generator, carrying the whole turn a/R, so
  // the energy is exact face by face except next to the two boundary generators.
  for (MidedgeSplit split : kSplits)
    for (bool along_x : {true, false})
      for (int cells : {24, 48, 96})
        for (double radius : {0.3, 1.0}) {
          const double ratio =
              cylinder_ratio(unit_sheet(1.0 / cells, true), split, radius, along_x);
          EXPECT_NEAR(ratio, 1.0, 0.05) << split_name(split) << ", " << cells << " cells";
          EXPECT_LT(ratio, 1.0);  // only the boundary deficit, never an excess
        }
}

TEST(MidedgeCalibration, PatchFitWrapsDelaunaySheetsAndTurnedGridsWithinFivePercent) {
  for (bool along_x : {true, false})
    for (double edge : {1.0 / 24, 1.0 / 48})
      EXPECT_NEAR(cylinder_ratio(unit_sheet(edge, false), MidedgeSplit::patch_fit, 1.0, along_x),
                  1.0, 0.05);
  // The hinge model gives 0.79–2.99 here (docs/bending-calibration.md).
  const TriMesh grid = unit_sheet(1.0 / 64, true);
  for (double degrees : {5.7, 22.5, 45.0, -45.0})
    EXPECT_NEAR(cylinder_ratio(grid, MidedgeSplit::patch_fit, 1.0, true, degrees), 1.0, 0.05)
        << degrees << " degrees";
}

TEST(MidedgeCalibration, HalvesAreTooStiffOnDelaunaySheetsAndTurnedGrids) {
  // The averaged split is exact only where neighbours mirror each other: pinned down here so
  // that a change of model shows up (docs/midedge-bending.md).
  for (double edge : {1.0 / 24, 1.0 / 48}) {
    const double ratio = cylinder_ratio(unit_sheet(edge, false), MidedgeSplit::halves, 1.0, false);
    EXPECT_GT(ratio, 1.08);
    EXPECT_LT(ratio, 1.2);
  }
  const TriMesh grid = unit_sheet(1.0 / 64, true);
  EXPECT_GT(cylinder_ratio(grid, MidedgeSplit::halves, 1.0, true, 45.0), 1.5);
}

TEST(MidedgeCalibration, TwistOnTheGridCostsTwoOverOneMinusNuWithHalvesAndIsExactWithPatchFit) {
  // z = τxy: κ_xy = τ, Kirchhoff–Love's density D(1 − ν)τ². On the checkerboard grid each cell's
  // diagonal folds by τa√2 and no axis edge folds (the triangles on either side share their
  // slope), so the halves put the whole twist on the diagonal: per face d = h̄·τa√2 on the
  // hypotenuse alone, W = ½ S_hyp (τa√2)² = D τ² a² per face, 2Dτ² per area whatever ν —
  // 2/(1 − ν) times Kirchhoff–Love. The true turns on the legs are ±τa²/(2h), equal and
  // opposite across each leg: the averaged split cannot see them. The patch fit is exact for
  // every constant curvature. This twist, in the saddle modes of curved shells, is what makes
  // the halves (and the hinges) too stiff on the verification benchmarks (docs/verification.md).
  const double twist = 0.01;  // slopes ≤ 0.011: the finite deflection changes W by < 1e-4
  const TriMesh sheet = unit_sheet(1.0 / 48, true);
  for (double nu : {0.0, 0.3}) {
    Material material = test::test_material();
    material.poisson_ratio = nu;
    const double kirchhoff = bending_modulus(material) * (1.0 - nu) * twist * twist * mesh_area(sheet);
    for (MidedgeSplit split : kSplits) {
      const double ratio = mapped_energy(sheet, material, split, [&](const Eigen::Vector3d& p) {
                             return Eigen::Vector3d(p.x(), p.y(), twist * p.x() * p.y());
                           }) /
                           kirchhoff;
      std::cout << "[ midedge  ] " << split_name(split) << ": twist on the grid, nu " << nu
                << ": W/W_KL = " << ratio << "\n";
      const double expected = split == MidedgeSplit::halves ? 2.0 / (1.0 - nu) : 1.0;
      EXPECT_NEAR(ratio / expected, 1.0, 0.01) << split_name(split) << ", nu " << nu;
    }
  }
}

/// An n × n grid of unit size with every cell split along the same diagonal: a lattice of
/// parallelograms, unlike the generators' checkerboard.
TriMesh uniform_diagonal_sheet(int n) {
  TriMesh mesh;
  mesh.vertices.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.vertices.row(j * (n + 1) + i) << -0.5 + double(i) / n, -0.5 + double(j) / n, 0.0;
  mesh.triangles.resize(2 * n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      mesh.triangles.row(2 * (j * n + i)) << a, b, c;
      mesh.triangles.row(2 * (j * n + i) + 1) << a, c, d;
    }
  return mesh;
}

TEST(MidedgeCalibration, HalvesAreExactForEveryConstantCurvatureOnAUniformDiagonalGrid) {
  // Two faces across an interior edge of this lattice form a parallelogram: face B is face A
  // turned by 180° about the edge's midpoint. Then d_i^B = d_i^A for every quadratic height
  // field (the three B(·) terms of docs/midedge-bending.md's d_i swap among themselves), so the
  // turn on each side is exactly half of θ_i and the halves split is exact face by face; only
  // the faces with a boundary edge deviate (by 2–3 % of the total here, both ways). The twist
  // that the checkerboard overcharges 2/(1 − ν)-fold is no exception.
  const TriMesh sheet = uniform_diagonal_sheet(48);
  Material material = test::test_material();
  material.poisson_ratio = 0.3;
  const double nu = material.poisson_ratio;
  const double curvature = 0.01;
  const Eigen::Vector3d cases[] = {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, -1, 0}, {0, 0, 1}};
  for (const Eigen::Vector3d& k : cases) {
    const double kxx = curvature * k[0], kyy = curvature * k[1], kxy = curvature * k[2];
    const double w = mapped_energy(sheet, material, MidedgeSplit::halves, [&](const Eigen::Vector3d& p) {
      return Eigen::Vector3d(p.x(), p.y(),
                             0.5 * kxx * p.x() * p.x() + 0.5 * kyy * p.y() * p.y() +
                                 kxy * p.x() * p.y());
    });
    const double trace = kxx + kyy;
    const double square = kxx * kxx + kyy * kyy + 2 * kxy * kxy;
    const double kirchhoff =
        0.5 * bending_modulus(material) * (nu * trace * trace + (1 - nu) * square);
    std::cout << "[ midedge  ] halves, uniform diagonals, curvature (" << k.transpose()
              << "): W/W_KL = " << w / kirchhoff << "\n";
    EXPECT_NEAR(w / kirchhoff, 1.0, 0.05) << k.transpose();
  }
}

TEST(MidedgeCalibration, SpherePatchCostsOnePlusNuTimesDKappaSquared) {
  // κ1 = κ2 = κ: the Kirchhoff–Love density (D/2)[(2κ)² − 2(1 − ν)κ²] = (1 + ν) D κ². The
  // vertical projection onto the sphere stretches the patch by at most ~(r/R)²/2 = 0.6%. The
  // halves split is exact on the grid only.
  const double radius = 5.0;
  for (MidedgeSplit split : kSplits)
    for (bool structured : {true, false}) {
      if (split == MidedgeSplit::halves && !structured) continue;
      for (double nu : {0.0, 0.3, -0.5}) {
        Material material = test::test_material();
        material.poisson_ratio = nu;
        const TriMesh sheet = unit_sheet(1.0 / 48, structured);
        const double w = mapped_energy(sheet, material, split, [&](const Eigen::Vector3d& p) {
          return Eigen::Vector3d(
              p.x(), p.y(), radius - std::sqrt(radius * radius - p.x() * p.x() - p.y() * p.y()));
        });
        const double ratio =
            w / ((1.0 + nu) * bending_modulus(material) * mesh_area(sheet) / (radius * radius));
        std::cout << "[ midedge  ] " << split_name(split) << ": sphere patch, "
                  << (structured ? "grid" : "Delaunay") << ", nu " << nu << ": W/W_KL = " << ratio
                  << "\n";
        EXPECT_NEAR(ratio, 1.0, 0.05) << split_name(split) << (structured ? " grid" : " Delaunay");
      }
    }
}

// ---------------------------------------------------------------------------------------------
// A curved rest shape: Rayleigh's inextensional mode of a spherical zone, against Koiter's
// bending energy evaluated from the smooth surface.

/// The zone of the pinched hemisphere (docs/verification.md): R = 10, polar angle 18°–90°.
constexpr double kZoneRadius = 10.0;
constexpr double kZonePolarMin = 18.0 * std::numbers::pi / 180.0;
constexpr double kZonePolarMax = 0.5 * std::numbers::pi;

Eigen::Vector3d zone_point(double polar, double azimuth) {
  return kZoneRadius * Eigen::Vector3d(std::sin(polar) * std::cos(azimuth),
                                       std::sin(polar) * std::sin(azimuth), std::cos(polar));
}

/// Rayleigh's inextensional mode n = 2 of a sphere, the pinching mode of the hemisphere:
/// f = tan²(φ/2), u = f [sin φ cos 2ϑ e_φ + sin φ sin 2ϑ e_ϑ − (2 + cos φ) cos 2ϑ e_r].
Eigen::Vector3d rayleigh_mode(double polar, double azimuth) {
  const Eigen::Vector3d e_polar(std::cos(polar) * std::cos(azimuth),
                                std::cos(polar) * std::sin(azimuth), -std::sin(polar));
  const Eigen::Vector3d e_azimuth(-std::sin(azimuth), std::cos(azimuth), 0.0);
  const double f = std::pow(std::tan(0.5 * polar), 2);
  return f * (std::sin(polar) * std::cos(2 * azimuth) * e_polar +
              std::sin(polar) * std::sin(2 * azimuth) * e_azimuth -
              (2.0 + std::cos(polar)) * std::cos(2 * azimuth) * zone_point(polar, azimuth) /
                  kZoneRadius);
}

struct KoiterEnergies {
  double bending, membrane;  ///< per squared amplitude
};

/// Koiter's energies of the displacement amplitude·rayleigh_mode on the smooth zone: the first
/// and second fundamental forms of the displaced surface by central differences in (φ, ϑ), their
/// changes by central differences in the amplitude, integrated by the midpoint rule.
KoiterEnergies koiter_energies(const Material& material) {
  const double step = 1e-3, amplitude = 1e-3;
  const auto forms = [&](double polar, double azimuth, double scale, Eigen::Matrix2d& a,
                         Eigen::Matrix2d& b) {
    const auto x = [&](double p, double t) -> Eigen::Vector3d {
      return zone_point(p, t) + scale * rayleigh_mode(p, t);
    };
    const Eigen::Vector3d x0 = x(polar, azimuth);
    const Eigen::Vector3d xp = (x(polar + step, azimuth) - x(polar - step, azimuth)) / (2 * step);
    const Eigen::Vector3d xt = (x(polar, azimuth + step) - x(polar, azimuth - step)) / (2 * step);
    const Eigen::Vector3d xpp =
        (x(polar + step, azimuth) - 2 * x0 + x(polar - step, azimuth)) / (step * step);
    const Eigen::Vector3d xtt =
        (x(polar, azimuth + step) - 2 * x0 + x(polar, azimuth - step)) / (step * step);
    const Eigen::Vector3d xpt =
        (x(polar + step, azimuth + step) - x(polar + step, azimuth - step) -
         x(polar - step, azimuth + step) + x(polar - step, azimuth - step)) /
        (4 * step * step);
    const Eigen::Vector3d n = xp.cross(xt).normalized();
    a << xp.dot(xp), xp.dot(xt), xp.dot(xt), xt.dot(xt);
    b << xpp.dot(n), xpt.dot(n), xpt.dot(n), xtt.dot(n);
  };
  const double nu = material.poisson_ratio;
  const double stretching =
      material.youngs_modulus * material.thickness / (1.0 - nu * nu);
  const auto density = [nu](const Eigen::Matrix2d& m) {
    return 0.5 * (nu * m.trace() * m.trace() + (1.0 - nu) * (m * m).trace());
  };
  const int rows = 200, columns = 400;
  const double d_polar = (kZonePolarMax - kZonePolarMin) / rows;
  const double d_azimuth = 2.0 * std::numbers::pi / columns;
  KoiterEnergies w{0.0, 0.0};
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < columns; ++j) {
      const double polar = kZonePolarMin + (i + 0.5) * d_polar;
      const double azimuth = (j + 0.5) * d_azimuth;
      Eigen::Matrix2d a, b, a_plus, b_plus, a_minus, b_minus;
      forms(polar, azimuth, 0.0, a, b);
      forms(polar, azimuth, amplitude, a_plus, b_plus);
      forms(polar, azimuth, -amplitude, a_minus, b_minus);
      const Eigen::Matrix2d a_inv = a.inverse();
      const double area = std::sqrt(a.determinant()) * d_polar * d_azimuth;
      w.bending += area * bending_modulus(material) *
                   density(a_inv * (b_plus - b_minus) / (2 * amplitude));
      w.membrane += area * stretching * density(0.25 * a_inv * (a_plus - a_minus) / amplitude);
    }
  return w;
}

/// The pinched hemisphere's material (R/h = 250, docs/verification.md).
Material hemisphere_material() {
  Material material = test::test_material();
  material.youngs_modulus = 6.825e7;
  material.poisson_ratio = 0.3;
  material.thickness = 0.04;
  return material;
}

/// The zone's vertices moved by amplitude·rayleigh_mode.
Eigen::VectorXd moved_by_mode(const TriMesh& zone, double amplitude) {
  Eigen::VectorXd x = flat(zone.vertices);
  for (int v = 0; v < zone.vertex_count(); ++v) {
    const Eigen::Vector3d p = zone.vertices.row(v).transpose();
    x.segment<3>(3 * v) +=
        amplitude * rayleigh_mode(std::acos(p.z() / kZoneRadius), std::atan2(p.y(), p.x()));
  }
  return x;
}

TEST(CurvedRestBending, SphereInextensionalModeIsKoiterWithPatchFitAndTwiceItWithHalvesOrHinges) {
  // On a sphere every inextensional change of curvature is a pure saddle (δK = 0 makes it
  // traceless), whose axes turn against the grid lines over the zone: where they are at 45°
  // it is the twist that the halves and the hinges charge 2/(1 − ν) times (the TwistOnTheGrid
  // tests), where they follow the grid lines it is charged right. Integrated over the
  // zone that is about twice Koiter's energy, and it does not shrink with refinement (edge 0.5,
  // 0.25, 0.125: halves 1.97, 1.98, 1.99; hinges 2.17, 2.18, 2.20; patch fit 0.985, 0.992,
  // 0.996) — the pinched hemisphere's −49 % and −53 % (docs/verification.md).
  const Material material = hemisphere_material();
  const KoiterEnergies koiter = koiter_energies(material);
  ASSERT_LT(koiter.membrane, 1e-6 * koiter.bending);  // the mode is inextensional

  SphericalPanelGenerator spec;
  spec.radius = kZoneRadius;
  spec.polar_min_degrees = 18.0;
  spec.polar_max_degrees = 90.0;
  spec.edge_length = 0.5;
  const TriMesh zone = make_spherical_panel(spec);
  const MeshTopology topology = MeshTopology::build(zone);
  const double amplitude = 1e-5;
  const Eigen::VectorXd x = moved_by_mode(zone, amplitude);
  const auto ratio = [&](double energy) {
    return energy / (amplitude * amplitude) / koiter.bending;
  };
  const double patch_fit =
      ratio(MidedgeBendingEnergy(zone, topology, material, 0, MidedgeSplit::patch_fit).value(x));
  const double halves =
      ratio(MidedgeBendingEnergy(zone, topology, material, 0, MidedgeSplit::halves).value(x));
  const double hinges = ratio(BendingEnergy(zone, topology, material).value(x));
  std::cout << "[ curved   ] sphere mode n = 2, edge 0.5: W/W_Koiter = " << patch_fit
            << " (patch fit), " << halves << " (halves), " << hinges << " (hinges)\n";
  EXPECT_NEAR(patch_fit, 1.0, 0.03);
  EXPECT_GT(halves, 1.9);
  EXPECT_LT(halves, 2.1);
  EXPECT_GT(hinges, 2.0);
  EXPECT_LT(hinges, 2.3);
}

/// The zone as a latitude–longitude grid with every cell split along the same diagonal, about
/// `edge` long along both grid directions at the equator.
TriMesh uniform_diagonal_zone(double edge) {
  const int columns = 4 * static_cast<int>(std::ceil(2 * std::numbers::pi * kZoneRadius / edge / 4));
  const int rows =
      2 * static_cast<int>(std::ceil(kZoneRadius * (kZonePolarMax - kZonePolarMin) / edge / 2));
  TriMesh mesh;
  mesh.vertices.resize(columns * (rows + 1), 3);
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i < columns; ++i)
      mesh.vertices.row(j * columns + i) =
          zone_point(kZonePolarMax - (kZonePolarMax - kZonePolarMin) * j / rows,
                     2 * std::numbers::pi * i / columns)
              .transpose();
  mesh.triangles.resize(2 * columns * rows, 3);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      const int a = j * columns + i, b = j * columns + (i + 1) % columns;
      const int c = b + columns, d = a + columns;
      mesh.triangles.row(2 * (j * columns + i)) << a, b, c;
      mesh.triangles.row(2 * (j * columns + i) + 1) << a, c, d;
    }
  return mesh;
}

TEST(CurvedRestBending, SphereInextensionalModeIsKoiterWithHalvesOnUniformDiagonals) {
  // The same zone and mode with one diagonal direction throughout: every pair of faces across
  // an edge is a parallelogram up to the cells' taper, the halves split is exact for every
  // constant curvature (HalvesAreExactFor... above), and the twist excess is gone (1.017 at
  // edge 0.5, against 1.97 on the checkerboard).
  const Material material = hemisphere_material();
  const double koiter = koiter_energies(material).bending;
  const TriMesh zone = uniform_diagonal_zone(0.5);
  const double amplitude = 1e-5;
  const double ratio =
      MidedgeBendingEnergy(zone, MeshTopology::build(zone), material)
          .value(moved_by_mode(zone, amplitude)) /
      (amplitude * amplitude) / koiter;
  std::cout << "[ curved   ] sphere mode n = 2, uniform diagonals, edge 0.5: W/W_Koiter = "
            << ratio << " (halves)\n";
  EXPECT_NEAR(ratio, 1.0, 0.03);
}

}  // namespace
}  // namespace psq
