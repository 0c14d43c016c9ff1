// bireg: what a fit reports beside its endpoints, written in one place
// (diagnose) from the problem, the step rule, the iteration's record and
// the returned state.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "bireg/groups/capabilities.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/iteration.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

template <class Scalar>
struct RegressionDiagnostics {
  Scalar mu_min = 0;  // eigenvalues of H (Lemma 3.7, unit covariate interval)
  Scalar mu_max = 0;
  // mu_max / mu_min: how well the covariates pin down the slope. The paper
  // solver needs ~condition_number iterations; the slope's error grows
  // like sqrt(condition_number) times the noise.
  Scalar condition_number = 0;
  Scalar step_size = 0;  // lambda used (1 for preconditioned and gauss_newton)
  // Step halvings of the safeguard (every solver but paper): a step that
  // would increase ||v|| is halved until it does not.
  int backtracks = 0;
  // Ratio of the last two step norms: the observed linear rate, which the
  // theory bounds by 1 - lambda eta (Theorem 4.8; by max|1 - lambda mu| on
  // commutative groups).
  Scalar contraction_factor = 0;
  int series_order = 0;                // at the returned endpoints (0: closed form)
  Scalar series_truncation_bound = 0;  // relative size of the omitted terms
  // ||(v0, v1)|| at the returned endpoints (0 when they are outside the
  // series' disc: series_diverged).
  Scalar force_norm = 0;
  // sqrt(sum w_i |r_i|^2 / sum w_i), residuals about the fitted geodesic,
  // and the data's spread about their mean, sqrt(sum w_i |y_i - ybar|^2 /
  // sum w_i) with y_i = log(f_ref^{-1} f_i) in the chart at the middle
  // observation (the constant model; see start.hpp).
  Scalar residual_rms = 0;
  Scalar residual_rms_about_mean = 0;
  // 1 - residual_rms^2 / residual_rms_about_mean^2: the share of the data's
  // spread that the geodesic explains. On R^n it is the ordinary R^2. Norms
  // are Euclidean in the tangent coordinates (which mix units on SE(3));
  // 1 when the data do not spread.
  Scalar explained_variance = 0;
  // The largest rotation angle of a residual, measured by the spectral
  // radius of ad_{r_i} (the rotation angle on SO(2), SO(3), SE(2), SE(3),
  // the largest part's on products, 0 on R^n; on Sim(3) |sigma + i theta|,
  // so a residual scale factor beyond e^{3 pi / 4} = 10.5 counts too), and
  // its observation. Computed for groups that give
  // the spectral radius in closed form (groups/capabilities.hpp); -1 and 0
  // for the others. beyond_domain: the angle exceeds kBeyondDomainAngle =
  // 3 pi / 4, i.e. an observation lies near the log's cut locus (pi) as
  // seen from the fitted geodesic. Then the data turn by more than pi along
  // the covariate (or that observation is a gross outlier), and the
  // estimating equations, built on the principal log, no longer describe
  // the data: a fit can converge there with a meaningless answer. Measured
  // (tests/test_stability.cpp): such fits of data turning 3.2 to 13 rad
  // end with angles of 2.99 to 3.14; noisy data within the domain stay at
  // a few noise levels.
  Scalar largest_residual_angle = 0;
  std::ptrdiff_t largest_residual_observation = -1;
  bool beyond_domain = false;
};

// Three quarters of the way to the cut locus of the principal log.
template <class Scalar>
constexpr Scalar kBeyondDomainAngle = Scalar(0.75L * 3.14159265358979323846264338327950288L);

// sum w |r_i|^2 and the largest residual angle with its observation (the
// smallest index of equals) over residuals [begin, end), named i + offset;
// and the first residual that is not finite. `add` joins two chunks' sums
// in either order. problem.w[i] belongs to residual i.
template <class G>
struct ResidualSums {
  using Scalar = typename G::Scalar;
  Scalar residual_sum = 0;
  Scalar largest_angle = 0;
  std::ptrdiff_t largest_observation = -1;
  std::ptrdiff_t not_finite = -1;

