#pragma once
// IPC's unit log barrier (Li et al. 2020, "Incremental Potential Contact"), shared by the
// contact potential (engine/contact/barrier.hpp, on squared distances) and the strain limit
// (engine/elastic/strain_limit.hpp, on the normalized slack to the limit).

namespace psq {

/// The unit barrier b(s) = −(s − ŝ)² ln(s/ŝ) for 0 < s < ŝ, 0 for s ≥ ŝ, +∞ for s ≤ 0.
/// Positive, decreasing and convex on (0, ŝ); b, b′ and b″ all vanish at ŝ, so the barrier is
/// C² there. A pair's contact potential is κ b (the stiffness is applied by the caller).
double barrier(double s, double s_hat);

/// b′(s) = (ŝ − s)(2 ln(s/ŝ) − ŝ/s + 1) for 0 < s < ŝ, 0 for s ≥ ŝ, −∞ for s ≤ 0.
double barrier_first_derivative(double s, double s_hat);

/// b″(s) = −2 ln(s/ŝ) + (ŝ/s)(ŝ/s + 2) − 3 for 0 < s < ŝ, 0 for s ≥ ŝ, +∞ for s ≤ 0.
double barrier_second_derivative(double s, double s_hat);

}  // namespace psq
