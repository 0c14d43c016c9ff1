// bireg: where the iteration starts, from one pass over the data in the log
// chart at f_ref, the observation nearest the middle of the covariate range,
// y_i = log(f_ref^{-1} f_i). It gives
//
//  * the default start: the weighted least-squares line y_i ~ (1 - t_i) x0
//    + t_i x1, i.e. (x0, x1) = (H^{-1} kron I)(sum w (1-t) y, sum w t y),
//    (g0, g1) = (f_ref exp(x0), f_ref exp(x1)). It is exact on commutative
//    groups, first-order accurate otherwise, and, like the iteration,
//    equivariant under left and right translation and inversion (the chart
//    moves with f_ref), so the whole fit stays equivariant. The middle
//    observation keeps the chart's distortion smallest for the endpoints;
//  * the fallback start, f_ref as a constant geodesic, for a start whose
//    geodesic leaves the series' disc or the log's domain;
//  * the data's spread about their mean in that chart, sum w |y_i - ybar|^2:
//    on commutative groups exactly the total sum of squares of ordinary
//    regression; otherwise the spread about the bi-invariant mean up to
//    terms of third order in the data's radius;
//  * the check that the data fit in the scalar's range: every later sum
//    squares tangent coordinates of the size of y_i, so |y_i| must stay
//    below largest_tangent<Scalar>(). The check is on y_i, not on the
//    observations, so it is left and right invariant like the fit: poses
//    1e200 away from the origin but close to each other are fine.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "bireg/geodesic.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

// The largest tangent coordinate the fit accepts: 2^-20 sqrt(max), so that
// squares summed over up to 2^40 observations stay finite (1.3e148 in
// double, 1.8e13 in float).
template <class Scalar>
Scalar largest_tangent() {
  using std::sqrt;
  return sqrt(std::numeric_limits<Scalar>::max()) / Scalar(1048576);
}

template <class G>
struct ChartStart {
  typename G::Element g0, g1;
  typename G::Element reference;  // the observation nearest the middle of the covariates
  typename G::Scalar spread = 0;
  std::ptrdiff_t no_logarithm = -1;  // an observation whose log was not finite
  std::ptrdiff_t too_large = -1;     // an observation whose |y_i| exceeds largest_tangent
};

// The index of the observation nearest the middle of the unit interval
// (the first of equals): the chart's reference, and the fallback start.
template <class Scalar>
std::size_t middle_observation(const Problem<Scalar>& problem) {
  using std::abs;
  std::size_t middle = 0;
  for (std::size_t i = 1; i < problem.size(); ++i) {
    if (abs(problem.t[i] - Scalar(0.5)) < abs(problem.t[middle] - Scalar(0.5))) middle = i;
  }
  return middle;
}

// The same over chunks of a larger set (chunked_fit.hpp): a chunk's
// observation nearest the middle, named i + offset, and the observation
// itself; `add` keeps the nearer (the smaller index of equals), in either
// order. problem.t[i] belongs to observation i.
template <class G>
struct MiddleCandidate {
  using Scalar = typename G::Scalar;
  std::ptrdiff_t index = -1;
  Scalar distance = std::numeric_limits<Scalar>::infinity();
  typename G::Element element = G::identity();

  template <class Observations>
  static MiddleCandidate over(const Observations& observations, const Problem<Scalar>& problem,
                              std::size_t begin, std::size_t end, std::size_t offset = 0) {
    using std::abs;
    MiddleCandidate middle;
    for (std::size_t i = begin; i < end; ++i) {
      const Scalar distance = abs(problem.t[i] - Scalar(0.5));
      if (distance < middle.distance) {
        middle.distance = distance;
        middle.index = static_cast<std::ptrdiff_t>(i + offset);
      }
    }
    if (middle.index >= 0) middle.element = observations[std::size_t(middle.index) - offset];
    return middle;
  }
  void add(const MiddleCandidate& other) {
    if (other.index < 0) return;
    if (index < 0 || other.distance < distance ||
        (other.distance == distance && other.index < index)) {
      *this = other;
    }
  }
};

// The weighted least-squares line y_i ~ (1 - t_i) x0 + t_i x1 from its
// moments, moment0 = sum w (1 - t) y and moment1 = sum w t y:
// (x0, x1) = (H^{-1} kron I)(moment0, moment1).
template <class Scalar, class Tangent>
std::pair<Tangent, Tangent> least_squares_line(const Problem<Scalar>& problem,
                                               const Tangent& moment0, const Tangent& moment1) {
  const Scalar determinant = problem.determinant();
  return {(problem.c * moment0 - problem.b * moment1) / determinant,
          (problem.a * moment1 - problem.b * moment0) / determinant};
}

