#pragma once
// Meshes, states and matrix helpers shared by the elastic tests (dense_hessian comes from
// support/derivative_check.hpp).

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "engine/elastic/dihedral_angle.hpp"
#include "engine/elastic/material.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"
#include "engine/mesh/tri_mesh.hpp"
#include "support/derivative_check.hpp"

namespace psq::test {

/// A steel-like sheet: the tests compare relative quantities, so only the ratios matter.
inline Material test_material() {
  Material m;
  m.youngs_modulus = 2e6;
  m.poisson_ratio = 0.3;
  m.thickness = 1e-3;
  return m;
}

/// Maps the plane z = 0 isometrically onto the cylinder of radius R whose axis is parallel to
/// y (wrap_along_x) or to x, touching the plane along that axis: arc length along the wrapped
/// coordinate is preserved and z is moved along the cylinder's normal.
inline Eigen::Vector3d wrap_onto_cylinder(const Eigen::Vector3d& p, double radius,
                                          bool wrap_along_x = true) {
  const double u = wrap_along_x ? p.x() : p.y();
  const double r = radius - p.z();
  const double along = r * std::sin(u / radius);
  const double height = radius - r * std::cos(u / radius);
  return wrap_along_x ? Eigen::Vector3d(along, p.y(), height)
                      : Eigen::Vector3d(p.x(), along, height);
}

/// A curved, irregular rest shape: a unit structured sheet of cells×cells squares whose
/// vertices are jittered (in plane and off plane, by `jitter` edge lengths), then wrapped onto
/// a cylinder of radius 0.6.
inline TriMesh curved_sheet(int cells, double jitter, std::mt19937& rng) {
  SheetGenerator spec;
  spec.structured = true;
  spec.edge_length = 1.0 / cells;
  TriMesh mesh = make_structured_sheet(spec);
  std::uniform_real_distribution<double> noise(-jitter / cells, jitter / cells);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    Eigen::Vector3d p = mesh.vertices.row(v).transpose();
    p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    mesh.vertices.row(v) = wrap_onto_cylinder(p, 0.6).transpose();
  }
  return mesh;
}

/// A curved_sheet (jitter 0.3) with its topology, for the bending energies.
struct CurvedShell {
  TriMesh rest;
  MeshTopology topology;
};

inline CurvedShell curved_shell(int cells, std::mt19937& rng) {
  CurvedShell s{curved_sheet(cells, 0.3, rng), {}};
  s.topology = MeshTopology::build(s.rest);
  return s;
}

/// x plus independent uniform noise in [−amplitude, amplitude] on every coordinate.
inline Eigen::VectorXd randomly_perturbed(const Eigen::VectorXd& x, double amplitude,
                                          std::mt19937& rng) {
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  Eigen::VectorXd y = x;
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += noise(rng);
  return y;
}

inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

/// Applies p ↦ R p + t to every vertex of a flat position vector.
inline Eigen::VectorXd rigidly_moved(const Eigen::VectorXd& x, const Eigen::Matrix3d& rotation,
                                     const Eigen::Vector3d& translation) {
  Eigen::VectorXd y(x.size());
  for (Eigen::Index v = 0; v < x.size() / 3; ++v)
    y.segment<3>(3 * v) = rotation * x.segment<3>(3 * v) + translation;
  return y;
}

/// A hinge folded by `fold` radians: the edge x0→x1 on the x axis, face 0 in the plane z = 0
/// with normal +z, and x3 turned about the edge from its flat position (0.7, −0.9, 0), away
/// from the normal for fold > 0. Then moved by a random rigid motion.
inline HingePositions folded_hinge(double fold, std::mt19937& rng) {
  HingePositions x;
  x.col(0) << 0.0, 0.0, 0.0;
  x.col(1) << 1.1, 0.0, 0.0;
  x.col(2) << 0.4, 0.8, 0.0;
  x.col(3) << 0.7, -0.9 * std::cos(fold), -0.9 * std::sin(fold);
  return (random_rotation(rng) * x).colwise() + Eigen::Vector3d(0.3, -1.2, 2.0);
}

/// Fold angles from nearly flat to strongly folded, of both signs.
inline constexpr double kFolds[] = {-3.0, -1.2, -1e-4, 0.0, 1e-4, 0.7, 3.0};

/// Smallest eigenvalue of a symmetric matrix.
inline double min_eigenvalue(const Eigen::MatrixXd& symmetric) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(symmetric, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .minCoeff();
}

}  // namespace psq::test
