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

// By chunks on `pool` when one is given (parallel.hpp: the same sums for
// any thread count).
template <class G, class Observations>
ChartStart<G> chart_start(const Observations& observations,
                          const Problem<typename G::Scalar>& problem, ChunkPool* pool = nullptr) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  const typename G::Element& f_ref = observations[middle_observation(problem)];
  const typename G::Element f_ref_inverse = G::inverse(f_ref);
  // sum w (1 - t) y, sum w t y and sum w |y|^2 over a chunk, or the first
  // observation of the chunk whose y_i is not finite or too large.
  struct Sums {
    Tangent moment0 = Tangent::Zero(), moment1 = Tangent::Zero();
    Scalar square_sum = 0;
    std::ptrdiff_t no_logarithm = -1, too_large = -1;
    bool outside() const { return no_logarithm >= 0 || too_large >= 0; }
  };
  const Sums sums = reduce_chunks<Sums>(
      observations.size(), pool,
      [&](std::size_t begin, std::size_t end) {
        Sums chunk;
        for (std::size_t i = begin; i < end; ++i) {
          const Tangent y = G::log(G::compose(f_ref_inverse, observations[i]));
          const bool finite = y.allFinite();
          if (!finite || y.cwiseAbs().maxCoeff() > largest_tangent<Scalar>()) {
            (finite ? chunk.too_large : chunk.no_logarithm) = static_cast<std::ptrdiff_t>(i);
            return chunk;
          }
          chunk.moment0 += problem.w[i] * (1 - problem.t[i]) * y;
          chunk.moment1 += problem.w[i] * problem.t[i] * y;
          chunk.square_sum += problem.w[i] * y.squaredNorm();
        }
        return chunk;
      },
      [](Sums& total, const Sums& next) {
        if (total.outside()) return;  // the first such observation is the one reported
        if (next.outside()) {
          total = next;
          return;
        }
        total.moment0 += next.moment0;
        total.moment1 += next.moment1;
        total.square_sum += next.square_sum;
      });
  ChartStart<G> chart;
  chart.reference = f_ref;
  if (sums.outside()) {
    chart.g0 = chart.g1 = f_ref;
    chart.no_logarithm = sums.no_logarithm;
    chart.too_large = sums.too_large;
    return chart;
  }
  const auto [x0, x1] = least_squares_line(problem, sums.moment0, sums.moment1);
  const Tangent total = sums.moment0 + sums.moment1;  // sum w y
  chart.g0 = exp_at<G>(f_ref, x0);
  chart.g1 = exp_at<G>(f_ref, x1);
  chart.spread = std::max(Scalar(0), sums.square_sum - total.squaredNorm() / problem.weight_sum);
  return chart;
}

}  // namespace bireg