// The chart's sums over observations [begin, end) at f_ref:
// sum w (1 - t) y, sum w t y and sum w |y|^2 with y_i = log(f_ref^{-1} f_i),
// or the first observation (index i + offset) whose y_i is not finite or
// too large, where the pass stops. `add` joins two chunks' sums in either
// order (the smaller index wins). problem.t[i] and
// problem.w[i] belong to observation i.
template <class G>
struct ChartSums {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  Tangent moment0 = Tangent::Zero(), moment1 = Tangent::Zero();
  Scalar square_sum = 0;
  std::ptrdiff_t outside_index = -1;  // the first observation without a usable y_i
  bool outside_finite = false;        // its y_i is finite (too large) or not (no logarithm)

  bool outside() const { return outside_index >= 0; }

  template <class Observations>
  static ChartSums over(const Observations& observations, const Problem<Scalar>& problem,
                        const typename G::Element& f_ref_inverse, std::size_t begin,
                        std::size_t end, std::size_t offset = 0) {
    ChartSums sums;
    for (std::size_t i = begin; i < end; ++i) {
      const Tangent y = G::log(G::compose(f_ref_inverse, observations[i]));
      const bool finite = y.allFinite();
      if (!finite || y.cwiseAbs().maxCoeff() > largest_tangent<Scalar>()) {
        sums.outside_index = static_cast<std::ptrdiff_t>(i + offset);
        sums.outside_finite = finite;
        return sums;
      }
      const Scalar t = problem.t[i], w = problem.w[i];
      sums.moment0 += w * (1 - t) * y;
      sums.moment1 += w * t * y;
      sums.square_sum += w * y.squaredNorm();
    }
    return sums;
  }

  void add(const ChartSums& other) {
    if (outside() || other.outside()) {
      if (other.outside() && (!outside() || other.outside_index < outside_index)) *this = other;
      return;
    }
    moment0 += other.moment0;
    moment1 += other.moment1;
    square_sum += other.square_sum;
  }
};

// The start from the chart's sums over all observations at f_ref.
template <class G>
ChartStart<G> chart_from_sums(const typename G::Element& f_ref,
                              const Problem<typename G::Scalar>& problem,
                              const ChartSums<G>& sums) {
  using Scalar = typename G::Scalar;
  ChartStart<G> chart;
  chart.reference = f_ref;
  if (sums.outside()) {
    chart.g0 = chart.g1 = f_ref;
    (sums.outside_finite ? chart.too_large : chart.no_logarithm) = sums.outside_index;
    return chart;
  }
  const auto [x0, x1] = least_squares_line(problem, sums.moment0, sums.moment1);
  const typename G::Tangent total = sums.moment0 + sums.moment1;  // sum w y
  chart.g0 = exp_at<G>(f_ref, x0);
  chart.g1 = exp_at<G>(f_ref, x1);
  chart.spread = std::max(Scalar(0), sums.square_sum - total.squaredNorm() / problem.weight_sum);
  return chart;
}

// By chunks on `pool` when one is given (parallel.hpp: the same sums for
// any thread count).
template <class G, class Observations>
ChartStart<G> chart_start(const Observations& observations,
                          const Problem<typename G::Scalar>& problem, ChunkPool* pool = nullptr) {
  const typename G::Element& f_ref = observations[middle_observation(problem)];
  const typename G::Element f_ref_inverse = G::inverse(f_ref);
  const ChartSums<G> sums = reduce_chunks<ChartSums<G>>(
      observations.size(), pool,
      [&](std::size_t begin, std::size_t end) {
        return ChartSums<G>::over(observations, problem, f_ref_inverse, begin, end);
      },
      [](ChartSums<G>& total, const ChartSums<G>& next) { total.add(next); });
  return chart_from_sums<G>(f_ref, problem, sums);
}

// Why the chart refuses the data, or nothing: an observation with no
// logarithm from the middle one, or one too far from it.
template <class G>
std::optional<Rejection> chart_rejection(const ChartStart<G>& chart) {
  if (chart.no_logarithm >= 0) {
    return Rejection{"observation " + std::to_string(chart.no_logarithm) +
                         " is out of reach of the middle observation: no principal logarithm "
                         "of f_mid^{-1} f_i (the data leave the domain of " +
                         G::name + "'s log)",
                     chart.no_logarithm};
  }
  if (chart.too_large >= 0) {
    return Rejection{"observation " + std::to_string(chart.too_large) +
                         " lies too far from the middle observation: log(f_mid^{-1} f_i) has "
                         "coordinates above " +
                         std::to_string(double(largest_tangent<typename G::Scalar>())) +
                         ", whose squares the fit cannot sum in this scalar type",
                     chart.too_large};
  }
  return std::nullopt;
}

// The refusal of a start whose estimating equations are not finite,
// naming the first observation whose residual there is not (-1: none).
template <class G>
Rejection unevaluable_start(std::ptrdiff_t first_bad) {
  const std::string which = first_bad >= 0
                                ? "the residual of observation " + std::to_string(first_bad)
                                : std::string("the estimating equations");
  return {which +
              " is not finite at the start: the data span magnitudes that this scalar type "
              "cannot invert and take the log of in " +
              G::name,
          first_bad};
}

}  // namespace bireg
