// bireg: the normalised data a fit works on, validated before any work.
//
// Covariates are mapped affinely onto the unit interval [0, 1] on which the
// paper defines the estimator (DESIGN.md section 1): by default t_min, the
// smallest covariate, goes to 0 and t_max, the largest, to 1; an explicit
// interval fixes both ends instead (the estimator depends on that choice, so
// fits of subsets or local fits that must be comparable need it). The map
// is computed in double (or in Scalar where that is wider), whatever the
// Scalar: float covariates such as 1.7e9 + 0.01 i would otherwise collapse.
//
// Weights are divided by the largest one before any sum: scaling all weights
// changes nothing in the estimator, and uniform weights of 1e300 or 1e-300
// would otherwise overflow or underflow the sums below.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "bireg/regression/parallel.hpp"

namespace bireg {

// Why a fit was refused, and the observation at fault (-1: none).
struct Rejection {
  std::string message;
  std::ptrdiff_t index = -1;
};

// The wider of double and Scalar: the precision of the covariate map.
template <class Scalar>
using CovariateScalar =
    std::conditional_t<(std::numeric_limits<Scalar>::digits > std::numeric_limits<double>::digits),
                       Scalar, double>;

template <class Scalar>
struct Problem {
  using Wide = CovariateScalar<Scalar>;
  std::vector<Scalar> t;  // covariates mapped onto [0, 1]
  std::vector<Scalar> w;  // weights divided by the largest
  Wide t_min = 0, t_max = 1;
  // H = [a b; b c] of Lemma 3.7, a = sum w (1-t)^2, b = sum w t (1-t),
  // c = sum w t^2, and its eigenvalues.
  Scalar a = 0, b = 0, c = 0;
  Scalar mu_min = 0, mu_max = 0;
  Scalar weight_sum = 0;

  std::size_t size() const { return t.size(); }
  Scalar determinant() const { return a * c - b * b; }
};

// The smallest covariate range (max - min) fit() accepts; the largest is
// its inverse. The velocity is X / range (X on the unit interval): beyond
// these it would overflow or underflow out of the normal numbers.
// min normal / epsilon: 1e-292 in double, 1e-31 in float.
template <class Scalar>
CovariateScalar<Scalar> covariate_range_limit() {
  using Wide = CovariateScalar<Scalar>;
  return Wide(std::numeric_limits<Scalar>::min()) / Wide(std::numeric_limits<Scalar>::epsilon());
}

// The same for the velocity's covariance, C / range^2: its square root,
// 1e-146 in double, 3e-16 in float (statistics/inference/covariance.hpp refuses a
// covariance outside it as undefined; the fit itself stands).
template <class Scalar>
CovariateScalar<Scalar> covariance_range_limit() {
  using std::sqrt;
  return sqrt(covariate_range_limit<Scalar>());
}

// Why a covariate range lies outside [limit, 1 / limit], or nothing: the
// one check and message behind fit() (covariate_range_limit), model
// selection (the same, before any candidate) and the covariance
// (covariance_range_limit). `consequence` completes the message. A NaN
// range lies outside.
template <class Wide>
std::optional<std::string> range_outside(Wide range, Wide limit, const char* consequence) {
  if (range >= limit && range <= 1 / limit) return std::nullopt;
  std::ostringstream why;
  why << "the covariates' range " << double(range) << " lies outside [" << double(limit) << ", "
      << double(1 / limit) << "]" << consequence << "; rescale the covariates";
  return why.str();
}

namespace problem_detail {
template <class Scalar>
bool finite(Scalar x) {
  using std::isfinite;
  return isfinite(x);
}
}  // namespace problem_detail

// Builds the problem from n covariates and optional weights (empty: all 1)
// and an optional interval (first < second, containing every covariate).
// `problem` may be one built before (its vectors keep their capacity: a
// sequence of problems no larger than the first allocates nothing).
template <class Scalar, class Covariates>
std::optional<Rejection> make_problem(
    const Covariates& covariates, const std::vector<Scalar>& weights,
    const std::optional<std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>>>& interval,
    Problem<Scalar>& problem) {
  using problem_detail::finite;
  using std::sqrt;
  using Wide = CovariateScalar<Scalar>;
  const std::size_t n = covariates.size();
  const auto index = [](std::size_t i) { return static_cast<std::ptrdiff_t>(i); };
  const auto wide = [&](std::size_t i) { return static_cast<Wide>(covariates[i]); };
  if (!weights.empty() && weights.size() != n) {
    return Rejection{"weights and observations differ in length (" +
                     std::to_string(weights.size()) + " vs " + std::to_string(n) + ")"};
  }
  Wide smallest = std::numeric_limits<Wide>::infinity();
  Wide largest = -std::numeric_limits<Wide>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const Wide covariate = wide(i);
    if (!finite(covariate)) {
      return Rejection{"covariate " + std::to_string(i) + " is not finite", index(i)};
    }
    smallest = std::min(smallest, covariate);
    largest = std::max(largest, covariate);
  }
  Scalar largest_weight = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    if (!(weights[i] >= 0) || !finite(weights[i])) {
      return Rejection{"weight " + std::to_string(i) + " is negative or not finite", index(i)};
    }
    largest_weight = std::max(largest_weight, weights[i]);
  }
  if (!weights.empty() && !(largest_weight > 0)) return Rejection{"all weights are zero"};

  if (interval) {
    const auto [low, high] = *interval;
    if (!finite(low) || !finite(high) || !(low < high) || !finite(high - low)) {
      return Rejection{"the covariate interval needs finite ends with first < second"};
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (wide(i) < low || wide(i) > high) {
        return Rejection{"covariate " + std::to_string(i) + " lies outside the covariate interval",
                         index(i)};
      }
    }
    problem.t_min = low;
    problem.t_max = high;
  } else {
    problem.t_min = smallest;
    problem.t_max = largest;
  }
  const Wide range = problem.t_max - problem.t_min;
  if (!(range > 0) || !finite(range)) {
    return Rejection{range > 0 ? "covariate range overflows"
                               : "all covariates are equal: the slope is not identifiable"};
  }
  // The velocity is X / range (X on the unit interval): a range outside
  // covariate_range_limit would make it overflow or underflow.
  if (auto why = range_outside(range, covariate_range_limit<Scalar>(),
                               ": the velocity would overflow or underflow")) {
    return Rejection{*why};
  }
  problem.t.resize(n);
  problem.w.assign(n, Scalar(1));
  for (std::size_t i = 0; i < n; ++i) {
    problem.t[i] =
        static_cast<Scalar>(std::clamp((wide(i) - problem.t_min) / range, Wide(0), Wide(1)));
    if (!weights.empty()) problem.w[i] = weights[i] / largest_weight;
  }

  // H of Lemma 3.7, and its eigenvalues in a cancellation-free form.
  problem.a = problem.b = problem.c = problem.weight_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Scalar t = problem.t[i], w = problem.w[i];
    problem.a += w * (1 - t) * (1 - t);
    problem.b += w * t * (1 - t);
    problem.c += w * t * t;
    problem.weight_sum += w;
  }
  const Scalar half_trace = (problem.a + problem.c) / 2;
  const Scalar half_gap = (problem.a - problem.c) / 2;
  problem.mu_max = half_trace + sqrt(half_gap * half_gap + problem.b * problem.b);
  problem.mu_min = problem.mu_max > 0 ? problem.determinant() / problem.mu_max : Scalar(0);
  // mu_min is computed to ~eps mu_max; below a few of those it is noise.
  if (!(problem.mu_min > 16 * std::numeric_limits<Scalar>::epsilon() * problem.mu_max)) {
    return Rejection{
        "the observations with positive weight share one covariate: the slope is not "
        "identifiable (mu_min = 0)"};
  }
  return std::nullopt;
}