  static ResidualSums over(const Problem<Scalar>& problem,
                           const std::vector<typename G::Tangent>& residuals, std::size_t begin,
                           std::size_t end, std::size_t offset = 0) {
    ResidualSums sums;
    for (std::size_t i = begin; i < end; ++i) {
      const Scalar w = problem.w[i];
      if (sums.not_finite < 0 && !residuals[i].allFinite())
        sums.not_finite = static_cast<std::ptrdiff_t>(i + offset);
      sums.residual_sum += w * residuals[i].squaredNorm();
      if constexpr (provides_v<G, capability_detail::ad_spectral_radius>) {
        if (w == 0) continue;  // a zero weight takes the observation out of the fit
        const Scalar angle = G::ad_spectral_radius(residuals[i]);
        if (angle > sums.largest_angle) {
          sums.largest_angle = angle;
          sums.largest_observation = static_cast<std::ptrdiff_t>(i + offset);
        }
      }
    }
    return sums;
  }

  void add(const ResidualSums& other) {
    residual_sum += other.residual_sum;
    if (other.largest_angle > largest_angle ||
        (other.largest_angle == largest_angle && other.largest_observation >= 0 &&
         (largest_observation < 0 || other.largest_observation < largest_observation))) {
      largest_angle = other.largest_angle;
      largest_observation = other.largest_observation;
    }
    if (other.not_finite >= 0 && (not_finite < 0 || other.not_finite < not_finite))
      not_finite = other.not_finite;
  }
};

// The diagnostics from the residuals' sums over all observations.
template <class G, class Rule>
RegressionDiagnostics<typename G::Scalar> diagnose_from_sums(
    const Problem<typename G::Scalar>& problem, const Rule& rule, const IterationRecord<G>& record,
    const State<G>& state, typename G::Scalar spread, const ResidualSums<G>& sums) {
  using Scalar = typename G::Scalar;
  using std::sqrt;
  RegressionDiagnostics<Scalar> d;
  d.mu_min = problem.mu_min;
  d.mu_max = problem.mu_max;
  d.condition_number = problem.mu_max / problem.mu_min;
  d.step_size = rule.step_size();
  d.backtracks = record.backtracks;
  d.series_order = state.order;
  d.series_truncation_bound = state.truncation;
  if (state.series_converges) d.force_norm = state.force.norm();
  const std::size_t steps = record.step_norms.size();
  if (steps >= 2 && record.step_norms[steps - 2] > 0) {
    d.contraction_factor = record.step_norms[steps - 1] / record.step_norms[steps - 2];
  }
  const Scalar residual_sum = sums.residual_sum;
  d.residual_rms = sqrt(residual_sum / problem.weight_sum);
  d.residual_rms_about_mean = sqrt(spread / problem.weight_sum);
  d.explained_variance = spread > 0 ? 1 - residual_sum / spread : Scalar(1);
  if constexpr (provides_v<G, capability_detail::ad_spectral_radius>) {
    d.largest_residual_angle = sums.largest_angle;
    d.largest_residual_observation = sums.largest_observation;
    d.beyond_domain = d.largest_residual_angle > kBeyondDomainAngle<Scalar>;
  }
  return d;
}

// The diagnostics of a fit whose residuals are all here, by chunks on
// `pool` when one is given.
template <class G, class Rule>
RegressionDiagnostics<typename G::Scalar> diagnose(
    const Problem<typename G::Scalar>& problem, const Rule& rule, const IterationRecord<G>& record,
    const State<G>& state, typename G::Scalar spread,
    const std::vector<typename G::Tangent>& residuals, ChunkPool* pool = nullptr) {
  const ResidualSums<G> sums = reduce_chunks<ResidualSums<G>>(
      residuals.size(), pool,
      [&](std::size_t begin, std::size_t end) {
        return ResidualSums<G>::over(problem, residuals, begin, end);
      },
      [](ResidualSums<G>& total, const ResidualSums<G>& next) { total.add(next); });
  return diagnose_from_sums<G>(problem, rule, record, state, spread, sums);
}

}  // namespace bireg
