#include "engine/contact/contact_potential.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>

#include "engine/contact/edge_edge_distance.hpp"
#include "engine/contact/edge_edge_mollifier.hpp"
#include "engine/contact/point_triangle_distance.hpp"
#include "engine/core/error.hpp"
#include "engine/core/psd_projection.hpp"
#include "engine/solver/solver_stats.hpp"

namespace psq {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

using Gradient12 = Eigen::Matrix<double, 12, 1>;

/// The largest certificate radius, in reaches: it caps the clearance query, whose cost grows
/// with the candidates within reach + 2 r_max. See docs/contact.md for the measurements.
constexpr double kMaxCertificateRadius = 16.0;

/// The skin s of a CCD query's candidate search, in reaches: the search covers every vertex
/// within s of its swept box, so that the next iterations' shorter steps reuse it
/// (docs/contact.md, the trade-off).
constexpr double kSearchSkin = 1.0;

Eigen::Vector3d vertex_of(const Eigen::VectorXd& x, int v) { return x.segment<3>(3 * v); }

/// m(c) b(d − ξ²) of one pair (m = 1 for point–triangle), +∞ within the thickness.
double pair_value(const ContactPair& pair, const Eigen::VectorXd& x, const BarrierBand& band) {
  const double s = band.barrier_argument(pair_distance(pair, x));
  if (!(s > 0)) return kInfinity;
  const double b = barrier(s, band.barrier_activation());
  return b == 0 ? b : barrier_weight(pair, x) * b;
}

/// Value, gradient and Hessian of m b for one pair (κ = 1), by the product rule
///   ∇(m b) = m ∇b + b ∇m,   ∇²(m b) = m ∇²b + b ∇²m + ∇m ∇bᵀ + ∇b ∇mᵀ.
StencilDerivatives<12> pair_derivatives(const ContactPair& pair, const Eigen::VectorXd& x,
                                        const BarrierBand& band) {
  const PairPositions p = stencil_positions(pair.vertices, x);
  if (!pair.edge_edge)
    return barrier_of_distance(point_triangle_distance_derivatives(p[0], p[1], p[2], p[3]), band);
  const StencilDerivatives<12> b =
      barrier_of_distance(edge_edge_distance_derivatives(p[0], p[1], p[2], p[3]), band);
  const StencilDerivatives<12> m =
      edge_edge_mollifier(p[0], p[1], p[2], p[3], pair.mollifier_threshold);
  StencilDerivatives<12> product;
  product.value = m.value * b.value;
  product.gradient = m.value * b.gradient + b.value * m.gradient;
  product.hessian = m.value * b.hessian + b.value * m.hessian +
                    m.gradient * b.gradient.transpose() + b.gradient * m.gradient.transpose();
  return product;
}

/// Pairs whose CCD runs in parallel against the same bound before it is lowered.
constexpr std::size_t kCcdBatch = 128;

/// min(1, the smallest ACCD time of impact of the pairs) for the motion x → x_end, the same as
/// if every pair ran to the end (but for a first advance's check against rounding, which
/// cannot fail beyond the margin δ). The pairs go in the order of the time their first advance
/// covers, in batches: a pair is not advanced past the smallest time found so far
/// (stop_after), and once a batch's first pair covers that time by its first advance, so do
/// all after it. A pair at a tiny gap
/// costs ACCD thousands of advances to t = 1; against a bound already found it costs a few.
/// The batches' order is fixed, so the result does not depend on the threads.
double smallest_time_of_impact(const std::vector<ContactPair>& pairs, const Eigen::VectorXd& x,
                               const Eigen::VectorXd& x_end, AdditiveCcdSettings settings) {
  const auto positions = [&](std::size_t k) {
    return std::pair{stencil_positions(pairs[k].vertices, x),
                     stencil_positions(pairs[k].vertices, x_end)};
  };
  std::vector<double> first_advance(pairs.size());
  tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t k) {
    const auto [p0, p1] = positions(k);
    first_advance[k] = ccd_first_advance(p0, p1, pairs[k].edge_edge, settings);
  });
  // Pairs whose first advance covers the whole step cannot limit it.
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (first_advance[k] < 1.0) order.push_back(k);
  const auto earlier = [&](std::size_t a, std::size_t b) {
    return first_advance[a] < first_advance[b] || (first_advance[a] == first_advance[b] && a < b);
  };
  double step = 1.0;
  for (std::size_t begin = 0; begin < order.size(); begin += kCcdBatch) {
    const std::size_t end = std::min(order.size(), begin + kCcdBatch);
    // Only the batches the loop reaches are ordered, each from the smallest first advances
    // left: the same batches as a sort of all pairs, without its n log n (most steps end
    // after a batch or two).
    std::nth_element(order.begin() + begin, order.begin() + end - 1, order.end(), earlier);
    std::sort(order.begin() + begin, order.begin() + end, earlier);
    if (first_advance[order[begin]] >= step) break;
    settings.stop_after = step;
    step = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(begin, end), step,
        [&](const tbb::blocked_range<std::size_t>& range, double smallest) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const std::size_t k = order[i];
            if (first_advance[k] >= settings.stop_after) continue;
            const auto [p0, p1] = positions(k);
            const CcdResult hit = pairs[k].edge_edge ? edge_edge_ccd(p0, p1, settings)
                                                     : point_triangle_ccd(p0, p1, settings);
            smallest = std::min(smallest, hit.toi);
          }
          return smallest;
        },
        [](double a, double b) { return std::min(a, b); });
  }
  return step;
}

