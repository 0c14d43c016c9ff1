// bireg: the bi-invariant mean (exponential barycenter) of group elements,
// DESIGN.md section 5: the m with
//
//   F(m) = sum_i w_i y_i = 0,   y_i = log(m^{-1} f_i),
//
// the constant model of the regression (a geodesic with X = 0 solves the
// paper's Definition 2.1 equations exactly when its point solves F = 0).
// F moves with the data like the estimator (Theorem 2.4): left
// translation leaves y_i unchanged, right translation by h maps them by
// Ad_{h^{-1}}, inversion maps the root m to m^{-1}; so the mean is left,
// right and inverse equivariant.
//
// Newton's step. Perturbing m to m exp(delta), log(exp(-delta) exp(y_i)) =
// y_i - J_l^{-1}(y_i) delta + O(delta^2), J_l^{-1}(y) = J_r^{-1}(-y) (the
// inverse differential of the paper's Lemma 3.1 at s = 1 seen from the
// other end), so
//
//   delta = (sum_i w_i J_r^{-1}(-y_i))^{-1} sum_i w_i y_i,  m <- m exp(delta)
//
// converges quadratically. Each step is left and right equivariant (the
// Jacobian moves by Ad like the y_i); inversion maps it to the step with
// J_r^{-1}(y_i) instead, so inverse equivariance holds for the limit (the
// root), not iterate by iterate. The fixed-point iteration m <- m
// exp(sum w y / sum w) that Sophus, manif, morphomatics and geomstats use is
// the same with the Jacobian replaced by its value at y = 0 (sum w I): it
// converges linearly, at a rate growing with the data's spread.
// Safeguard: a step that increases |F| (Euclidean in left-trivialised
// coordinates) is halved, as in the regression's iteration.
//
// Start: the chart mean at the observation of largest weight (the first of
// equal ones), m0 = f_k exp(sum w log(f_k^{-1} f_i) / sum w). It is left and
// right equivariant; its dependence on which observation is f_k (hence on
// the order of equal-weight data) is only through the start: wherever the
// root is unique (data inside a ball where the log is a diffeomorphism,
// the regime in which the mean is defined at all) Newton converges to the
// same m, so the order changes the result by rounding only (tested to
// 1e-12). A choice among data points by an invariant criterion (the
// medoid) would cost O(N^2) to buy nothing beyond rounding.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

template <class Scalar>
struct MeanOptions {
  // Converged once the step taken has norm at or below this (Newton: the
  // error after it is of the order of its square).
  Scalar tolerance = std::max(Scalar(1e-10), Scalar(64) * std::numeric_limits<Scalar>::epsilon());
  int max_iterations = 100;
  Scalar element_tolerance = default_element_tolerance<Scalar>();
  // Newton (default) or the linear fixed-point iteration, for comparison.
  bool newton = true;
};

template <class G>
struct MeanResult {
  using Scalar = typename G::Scalar;
  // converged, max_iterations, diverged (non-finite logs: the data leave
  // the log's domain), no_descent (no step along Newton's direction
  // reduces |F|), invalid_input (message and bad_index say why).
  Status status = Status::invalid_input;
  std::string message;
  std::ptrdiff_t bad_index = -1;
  std::optional<typename G::Element> mean;  // the last usable iterate unless invalid_input
  int iterations = 0;
  std::vector<Scalar> step_norms;
  std::vector<typename G::Tangent> residuals;  // y_i = log(m^{-1} f_i), input order
  Scalar residual_norm = 0;                    // |sum w y| / sum w at the mean

  bool ok() const { return is_success(status); }
};

namespace mean_detail {

// sum w y and, for Newton, sum w J_r^{-1}(-y), at m; false if a log is not finite.
template <class G, class Observations>
bool moments(const Observations& observations, const std::vector<typename G::Scalar>& weights,
             const typename G::Element& m, bool jacobian, std::vector<typename G::Tangent>& y,
             typename G::Tangent& sum, typename G::AdMatrix& jacobian_sum) {
  const typename G::Element m_inverse = G::inverse(m);
  sum.setZero();
  jacobian_sum.setZero();
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const typename G::Scalar w = weights.empty() ? typename G::Scalar(1) : weights[i];
    y[i] = G::log(G::compose(m_inverse, observations[i]));
    if (!y[i].allFinite()) return false;
    sum += w * y[i];
    if (jacobian && w != 0) jacobian_sum += w * right_jacobian_inverse<G>(-y[i]);
  }
  return true;
}

}  // namespace mean_detail

