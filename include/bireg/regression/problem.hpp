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

// One pass over covariates [begin, end) (and their weights, when there
// are any): their range, the largest weight, and the first covariate that
// is not finite, weight that is negative or not finite, and covariate
// outside `interval` (when one is given). Indices are i + offset, so that
// surveys of consecutive chunks of a larger set name the observation in
// the whole set; `add` joins two surveys in either order (the smaller
// index wins). make_problem surveys everything at once; a chunked fit
// (chunked_fit.hpp) surveys each chunk where it lives.
template <class Scalar>
struct CovariateSurvey {
  using Wide = CovariateScalar<Scalar>;
  std::size_t count = 0;
  Wide smallest = std::numeric_limits<Wide>::infinity();
  Wide largest = -std::numeric_limits<Wide>::infinity();
  Scalar largest_weight = 0;
  std::ptrdiff_t bad_covariate = -1, bad_weight = -1, outside_interval = -1;

  template <class Covariates>
  static CovariateSurvey over(const Covariates& covariates, const Scalar* weights,
                              const std::optional<std::pair<Wide, Wide>>& interval,
                              std::size_t begin, std::size_t end, std::size_t offset = 0) {
    using problem_detail::finite;
    CovariateSurvey survey;
    survey.count = end - begin;
    const auto index = [offset](std::size_t i) { return static_cast<std::ptrdiff_t>(i + offset); };
    for (std::size_t i = begin; i < end; ++i) {
      const Wide covariate = static_cast<Wide>(covariates[i]);
      if (!finite(covariate)) {
        if (survey.bad_covariate < 0) survey.bad_covariate = index(i);
        continue;
      }
      survey.smallest = std::min(survey.smallest, covariate);
      survey.largest = std::max(survey.largest, covariate);
      if (interval && survey.outside_interval < 0 &&
          (covariate < interval->first || covariate > interval->second)) {
        survey.outside_interval = index(i);
      }
    }
    if (weights) {
      for (std::size_t i = begin; i < end; ++i) {
        if (!(weights[i] >= 0) || !finite(weights[i])) {
          survey.bad_weight = index(i);
          break;
        }
        survey.largest_weight = std::max(survey.largest_weight, weights[i]);
      }
    }
    return survey;
  }

  void add(const CovariateSurvey& other) {
    const auto first = [](std::ptrdiff_t a, std::ptrdiff_t b) {
      return a < 0 ? b : (b < 0 ? a : std::min(a, b));
    };
    count += other.count;
    smallest = std::min(smallest, other.smallest);
    largest = std::max(largest, other.largest);
    largest_weight = std::max(largest_weight, other.largest_weight);
    bad_covariate = first(bad_covariate, other.bad_covariate);
    bad_weight = first(bad_weight, other.bad_weight);
    outside_interval = first(outside_interval, other.outside_interval);
  }
};

// Where the covariates map onto the unit interval and what the weights are
// divided by: t = (covariate - t_min) / (t_max - t_min), w = weight /
// largest_weight (1 without weights).
template <class Scalar>
struct CovariateFrame {
  CovariateScalar<Scalar> t_min = 0, t_max = 1;
  Scalar largest_weight = 1;
};

// The frame of a survey (of all observations), or why there is none: the
// checks of make_problem, in its order and with its messages.
template <class Scalar>
std::optional<Rejection> covariate_frame(
    const CovariateSurvey<Scalar>& survey, bool weighted,
    const std::optional<std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>>>& interval,
    CovariateFrame<Scalar>& frame) {
  using problem_detail::finite;
  using Wide = CovariateScalar<Scalar>;
  if (survey.bad_covariate >= 0) {
    return Rejection{"covariate " + std::to_string(survey.bad_covariate) + " is not finite",
                     survey.bad_covariate};
  }
  if (survey.bad_weight >= 0) {
    return Rejection{"weight " + std::to_string(survey.bad_weight) + " is negative or not finite",
                     survey.bad_weight};
  }
  if (weighted && !(survey.largest_weight > 0)) return Rejection{"all weights are zero"};
  frame.largest_weight = weighted ? survey.largest_weight : Scalar(1);
  if (interval) {
    const auto [low, high] = *interval;
    if (!finite(low) || !finite(high) || !(low < high) || !finite(high - low)) {
      return Rejection{"the covariate interval needs finite ends with first < second"};
    }
    if (survey.outside_interval >= 0) {
      return Rejection{"covariate " + std::to_string(survey.outside_interval) +
                           " lies outside the covariate interval",
                       survey.outside_interval};
    }
    frame.t_min = low;
    frame.t_max = high;
  } else {
    frame.t_min = survey.smallest;
    frame.t_max = survey.largest;
  }
  const Wide range = frame.t_max - frame.t_min;
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
  return std::nullopt;
}