void check_parameters(const ContactParameters& parameters) {
  const BarrierBand& band = parameters.band;
  if (!(band.activation_distance > 0) || !std::isfinite(band.activation_distance))
    throw InputError(fmt::format("contact: the activation distance d̂ must be positive (got {})",
                                 band.activation_distance));
  if (!(band.thickness >= 0) || !std::isfinite(band.thickness))
    throw InputError(
        fmt::format("contact: the thickness ξ must be at least 0 (got {})", band.thickness));
  validate_ccd_settings(parameters.ccd);
}

}  // namespace

PairPositions stencil_positions(const std::array<int, 4>& vertices, const Eigen::VectorXd& x) {
  return {vertex_of(x, vertices[0]), vertex_of(x, vertices[1]), vertex_of(x, vertices[2]),
          vertex_of(x, vertices[3])};
}

double pair_distance(const ContactPair& pair, const Eigen::VectorXd& x) {
  const PairPositions p = stencil_positions(pair.vertices, x);
  return pair.edge_edge ? edge_edge_distance(p[0], p[1], p[2], p[3])
                        : point_triangle_distance(p[0], p[1], p[2], p[3]);
}

/// Whether the boxes of a pair's two elements at x come within `reach` of each other on every
/// axis: a pair farther apart cannot be within reach. NaN coordinates pass, so that their
/// distance reaches the barrier and makes it non-finite.
bool boxes_within_reach(const ContactPair& pair, const Eigen::VectorXd& x, double reach) {
  const PairPositions p = stencil_positions(pair.vertices, x);
  const int split = pair.edge_edge ? 2 : 1;  // the first element's vertices
  for (int axis = 0; axis < 3; ++axis) {
    double a_min = p[0][axis], a_max = a_min, b_min = p[split][axis], b_max = b_min;
    for (int k = 1; k < split; ++k) {
      a_min = std::min(a_min, p[k][axis]);
      a_max = std::max(a_max, p[k][axis]);
    }
    for (int k = split + 1; k < 4; ++k) {
      b_min = std::min(b_min, p[k][axis]);
      b_max = std::max(b_max, p[k][axis]);
    }
    if (a_min - b_max > reach || b_min - a_max > reach) return false;
  }
  return true;
}

std::vector<ContactPair> candidate_pairs(const ContactCandidates& candidates,
                                         const BroadPhase& broad) {
  std::vector<ContactPair> pairs;
  pairs.reserve(candidates.size());
  for (const PointTriangleCandidate& c : candidates.point_triangle) {
    const auto t = broad.triangles().row(c.triangle);
    pairs.push_back({{c.vertex, t[0], t[1], t[2]}, false, 0.0});
  }
  for (const EdgeEdgeCandidate& c : candidates.edge_edge) {
    const auto& a = broad.edges()[c.edge0];
    const auto& b = broad.edges()[c.edge1];
    pairs.push_back({{a[0], a[1], b[0], b[1]}, true, 0.0});
  }
  return pairs;
}


