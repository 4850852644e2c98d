// The contact potential over a whole surface: derivatives against finite differences (point–
// triangle and mollified edge–edge pairs together), PSD projection, the CCD-safe step, and the
// skips with their counters.

#include "engine/contact/contact_potential.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "engine/contact/intersection_check.hpp"
#include "engine/core/error.hpp"
#include "engine/core/psd_projection.hpp"
#include "engine/mesh/generators.hpp"
#include "engine/mesh/topology.hpp"
#include "support/derivative_check.hpp"
#include "support/finite_difference.hpp"
#include "support/random_geometry.hpp"

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

// With the lower sheet fixed (a collider), each block is the exact pair Hessian's block over
// the moving vertices, projected, and nothing on the fixed rows.
TEST(ContactPotential, ProjectsEachBlockOverTheVerticesThatMove) {
  TwoSheets sheets = sheets_in_contact();
  const int n = static_cast<int>(sheets.x.size() / 3);
  std::vector<bool> fixed(n, false);
  std::fill_n(fixed.begin(), sheets.lower_vertices, true);
  ContactPotential contact(sheets.surface, parameters());
  ElementMatrices exact, projected;
  contact.hessian(sheets.x, exact, false);
  contact.hessian(sheets.x, projected, true, fixed);
  ASSERT_EQ(projected.element_count(), exact.element_count());
  ASSERT_GT(projected.element_count(), 0u);
  int clamped = 0;
  for (std::size_t e = 0; e < exact.element_count(); ++e) {
    Eigen::MatrixXd reference = exact.block(e);
    for (int i = 0; i < 4; ++i)
      if (fixed[projected.vertices[4 * e + i]]) {
        reference.middleRows<3>(3 * i).setZero();
        reference.middleCols<3>(3 * i).setZero();
      }
    const Eigen::MatrixXd unprojected = reference;
    project_to_psd(reference);
    if ((reference - unprojected).norm() > 1e-9 * unprojected.norm()) ++clamped;
    EXPECT_LE((Eigen::MatrixXd(projected.block(e)) - reference).norm(), 1e-9 * reference.norm())
        << "pair " << e;
  }
  EXPECT_GT(clamped, 0) << "no block was indefinite: the test would not see a wrong projection";
  std::vector<bool> too_few(n - 1, false);
  EXPECT_THROW(contact.hessian(sheets.x, projected, true, too_few), std::invalid_argument);
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

// With the lower sheet and half the upper one held, the potential keeps exactly the pairs with
// a moving vertex, and its gradient on the moving vertices is the whole potential's.
TEST(ContactPotential, LeavesOutThePairsOfHeldVerticesOnly) {
  TwoSheets sheets = sheets_in_contact();
  const int n = static_cast<int>(sheets.x.size() / 3);
  ContactSurface held_surface = sheets.surface;
  held_surface.held.assign(n, true);
  for (int v = sheets.lower_vertices; v < n; v += 2) held_surface.held[v] = false;
  ContactPotential whole(sheets.surface, parameters());
  ContactPotential partly_held(held_surface, parameters());

  const auto moves = [&](const ContactPair& pair) {
    return std::any_of(pair.vertices.begin(), pair.vertices.end(),
                       [&](int v) { return !held_surface.held[v]; });
  };
  const std::vector<ContactPair>& all = whole.active_pairs(sheets.x);
  const auto expected = std::count_if(all.begin(), all.end(), moves);
  ASSERT_GT(expected, 0);
  ASSERT_LT(expected, static_cast<long>(all.size()));  // some pairs are of held vertices only
  const std::vector<ContactPair>& kept = partly_held.active_pairs(sheets.x);
  EXPECT_EQ(static_cast<long>(kept.size()), expected);
  EXPECT_TRUE(std::all_of(kept.begin(), kept.end(), moves));

  Eigen::VectorXd g_whole = Eigen::VectorXd::Zero(sheets.x.size());
  Eigen::VectorXd g_held = g_whole;
  whole.add_gradient(sheets.x, g_whole);
  partly_held.add_gradient(sheets.x, g_held);
  for (int v = 0; v < n; ++v) {
    if (held_surface.held[v]) continue;
    EXPECT_LE((g_held.segment<3>(3 * v) - g_whole.segment<3>(3 * v)).norm(),
              1e-12 * g_whole.segment<3>(3 * v).norm() + 1e-300)
        << "vertex " << v;
  }
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

/// The upper sheet (body 1) of `sheets` moved by `offset`, the lower one left in place.
Eigen::VectorXd upper_moved(const TwoSheets& sheets, const Eigen::Vector3d& offset) {
  Eigen::VectorXd x = sheets.x;
  for (Eigen::Index v = sheets.lower_vertices; v < x.size() / 3; ++v) x.segment<3>(3 * v) += offset;
  return x;
}

TEST(ContactPotential, CertificateAnswersStatesAndStepsNearItsReference) {
  // Parallel sheets 5 d̂ apart, nothing else in reach: the certificate radius is (5 − 1) d̂ / 2.
  const TwoSheets sheets = two_sheets(5 * kActivation);
  ContactPotential contact(sheets.surface, parameters());
  EXPECT_EQ(contact.value(sheets.x), 0.0);
  EXPECT_EQ(contact.stats().certificate_renewals, 1);
  EXPECT_NEAR(contact.certificate().radius, 2 * kActivation, 1e-12);

  // Within the radius: no broad phase, no barrier, no CCD.
  const Eigen::VectorXd near_reference = upper_moved(sheets, {0.0, 0.0, -1.9 * kActivation});
  EXPECT_EQ(contact.value(near_reference), 0.0);
  const Eigen::VectorXd slide = upper_moved(sheets, {0.5 * kActivation, 0.0, 0.0}) - sheets.x;
  EXPECT_EQ(contact.max_feasible_step(near_reference, slide), 1.0);
  EXPECT_EQ(contact.stats().barrier_evaluations, 2);
  EXPECT_EQ(contact.stats().barrier_certified, 1);
  EXPECT_EQ(contact.stats().ccd_certified, 1);
  EXPECT_EQ(contact.stats().certificate_renewals, 1);

  // A step ending outside the radius is not the certificate's to answer, though it is safe.
  const Eigen::VectorXd long_slide = upper_moved(sheets, {0.02, 0.0, 0.0}) - sheets.x;
  EXPECT_EQ(contact.max_feasible_step(near_reference, long_slide), 1.0);
  EXPECT_EQ(contact.stats().ccd_certified, 1);
  EXPECT_EQ(contact.stats().ccd_skips, 2);
}

TEST(ContactPotential, CertificateIsRenewedWhereAStateLeavesIt) {
  const TwoSheets sheets = two_sheets(9 * kActivation);
  ContactPotential contact(sheets.surface, parameters());
  EXPECT_EQ(contact.value(sheets.x), 0.0);
  EXPECT_NEAR(contact.certificate().radius, 4 * kActivation, 1e-12);
  // 5 d̂ down leaves the first certificate; 3 d̂ apart, the new one has radius d̂.
  const Eigen::VectorXd lower = upper_moved(sheets, {0.0, 0.0, -6 * kActivation});
  EXPECT_EQ(contact.value(lower), 0.0);
  EXPECT_EQ(contact.stats().certificate_renewals, 2);
  EXPECT_EQ(contact.stats().barrier_certified, 0);
  EXPECT_EQ(contact.certificate().reference, lower);
  EXPECT_NEAR(contact.certificate().radius, kActivation, 1e-12);
}

TEST(ContactPotential, CertificateDoesNotHoldWhenPairsAreNear) {
  // 3 d̂ apart: radius d̂. Then 2.5 d̂ down, beyond the radius and into reach.
  const TwoSheets sheets = two_sheets(3 * kActivation);
  ContactPotential contact(sheets.surface, parameters());
  ContactPotential reference(sheets.surface, parameters(false));
  EXPECT_EQ(contact.value(sheets.x), 0.0);
  const Eigen::VectorXd near = upper_moved(sheets, {0.0, 0.0, -2.5 * kActivation});
  EXPECT_FALSE(contact.certificate().covers(near));
  EXPECT_GT(contact.value(near), 0.0);
  EXPECT_NEAR(contact.value(near), reference.value(near), 1e-12 * reference.value(near));
  EXPECT_EQ(contact.active_pairs(near).size(), reference.active_pairs(near).size());
  EXPECT_EQ(contact.stats().barrier_certified, 0);
  EXPECT_EQ(contact.stats().certificate_renewals, 1);
  // A surface that starts within reach gets no certificate.
  const TwoSheets touching = two_sheets(0.5 * kActivation);
  ContactPotential in_contact(touching.surface, parameters());
  EXPECT_GT(in_contact.value(touching.x), 0.0);
  EXPECT_LT(in_contact.certificate().radius, 0.0);
  EXPECT_EQ(in_contact.stats().certificate_renewals, 0);
}

/// A random motion of every vertex: coordinates uniform in [−size, size].
Eigen::VectorXd random_motion(Eigen::Index size_of_x, double size, std::mt19937& rng) {
  Eigen::VectorXd dx(size_of_x);
  for (Eigen::Index i = 0; i < size_of_x; i += 3) dx.segment<3>(i) = size * test::random_point(rng);
  return dx;
}

void expect_same_pairs(const std::vector<ContactPair>& a, const std::vector<ContactPair>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].vertices, b[k].vertices);
    EXPECT_EQ(a[k].edge_edge, b[k].edge_edge);
  }
}

