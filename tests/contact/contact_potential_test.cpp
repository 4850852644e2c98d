// The contact potential over a whole surface: derivatives against finite differences (point–
// triangle and mollified edge–edge pairs together), PSD projection, the CCD-safe step, and the
// skips with their counters.

#include "engine/contact/contact_potential.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"
#include "support/derivative_check.hpp"
#include "support/finite_difference.hpp"

namespace psq {
namespace {

constexpr double kActivation = 1e-3;

/// Two 3 cm square structured sheets (1 cm edges), the upper one `gap` above the lower and
/// shifted by (0.3, 0.4) cm, as two bodies of one surface.
struct TwoSheets {
  ContactSurface surface;
  Eigen::VectorXd x;
  int lower_vertices = 0;
};

TwoSheets two_sheets(double gap) {
  SheetGenerator spec;
  spec.width = spec.height = 0.03;
  spec.edge_length = 0.01;
  spec.structured = true;
  const TriMesh sheet = make_structured_sheet(spec);
  const MeshTopology topology = MeshTopology::build(sheet);
  const int n = sheet.vertex_count();
  TwoSheets out;
  out.lower_vertices = n;
  Positions positions(2 * n, 3);
  positions.topRows(n) = sheet.vertices;
  positions.bottomRows(n) = sheet.vertices.rowwise() + Eigen::RowVector3d(0.003, 0.004, gap);
  out.surface.triangles.resize(2 * sheet.triangle_count(), 3);
  out.surface.triangles.topRows(sheet.triangle_count()) = sheet.triangles;
  out.surface.triangles.bottomRows(sheet.triangle_count()) = sheet.triangles.array() + n;
  for (int copy = 0; copy < 2; ++copy)
    for (const auto& e : topology.edges)
      out.surface.edges.push_back({e[0] + copy * n, e[1] + copy * n});
  out.surface.vertex_body.assign(2 * n, 0);
  std::fill(out.surface.vertex_body.begin() + n, out.surface.vertex_body.end(), 1);
  out.surface.may_touch = [](int a, int b) { return a != b; };
  out.surface.rest = positions;
  out.x = flat(positions);
  return out;
}

ContactParameters parameters(bool skip = true) {
  ContactParameters p;
  p.band.activation_distance = kActivation;
  p.skip_when_apart = skip;
  return p;
}

/// The two sheets 0.6 d̂ apart with out-of-plane noise of 0.15 d̂: every sub-case of both pair
/// kinds within reach, nearly parallel edges among them.
TwoSheets sheets_in_contact() {
  TwoSheets sheets = two_sheets(0.6 * kActivation);
  std::srand(11);
  for (Eigen::Index v = 0; v < sheets.x.size() / 3; ++v)
    sheets.x[3 * v + 2] += 0.15 * kActivation * Eigen::VectorXd::Random(1)[0];
  return sheets;
}

TEST(ContactPotential, GradientAndHessianMatchFiniteDifferences) {
  TwoSheets sheets = sheets_in_contact();
  ContactPotential contact(sheets.surface, parameters());
  contact.set_stiffness(1e3);
  const auto& pairs = contact.active_pairs(sheets.x);
  const auto edge_edge =
      std::count_if(pairs.begin(), pairs.end(), [](const ContactPair& p) { return p.edge_edge; });
  ASSERT_GT(edge_edge, 0);
  ASSERT_LT(static_cast<std::size_t>(edge_edge), pairs.size());
  // Some edge–edge pair is nearly parallel, inside the mollifier's band.
  bool mollified = false;
  for (const ContactPair& p : pairs) {
    if (!p.edge_edge) continue;
    const auto at = [&](int k) -> Eigen::Vector3d {
      return sheets.x.segment<3>(3 * p.vertices[k]);
    };
    mollified |= (at(1) - at(0)).cross(at(3) - at(2)).squaredNorm() < p.mollifier_threshold;
  }
  EXPECT_TRUE(mollified);

  const double value = contact.value(sheets.x);
  ASSERT_GT(value, 0.0);
  ASSERT_TRUE(std::isfinite(value));
  Eigen::VectorXd g = Eigen::VectorXd::Zero(sheets.x.size());
  contact.add_gradient(sheets.x, g);
  const auto energy = [&](const Eigen::VectorXd& y) { return contact.value(y); };
  EXPECT_LT(test::relative_error(g, test::fd_gradient(energy, sheets.x, 1e-9)), 1e-5);

  ElementMatrices blocks;
  contact.hessian(sheets.x, blocks, false);
  const Eigen::MatrixXd hessian = test::dense_hessian(blocks, sheets.x.size());
  const Eigen::MatrixXd fd = test::fd_jacobian(
      [&](const Eigen::VectorXd& y) {
        Eigen::VectorXd gy = Eigen::VectorXd::Zero(y.size());
        contact.add_gradient(y, gy);
        return gy;
      },
      sheets.x, 1e-9);
  EXPECT_LT(test::relative_error(hessian, fd), 1e-4);
}

TEST(ContactPotential, ProjectedBlocksArePositiveSemiDefinite) {
  TwoSheets sheets = sheets_in_contact();
  ContactPotential contact(sheets.surface, parameters());
  ElementMatrices blocks;
  contact.hessian(sheets.x, blocks);
  ASSERT_GT(blocks.element_count(), 0u);
  for (std::size_t e = 0; e < blocks.element_count(); ++e) {
    const Eigen::MatrixXd h = blocks.block(e);
    const double smallest =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(h).eigenvalues().minCoeff();
    EXPECT_GE(smallest, -1e-9 * h.norm());
  }
}

TEST(ContactPotential, BarrierGrowsWithoutBoundAsTheGapCloses) {
  double previous = 0.0;
  for (double gap : {0.9, 0.5, 0.1, 1e-3, 1e-6}) {
    TwoSheets sheets = two_sheets(gap * kActivation);
    ContactPotential contact(sheets.surface, parameters());
    const double value = contact.value(sheets.x);
    EXPECT_GT(value, previous) << gap;
    previous = value;
  }
  TwoSheets touching = two_sheets(0.0);
  ContactPotential contact(touching.surface, parameters());
  EXPECT_EQ(contact.value(touching.x), std::numeric_limits<double>::infinity());
}

TEST(ContactPotential, SkipsTheBarrierWhenNothingIsWithinReach) {
  TwoSheets apart = two_sheets(3 * kActivation);
  for (bool skip : {true, false}) {
    ContactPotential contact(apart.surface, parameters(skip));
    EXPECT_EQ(contact.value(apart.x), 0.0);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(apart.x.size());
    contact.add_gradient(apart.x, g);  // same state: the active set is reused
    EXPECT_TRUE(g.isZero(0.0));
    EXPECT_EQ(contact.stats().barrier_evaluations, 1);
    EXPECT_EQ(contact.stats().barrier_skips, skip ? 1 : 0);
  }
  TwoSheets near = two_sheets(0.5 * kActivation);
  ContactPotential contact(near.surface, parameters());
  EXPECT_GT(contact.value(near.x), 0.0);
  EXPECT_EQ(contact.stats().barrier_skips, 0);
}

TEST(ContactPotential, FeasibleStepStopsAHeadOnApproachBeforeContact) {
  TwoSheets sheets = two_sheets(2 * kActivation);
  ContactPotential contact(sheets.surface, parameters());
  // The upper sheet moves 5 mm down, through the lower one.
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(sheets.x.size());
  for (Eigen::Index v = sheets.lower_vertices; v < sheets.x.size() / 3; ++v) dx[3 * v + 2] = -5e-3;
  const auto intersecting = [&](const Eigen::VectorXd& y) {
    return !find_intersections(as_positions(y), sheets.surface.triangles).clean();
  };
  ASSERT_TRUE(intersecting(sheets.x + 0.4 * dx));  // the full step passes through the lower sheet
  const double alpha = contact.max_feasible_step(sheets.x, dx);
  EXPECT_GT(alpha, 0.0);
  EXPECT_LT(alpha, 2 * kActivation / 5e-3);  // before the sheets meet at α = 0.4
  EXPECT_FALSE(intersecting(sheets.x + alpha * dx));
  EXPECT_GT(contact.min_distance(sheets.x + alpha * dx), 0.0);
  EXPECT_EQ(contact.stats().ccd_skips, 0);
  EXPECT_GT(contact.stats().ccd_pair_queries, 0);
}

TEST(ContactPotential, SkipsTheCcdWhenNothingComesWithinReach) {
  TwoSheets sheets = two_sheets(5 * kActivation);
  // A sideways slide keeps the sheets 5 d̂ apart throughout.
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(sheets.x.size());
  for (Eigen::Index v = sheets.lower_vertices; v < sheets.x.size() / 3; ++v) dx[3 * v] = 0.02;
  for (bool skip : {true, false}) {
    ContactPotential contact(sheets.surface, parameters(skip));
    EXPECT_EQ(contact.max_feasible_step(sheets.x, dx), 1.0);
    EXPECT_EQ(contact.stats().ccd_evaluations, 1);
    EXPECT_EQ(contact.stats().ccd_skips, skip ? 1 : 0);
  }
}

TEST(ContactPotential, RejectsBadParameters) {
  TwoSheets sheets = two_sheets(kActivation);
  ContactParameters bad = parameters();
  bad.band.activation_distance = 0;
  EXPECT_THROW(ContactPotential(sheets.surface, bad), InputError);
  bad = parameters();
  bad.ccd.ratio_bound = 1.0;
  EXPECT_THROW(ContactPotential(sheets.surface, bad), InputError);
}

}  // namespace
}  // namespace psq