double barrier_weight(const ContactPair& pair, const Eigen::VectorXd& x) {
  if (!pair.edge_edge) return 1.0;
  const PairPositions p = stencil_positions(pair.vertices, x);
  const double c = (p[1] - p[0]).cross(p[3] - p[2]).squaredNorm();
  return edge_edge_mollifier(c, pair.mollifier_threshold);
}

bool ClearanceCertificate::covers(const Eigen::VectorXd& x) const {
  if (radius < 0 || x.size() != reference.size()) return false;
  const double squared_radius = radius * radius;
  for (Eigen::Index i = 0; i < x.size(); i += 3)
    if (!((x.segment<3>(i) - reference.segment<3>(i)).squaredNorm() <= squared_radius))
      return false;
  return true;
}

bool ClearanceCertificate::covers_motion(const Eigen::VectorXd& x,
                                         const Eigen::VectorXd& dx) const {
  if (radius < 0 || x.size() != reference.size() || dx.size() != x.size()) return false;
  const double squared_radius = radius * radius;
  for (Eigen::Index i = 0; i < x.size(); i += 3) {
    const Eigen::Vector3d start = x.segment<3>(i) - reference.segment<3>(i);
    if (!(start.squaredNorm() <= squared_radius) ||
        !((start + dx.segment<3>(i)).squaredNorm() <= squared_radius))
      return false;
  }
  return true;
}

ContactStats& ContactStats::operator+=(const ContactStats& other) {
  barrier_evaluations += other.barrier_evaluations;
  barrier_skips += other.barrier_skips;
  ccd_evaluations += other.ccd_evaluations;
  ccd_skips += other.ccd_skips;
  ccd_pair_queries += other.ccd_pair_queries;
  barrier_certified += other.barrier_certified;
  ccd_certified += other.ccd_certified;
  certificate_renewals += other.certificate_renewals;
  state_reuses += other.state_reuses;
  ccd_reuses += other.ccd_reuses;
  max_active_pairs = std::max(max_active_pairs, other.max_active_pairs);
  broad_phase_seconds += other.broad_phase_seconds;
  barrier_seconds += other.barrier_seconds;
  ccd_seconds += other.ccd_seconds;
  return *this;
}

ContactPotential::ContactPotential(ContactSurface surface, const ContactParameters& parameters)
    : surface_(std::move(surface)),
      parameters_(parameters),
      broad_phase_(surface_.triangles, surface_.edges, surface_.vertex_body, surface_.may_touch) {
  parameters_.ccd.min_distance = parameters_.band.thickness;
  check_parameters(parameters_);
  if (!surface_.held.empty() && surface_.held.size() != surface_.vertex_body.size())
    throw std::invalid_argument(fmt::format("contact surface: {} held flags for {} vertices",
                                            surface_.held.size(), surface_.vertex_body.size()));
}

double ContactPotential::reach() const {
  return parameters_.band.thickness + parameters_.band.activation_distance;
}

std::vector<ContactPair> ContactPotential::moving_pairs(const ContactCandidates& candidates) const {
  std::vector<ContactPair> pairs = candidate_pairs(candidates, broad_phase_);
  if (surface_.held.empty()) return pairs;
  std::erase_if(pairs, [&](const ContactPair& pair) {
    return std::all_of(pair.vertices.begin(), pair.vertices.end(),
                       [&](int v) { return surface_.held[v]; });
  });
  return pairs;
}