// The weights divided by the largest (empty stays empty, as does a list
// with no positive weight): the estimators depend only on the weights'
// ratios, and sums of weights of 1e308, or products of subnormal weights
// such as 1e-320, would overflow or lose every digit. For weights that
// make_problem accepted; the statistics above fit() call it once, at
// their entry.
template <class Scalar>
std::vector<Scalar> normalised_weights(const std::vector<Scalar>& weights) {
  std::vector<Scalar> normalised(weights);
  Scalar largest = 0;
  for (const Scalar w : weights)
    largest = std::max(largest, w);
  if (!(largest > 0)) return normalised;
  for (Scalar& w : normalised)
    w /= largest;
  return normalised;
}

// Every observation finite and in the group (to `tolerance`); the first
// that is not is named. By chunks on `pool` when one is given.
template <class G, class Observations>
std::optional<Rejection> check_observations(const Observations& observations,
                                            typename G::Scalar tolerance,
                                            ChunkPool* pool = nullptr) {
  struct Finding {
    std::ptrdiff_t index = -1;  // the first observation that fails, or -1
    bool finite = true;         // whether it fails by non-finite entries or by membership
  };
  const Finding found = reduce_chunks<Finding>(
      observations.size(), pool,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const typename G::Element& f = observations[i];
          const auto index = static_cast<std::ptrdiff_t>(i);
          if (!f.allFinite()) return Finding{index, false};
          if (!G::is_element(f, tolerance)) return Finding{index, true};
        }
        return Finding{};
      },
      [](Finding& first, const Finding& next) {
        if (first.index < 0) first = next;
      });
  if (found.index < 0) return std::nullopt;
  const std::string observation = "observation " + std::to_string(found.index);
  if (!found.finite) return Rejection{observation + " has non-finite entries", found.index};
  return Rejection{observation + " is not an element of " + G::name + " (to tolerance " +
                       std::to_string(double(tolerance)) + ")",
                   found.index};
}

}  // namespace bireg