TEST(ContactPotential, SkipsChangeNothingAlongRandomMotions) {
  // Noisy sheets 6 d̂ apart, pushed together by random motions (small ones like late Newton
  // steps, large ones like early ones) plus a downward drift of the upper sheet, each step cut
  // to the CCD-safe fraction: states far apart, approaching and in contact.
  ContactStats with_skips;
  int longer_steps = 0;
  for (const unsigned seed : {3u, 5u, 8u}) {
    std::mt19937 rng(seed);
    TwoSheets sheets = two_sheets(6 * kActivation);
    for (Eigen::Index i = 2; i < sheets.x.size(); i += 3)
      sheets.x[i] += 0.3 * kActivation * test::random_point(rng).z();
    ContactParameters with_thickness = parameters();
    with_thickness.band.thickness = 0.2 * kActivation;
    ContactPotential skipping(sheets.surface, with_thickness);
    with_thickness.skip_when_apart = false;
    ContactPotential searching(sheets.surface, with_thickness);
    ContactPotential checking(sheets.surface, with_thickness);
    skipping.set_stiffness(1e3);
    searching.set_stiffness(1e3);
    const Eigen::VectorXd drift = upper_moved(sheets, {0.0, 0.0, -0.3 * kActivation}) - sheets.x;
    std::uniform_real_distribution<double> size_exponent(-2.0, 0.5);
    Eigen::VectorXd x = sheets.x;
    for (int step = 0; step < 60; ++step) {
      expect_same_pairs(skipping.active_pairs(x), searching.active_pairs(x));
      const double value = searching.value(x);
      EXPECT_NEAR(skipping.value(x), value, 1e-12 * value) << step;
      Eigen::VectorXd g_skipping = Eigen::VectorXd::Zero(x.size());
      Eigen::VectorXd g_searching = Eigen::VectorXd::Zero(x.size());
      skipping.add_gradient(x, g_skipping);
      searching.add_gradient(x, g_searching);
      EXPECT_EQ(g_skipping, g_searching) << step;

      const double size = kActivation * std::pow(10.0, size_exponent(rng));
      const Eigen::VectorXd dx = drift + random_motion(x.size(), size, rng);
      const long skips_before = skipping.stats().ccd_skips;
      const double alpha_skipping = skipping.max_feasible_step(x, dx);
      const double alpha_searching = searching.max_feasible_step(x, dx);
      if (skipping.stats().ccd_skips == skips_before) {
        EXPECT_EQ(alpha_skipping, alpha_searching) << step;
      } else {
        // A skipped step is the whole step, and nothing comes within reach along it (the
        // CCD's ratio bound may still cut a fast approach of pairs far apart).
        EXPECT_EQ(alpha_skipping, 1.0);
        EXPECT_GE(alpha_skipping, alpha_searching);
        longer_steps += alpha_skipping > alpha_searching;
        for (double t = 0; t <= 1.0; t += 0.125)
          EXPECT_TRUE(checking.active_pairs(x + t * dx).empty()) << step << " " << t;
      }
      // A line-search trial at half the step, then the step itself (CCD-safe for both).
      const double alpha = 0.9 * std::min(alpha_skipping, alpha_searching);
      EXPECT_NEAR(skipping.value(x + 0.5 * alpha * dx), searching.value(x + 0.5 * alpha * dx),
                  1e-12 * searching.value(x + 0.5 * alpha * dx));
      x += alpha * dx;
    }
    EXPECT_GT(searching.stats().max_active_pairs, 0);
    with_skips += skipping.stats();
  }
  // Every kind of state was met: certified ones, renewals, and searches in contact.
  EXPECT_GT(with_skips.barrier_certified, 0);
  EXPECT_GT(with_skips.ccd_certified, 0);
  EXPECT_GT(with_skips.certificate_renewals, 3);
  EXPECT_LT(with_skips.barrier_skips, with_skips.barrier_evaluations);
  std::printf(
      "random motions: %ld of %ld states certified, %ld renewals, %ld of %ld steps "
      "certified, %d skipped steps longer than the CCD's\n",
      with_skips.barrier_certified, with_skips.barrier_evaluations, with_skips.certificate_renewals,
      with_skips.ccd_certified, with_skips.ccd_evaluations, longer_steps);
}