void ContactPotential::refresh(const Eigen::VectorXd& x) {
  if (cached_x_.size() == x.size() && cached_x_ == x) return;
  ++stats_.barrier_evaluations;
  // A clearance query pays only when nothing is within reach; while the last state had pairs
  // within reach, it would find one at once and the candidates would be searched a second time.
  const bool last_apart = active_.empty();
  active_.clear();
  min_distance_ = kInfinity;
  cached_x_ = x;
  ContactCandidates searched;
  const ContactCandidates* candidates = &searched_.candidates;
  {
    ScopedTimer timer(stats_.broad_phase_seconds);
    if (parameters_.skip_when_apart && certificate_.covers(x)) {
      ++stats_.barrier_skips;
      ++stats_.barrier_certified;
      return;
    }
    // Inside the kept region the candidates answer at once; a clearance query (a search 33
    // reaches wide) would cost more.
    const bool kept = searched_.contains(as_positions(x));
    if (parameters_.skip_when_apart && last_apart && !kept && renew_certificate(x)) {
      ++stats_.barrier_skips;
      return;
    }
    if (kept) {
      ++stats_.state_reuses;
    } else {
      searched = broad_phase_.distance_candidates(as_positions(x), reach());
      candidates = &searched;
    }
  }
  ScopedTimer timer(stats_.barrier_seconds);
  std::vector<ContactPair> pairs = moving_pairs(*candidates);
  std::vector<double> distance(pairs.size());
  // The kept region's candidates reach farther than the state needs (its skin): the boxes
  // sort out most of those before the exact distance.
  const double reach = this->reach();
  tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t k) {
    distance[k] = boxes_within_reach(pairs[k], x, reach) ? pair_distance(pairs[k], x) : kInfinity;
  });
  const BarrierBand& band = parameters_.band;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    // NaN distances are kept: they make the value non-finite instead of vanishing silently.
    if (band.barrier_argument(distance[k]) >= band.barrier_activation()) continue;
    ContactPair& pair = pairs[k];
    if (pair.edge_edge) {
      const auto rest = [&](int slot) -> Eigen::Vector3d {
        return surface_.rest.row(pair.vertices[slot]).transpose();
      };
      pair.mollifier_threshold = edge_edge_mollifier_threshold(rest(0), rest(1), rest(2), rest(3));
    }
    active_.push_back(pair);
    min_distance_ = std::min(min_distance_, distance[k]);
  }
  stats_.max_active_pairs = std::max(stats_.max_active_pairs, static_cast<long>(active_.size()));
}

bool ContactPotential::SearchedRegion::contains(const Positions& x) const {
  return x.rows() == lower.rows() && (x.array() >= lower.array()).all() &&
         (x.array() <= upper.array()).all();
}

const ContactCandidates& ContactPotential::swept_candidates(const Positions& start,
                                                            const Positions& end) {
  if (searched_.contains(start) && searched_.contains(end)) {
    ++stats_.ccd_reuses;
    return searched_.candidates;
  }
  // The boxes are rounded outward by τ (distance_rounding_margin) on top of the skin, and the
  // search's reach by 2τ, so that a vertex in its box lies within s of its searched box
  // whatever the rounding of the box's bounds.
  const double skin = kSearchSkin * reach();
  const double tolerance = distance_rounding_margin(
      std::max(start.cwiseAbs().maxCoeff(), end.cwiseAbs().maxCoeff()) + skin);
  searched_.lower = (start.cwiseMin(end).array() - (skin + tolerance)).matrix();
  searched_.upper = (start.cwiseMax(end).array() + (skin + tolerance)).matrix();
  searched_.candidates =
      broad_phase_.swept_candidates(start, end, reach() + 2 * (skin + 2 * tolerance));
  return searched_.candidates;
}

bool ContactPotential::renew_certificate(const Eigen::VectorXd& x) {
  const double reach = this->reach();
  const double clearance =
      broad_phase_.clearance(as_positions(x), reach, (1 + 2 * kMaxCertificateRadius) * reach);
  // Distances come from rounded coordinates: the margin keeps a pair that the candidate search
  // would find at reach (to rounding) out of the radius.
  const double margin = distance_rounding_margin(x.cwiseAbs().maxCoeff());
  const double radius = 0.5 * (clearance - reach - margin);
  if (!(radius > 0)) return false;
  certificate_ = {x, radius};
  ++stats_.certificate_renewals;
  return true;
}