// The bi-invariant mean of `observations` (indexable, with size()) with
// optional non-negative weights (empty: all 1). Never throws for bad data,
// never returns NaN.
template <class G, class Observations>
MeanResult<G> mean(const Observations& observations,
                   const std::vector<typename G::Scalar>& weights = {},
                   const MeanOptions<typename G::Scalar>& options = {}) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Element = typename G::Element;
  using std::sqrt;
  MeanResult<G> result;
  const std::size_t n = observations.size();
  if (n == 0) {
    result.message = "the mean of no observations is undefined";
    return result;
  }
  if (!weights.empty() && weights.size() != n) {
    result.message = "weights and observations differ in length (" +
                     std::to_string(weights.size()) + " vs " + std::to_string(n) + ")";
    return result;
  }
  if (!(options.tolerance >= 0) || options.max_iterations < 1) {
    result.message = "tolerance must be non-negative and max_iterations at least 1";
    return result;
  }
  std::size_t heaviest = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    using std::isfinite;
    if (!(weights[i] >= 0) || !isfinite(weights[i])) {
      result.message = "weight " + std::to_string(i) + " is negative or not finite";
      result.bad_index = static_cast<std::ptrdiff_t>(i);
      return result;
    }
    if (weights[i] > weights[heaviest]) heaviest = i;
  }
  if (!weights.empty() && !(weights[heaviest] > 0)) {
    result.message = "all weights are zero";
    return result;
  }
  if (auto rejection = check_observations<G>(observations, options.element_tolerance)) {
    result.message = rejection->message;
    result.bad_index = rejection->index;
    return result;
  }
  // Weights divided by the largest (normalised_weights), then by their sum:
  // F is then an average, and its size comparable across data sets
  // (scaling all weights changes nothing). Dividing by the largest first
  // keeps the sum finite for weights of 1e308 and exact for subnormal
  // weights such as 1e-320.
  std::vector<Scalar> w =
      weights.empty() ? std::vector<Scalar>(n, Scalar(1)) : normalised_weights(weights);
  Scalar weight_sum = 0;
  for (const Scalar wi : w)
    weight_sum += wi;
  for (Scalar& wi : w)
    wi /= weight_sum;

  std::vector<Tangent> y(n), trial_y(n);
  Tangent force;
  AdMatrix jacobian;
  const Element& anchor = observations[heaviest];
  if (!mean_detail::moments<G>(observations, w, anchor, false, y, force, jacobian)) {
    result.status = Status::diverged;
    result.message = "an observation is out of reach of observation " + std::to_string(heaviest) +
                     ": no principal logarithm (the data leave " + "the domain of " + G::name +
                     "'s log)";
    result.mean = anchor;
    return result;
  }
  Element m = exp_at<G>(anchor, force);
  result.mean = m;
  if (!mean_detail::moments<G>(observations, w, m, options.newton, y, force, jacobian)) {
    result.status = Status::diverged;
    result.message = "the chart mean leaves the domain of the log";
    result.mean = anchor;
    return result;
  }
  constexpr int kMaxHalvings = 20;
  result.status = Status::max_iterations;
  result.step_norms.reserve(static_cast<std::size_t>(options.max_iterations));
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const Tangent step = options.newton ? Tangent(SmallLU<AdMatrix>(jacobian).solve(force)) : force;
    const Scalar step_norm = sqrt(step.squaredNorm());
    result.iterations = iteration + 1;
    using std::isfinite;
    if (!isfinite(step_norm)) {
      result.status = Status::diverged;
      result.message = "the Newton step is not finite (singular Jacobian)";
      break;
    }
    result.step_norms.push_back(step_norm);
    const Scalar force_norm = sqrt(force.squaredNorm());
    Scalar fraction = 1;
    Tangent trial_force;
    AdMatrix trial_jacobian;
    Element trial = exp_at<G>(m, step);
    bool usable = mean_detail::moments<G>(observations, w, trial, options.newton, trial_y,
                                          trial_force, trial_jacobian);
    for (int halving = 0;
         halving < kMaxHalvings && !(usable && sqrt(trial_force.squaredNorm()) <= force_norm);
         ++halving) {
      fraction /= 2;
      trial = exp_at<G>(m, fraction * step);
      usable = mean_detail::moments<G>(observations, w, trial, options.newton, trial_y, trial_force,
                                       trial_jacobian);
    }
    if (!usable) {
      result.status = Status::diverged;
      result.message = "every step leaves the domain of " + std::string(G::name) + "'s log";
      break;
    }
    if (!(sqrt(trial_force.squaredNorm()) <= force_norm) &&
        step_norm > sqrt(std::numeric_limits<Scalar>::epsilon())) {
      result.status = Status::no_descent;
      result.message =
          "no step reduces the barycenter equation: the data spread too far for a unique "
          "exponential barycenter";
      break;
    }
    m = trial;
    force = trial_force;
    jacobian = trial_jacobian;
    std::swap(y, trial_y);
    if (step_norm <= options.tolerance) {
      result.status = Status::converged;
      break;
    }
  }
  if (result.status == Status::max_iterations) {
    result.message = "no convergence in " + std::to_string(options.max_iterations) +
                     " iterations (data spread beyond the region where the mean is unique?)";
  }
  result.mean = m;
  result.residuals = std::move(y);
  result.residual_norm = sqrt(force.squaredNorm());
  return result;
}

}  // namespace bireg

// The compiled part's instantiations of mean() (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/statistics/precompiled/mean.hpp"
#endif