TEST(ContactPotential, StatesAndMotionsWithinTheSearchedRegionFindThePairsOfAFreshSearch) {
  // The sheets approach from 4 d̂ to within reach along one CCD query's motion. Every state on
  // it (computed as x + α dx, with its rounding), and every state or motion that stays within
  // the search's skin (d̂ here: reach = d̂) of its swept boxes, must see the pairs and the time
  // of impact that a fresh potential sees; anything farther must be searched again.
  std::mt19937 rng(17);
  TwoSheets sheets = two_sheets(4 * kActivation);
  for (Eigen::Index i = 2; i < sheets.x.size(); i += 3)
    sheets.x[i] += 0.3 * kActivation * test::random_point(rng).z();
  ContactPotential reusing(sheets.surface, parameters(false));
  const auto fresh_pairs = [&](const Eigen::VectorXd& x) {
    return ContactPotential(sheets.surface, parameters(false)).active_pairs(x);
  };
  const auto fresh_step = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
    return ContactPotential(sheets.surface, parameters(false)).max_feasible_step(x, dx);
  };
  const Eigen::VectorXd dx = upper_moved(sheets, {0.0, 0.0, -3.6 * kActivation}) - sheets.x +
                             random_motion(sheets.x.size(), 0.1 * kActivation, rng);
  const double alpha = reusing.max_feasible_step(sheets.x, dx);
  ASSERT_GT(alpha, 0.5);
  std::size_t most_pairs = 0;
  for (const double t : {0.0, 0.25, 0.5, 0.75, 0.9, 1.0}) {
    const Eigen::VectorXd x = sheets.x + t * alpha * dx;
    expect_same_pairs(reusing.active_pairs(x), fresh_pairs(x));
    most_pairs = std::max(most_pairs, fresh_pairs(x).size());
  }
  EXPECT_GT(most_pairs, 0u);
  EXPECT_EQ(reusing.stats().state_reuses, 6);
  EXPECT_EQ(reusing.stats().ccd_reuses, 0);

  // A short motion 2 d̂ apart and 5 d̂ aside (beyond the skin: a new search), then a state
  // 0.9 d̂ closer, within the skin: pairs whose boxes were up to 1.8 d̂ beyond reach during the
  // motion come within reach, and the search's slack kept them. A short motion from there
  // reuses the candidates and finds the same time of impact.
  const Eigen::VectorXd apart = upper_moved(sheets, {5 * kActivation, 0.0, -2 * kActivation});
  const Eigen::VectorXd nudge = random_motion(sheets.x.size(), 0.05 * kActivation, rng);
  EXPECT_EQ(reusing.max_feasible_step(apart, nudge), fresh_step(apart, nudge));
  EXPECT_EQ(reusing.stats().ccd_reuses, 0);
  const Eigen::VectorXd closer = upper_moved(sheets, {5 * kActivation, 0.0, -2.9 * kActivation});
  expect_same_pairs(reusing.active_pairs(closer), fresh_pairs(closer));
  EXPECT_GT(fresh_pairs(closer).size(), 0u);
  EXPECT_EQ(reusing.stats().state_reuses, 7);
  EXPECT_EQ(reusing.max_feasible_step(closer, nudge), fresh_step(closer, nudge));
  EXPECT_EQ(reusing.stats().ccd_reuses, 1);

  // 3 d̂ farther aside, beyond the skin: searched again.
  const Eigen::VectorXd far = upper_moved(sheets, {8 * kActivation, 0.0, -2.9 * kActivation});
  expect_same_pairs(reusing.active_pairs(far), fresh_pairs(far));
  EXPECT_EQ(reusing.stats().state_reuses, 7);
  EXPECT_EQ(reusing.max_feasible_step(far, nudge), fresh_step(far, nudge));
  EXPECT_EQ(reusing.stats().ccd_reuses, 1);
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