const std::vector<ContactPair>& ContactPotential::active_pairs(const Eigen::VectorXd& x) {
  refresh(x);
  return active_;
}

double ContactPotential::min_distance(const Eigen::VectorXd& x) {
  refresh(x);
  return min_distance_;
}

double ContactPotential::value(const Eigen::VectorXd& x) {
  refresh(x);
  if (active_.empty()) return 0.0;
  ScopedTimer timer(stats_.barrier_seconds);
  const double sum = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, active_.size()), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double partial) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
          partial += pair_value(active_[k], x, parameters_.band);
        return partial;
      },
      std::plus<>());
  return stiffness_ * sum;
}

void ContactPotential::accumulate_gradient(const Eigen::VectorXd& x, double scale,
                                           Eigen::VectorXd& g) {
  refresh(x);
  if (active_.empty()) return;
  ScopedTimer timer(stats_.barrier_seconds);
  std::vector<Gradient12> gradients(active_.size());
  tbb::parallel_for(std::size_t{0}, active_.size(), [&](std::size_t k) {
    gradients[k] = pair_derivatives(active_[k], x, parameters_.band).gradient;
  });
  for (std::size_t k = 0; k < active_.size(); ++k)
    for (int i = 0; i < 4; ++i)
      g.segment<3>(3 * active_[k].vertices[i]) += scale * gradients[k].segment<3>(3 * i);
}

void ContactPotential::add_gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) {
  accumulate_gradient(x, stiffness_, g);
}

Eigen::VectorXd ContactPotential::unit_gradient(const Eigen::VectorXd& x) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  accumulate_gradient(x, 1.0, g);
  return g;
}

void ContactPotential::hessian(const Eigen::VectorXd& x, ElementMatrices& blocks,
                               bool project_psd, const std::vector<bool>& fixed_vertices) {
  if (!fixed_vertices.empty() && fixed_vertices.size() != surface_.vertex_body.size())
    throw std::invalid_argument(fmt::format("contact Hessian: {} fixed flags for {} vertices",
                                            fixed_vertices.size(), surface_.vertex_body.size()));
  refresh(x);
  std::vector<int> stencils;
  stencils.reserve(4 * active_.size());
  for (const ContactPair& pair : active_)
    stencils.insert(stencils.end(), pair.vertices.begin(), pair.vertices.end());
  blocks.reset(4, std::move(stencils));
  ScopedTimer timer(stats_.barrier_seconds);
  tbb::parallel_for(std::size_t{0}, active_.size(), [&](std::size_t k) {
    Eigen::Matrix<double, 12, 12> h = pair_derivatives(active_[k], x, parameters_.band).hessian;
    if (project_psd) {
      std::array<bool, 4> fixed{};
      if (!fixed_vertices.empty())
        for (int i = 0; i < 4; ++i) fixed[i] = fixed_vertices[active_[k].vertices[i]];
      project_moving_block_to_psd(h, fixed);
    }
    blocks.block(k) = stiffness_ * h;
  });
}

double ContactPotential::max_feasible_step(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) {
  ++stats_.ccd_evaluations;
  // The state's own query (a certificate check, renewal or candidate search) is barrier time.
  const bool apart = parameters_.skip_when_apart && active_pairs(x).empty();
  ScopedTimer timer(stats_.ccd_seconds);
  // Nothing comes within the barrier's reach on the way, so nothing can come within ξ. (With
  // pairs within reach at the start, neither test could succeed: they are not tried.)
  if (apart && certificate_.covers_motion(x, dx)) {
    ++stats_.ccd_skips;
    ++stats_.ccd_certified;
    return 1.0;
  }
  const Eigen::Map<const Positions> start = as_positions(x);
  const Positions end = start + as_positions(dx);
  if (apart && !broad_phase_.any_within_reach_during(start, end, reach())) {
    ++stats_.ccd_skips;
    return 1.0;
  }
  const ContactCandidates& candidates = swept_candidates(start, end);
  stats_.ccd_pair_queries += static_cast<long>(candidates.size());
  return smallest_time_of_impact(moving_pairs(candidates), x, x + dx,
                                 parameters_.ccd);
}

}  // namespace psq