// Sets problem.t and problem.w of the covariates (and weights, when there
// are any) in `frame`, and the frame's ends.
template <class Scalar, class Covariates>
void normalise_covariates(const Covariates& covariates, const Scalar* weights,
                          const CovariateFrame<Scalar>& frame, Problem<Scalar>& problem) {
  using Wide = CovariateScalar<Scalar>;
  const Wide range = frame.t_max - frame.t_min;
  problem.t_min = frame.t_min;
  problem.t_max = frame.t_max;
  const std::size_t n = covariates.size();
  problem.t.resize(n);
  problem.w.assign(n, Scalar(1));
  for (std::size_t i = 0; i < n; ++i) {
    problem.t[i] = static_cast<Scalar>(
        std::clamp((static_cast<Wide>(covariates[i]) - frame.t_min) / range, Wide(0), Wide(1)));
    if (weights) problem.w[i] = weights[i] / frame.largest_weight;
  }
}

// The sums of H = [a b; b c] of Lemma 3.7 over a problem's observations,
// a = sum w (1-t)^2, b = sum w t (1-t), c = sum w t^2, and sum w.
template <class Scalar>
struct DesignSums {
  Scalar a = 0, b = 0, c = 0, weight_sum = 0;

  static DesignSums over(const Problem<Scalar>& problem) {
    DesignSums sums;
    for (std::size_t i = 0; i < problem.size(); ++i) {
      const Scalar t = problem.t[i], w = problem.w[i];
      sums.a += w * (1 - t) * (1 - t);
      sums.b += w * t * (1 - t);
      sums.c += w * t * t;
      sums.weight_sum += w;
    }
    return sums;
  }
  void add(const DesignSums& other) {
    a += other.a;
    b += other.b;
    c += other.c;
    weight_sum += other.weight_sum;
  }
};

// Sets the problem's H and its eigenvalues (in a cancellation-free form)
// from the sums of all observations; refuses an H that does not identify
// the slope.
template <class Scalar>
std::optional<Rejection> set_design(const DesignSums<Scalar>& sums, Problem<Scalar>& problem) {
  using std::sqrt;
  problem.a = sums.a;
  problem.b = sums.b;
  problem.c = sums.c;
  problem.weight_sum = sums.weight_sum;
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

// Builds the problem from n covariates and optional weights (empty: all 1)
// and an optional interval (first < second, containing every covariate).
// `problem` may be one built before (its vectors keep their capacity: a
// sequence of problems no larger than the first allocates nothing).
template <class Scalar, class Covariates>
std::optional<Rejection> make_problem(
    const Covariates& covariates, const std::vector<Scalar>& weights,
    const std::optional<std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>>>& interval,
    Problem<Scalar>& problem) {
  const std::size_t n = covariates.size();
  if (!weights.empty() && weights.size() != n) {
    return Rejection{"weights and observations differ in length (" +
                     std::to_string(weights.size()) + " vs " + std::to_string(n) + ")"};
  }
  const Scalar* const weight_data = weights.empty() ? nullptr : weights.data();
  const auto survey = CovariateSurvey<Scalar>::over(covariates, weight_data, interval, 0, n);
  CovariateFrame<Scalar> frame;
  if (auto rejection = covariate_frame(survey, weight_data != nullptr, interval, frame)) {
    return rejection;
  }
  normalise_covariates(covariates, weight_data, frame, problem);
  return set_design(DesignSums<Scalar>::over(problem), problem);
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

// The first observation of [begin, end) that is not finite or not an
// element of G (to `tolerance`), as index i + offset; `add` keeps the
// smaller index, so chunks join in any order (chunked_fit.hpp).
struct ObservationFinding {
  std::ptrdiff_t index = -1;  // the first observation that fails, or -1
  bool finite = true;         // whether it fails by non-finite entries or by membership

  template <class G, class Observations>
  static ObservationFinding over(const Observations& observations, typename G::Scalar tolerance,
                                 std::size_t begin, std::size_t end, std::size_t offset = 0) {
    for (std::size_t i = begin; i < end; ++i) {
      const typename G::Element& f = observations[i];
      const auto index = static_cast<std::ptrdiff_t>(i + offset);
      if (!f.allFinite()) return ObservationFinding{index, false};
      if (!G::is_element(f, tolerance)) return ObservationFinding{index, true};
    }
    return ObservationFinding{};
  }
  void add(const ObservationFinding& other) {
    if (other.index >= 0 && (index < 0 || other.index < index)) *this = other;
  }
};

// The refusal of a finding (none when it found nothing).
template <class G>
std::optional<Rejection> observation_rejection(const ObservationFinding& found,
                                               typename G::Scalar tolerance) {
  if (found.index < 0) return std::nullopt;
  const std::string observation = "observation " + std::to_string(found.index);
  if (!found.finite) return Rejection{observation + " has non-finite entries", found.index};
  return Rejection{observation + " is not an element of " + G::name + " (to tolerance " +
                       std::to_string(double(tolerance)) + ")",
                   found.index};
}

// Every observation finite and in the group (to `tolerance`); the first
// that is not is named. By chunks on `pool` when one is given.
template <class G, class Observations>
std::optional<Rejection> check_observations(const Observations& observations,
                                            typename G::Scalar tolerance,
                                            ChunkPool* pool = nullptr) {
  const ObservationFinding found = reduce_chunks<ObservationFinding>(
      observations.size(), pool,
      [&](std::size_t begin, std::size_t end) {
        return ObservationFinding::over<G>(observations, tolerance, begin, end);
      },
      [](ObservationFinding& first, const ObservationFinding& next) { first.add(next); });
  return observation_rejection<G>(found, tolerance);
}

}  // namespace bireg
