// bireg: the roughness penalty of a spline regression
// (SplineOptions::roughness_penalty, docs/splines.md §12) by
// cross-validation, with the folds and the invariant criterion of the knot
// spacing's selection (statistics/smoothing/spline_knots.hpp).
//
// The knots stay where the caller put them (fine, about one per sample or
// two); lambda trades the fit to the data against the second differences
// of the increments. Every lambda on the grid is scored as a knot spacing
// is: the fit to all observations, then each fold held out and fitted from
// it, det(S)^(1/d) of the held-out prediction errors. Lambda scales F's
// penalty term against its data term, whose size is the weight of the
// observations near a control point, so the automatic grid is in units of
// the observations per knot span. Left and right invariant as the knot
// spacing's choice is: the penalty and the residuals move by the same Ad.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "bireg/statistics/smoothing/spline_knots.hpp"

namespace bireg {

// The curve over lambda (SplineGridCurve: criterion, failures, refusals
// per value) and the choice.
template <class Scalar>
struct RoughnessPenaltySelection : SplineGridCurve<Scalar> {
  Scalar roughness_penalty = 0;  // the choice (0: none)
  bool ok() const { return roughness_penalty > 0; }
};

// Geometric, at least four values a decade, in units of w = N / S, the
// observations per knot span (S = ceil(range / h) spans, at least 1). In
// R^n the penalised fit is a kernel smoother whose window is about
// (lambda / w)^(1/4) knot spans (the second-difference P-spline's), so the
// grid runs from 1e-4 w (a tenth of a span: the penalty barely felt) to
// w W^4 with W = min(S, 100) the widest window: a window of the whole
// range or of a hundred spans, whichever is shorter. Empty when the
// covariates have no range or the spacing is not positive and finite.
constexpr int kRoughnessValuesPerDecade = 4;

template <class Scalar>
std::vector<Scalar> auto_roughness_penalty_grid(const std::vector<Scalar>& covariates,
                                                Scalar knot_spacing) {
  using std::ceil;
  using std::log10;
  using std::pow;
  std::vector<Scalar> grid;
  if (covariates.size() < 2 || !(knot_spacing > 0) || !std::isfinite(knot_spacing)) return grid;
  const auto [lowest, highest] = std::minmax_element(covariates.begin(), covariates.end());
  const Scalar range = *highest - *lowest;
  if (!(range > 0) || !std::isfinite(range)) return grid;
  const Scalar spans = std::max(Scalar(1), ceil(range / knot_spacing));
  const Scalar per_span = Scalar(covariates.size()) / spans;
  const Scalar widest = std::min(spans, Scalar(100));
  const Scalar low = Scalar(-4);
  const Scalar high = Scalar(4) * log10(widest);
  const int values = 1 + static_cast<int>(ceil(Scalar(kRoughnessValuesPerDecade) * (high - low)));
  for (int v = 0; v < values; ++v)
    grid.push_back(per_span * pow(Scalar(10), low + (high - low) * Scalar(v) / Scalar(values - 1)));
  return grid;
}

// The knots of a penalised spline when none are given: 1.5 median
// covariate spacings, as coarse as the x-IMU recording's velocity allowed
// without loss (docs/splines.md §12); lambda then does the smoothing. Never
// more spans than a fold of 4/5 of the N observations has observations
// less 4, whatever the spacings' spread, so that on small or bursty data
// the folds' fits still rest on their data more than on the penalty. 0
// when the covariates have no spacing.
template <class Scalar>
Scalar fine_knot_spacing(std::vector<Scalar> covariates) {
  std::sort(covariates.begin(), covariates.end());
  const Scalar gap = median_covariate_gap(covariates);
  if (!(gap > 0)) return Scalar(0);
  const Scalar range = covariates.back() - covariates.front();
  const auto fold = static_cast<std::ptrdiff_t>(covariates.size() * 4 / 5);
  const Scalar most_spans = Scalar(std::max<std::ptrdiff_t>(1, fold - 4));
  return std::max(Scalar(1.5) * gap, range / most_spans);
}

// Cross-validates the grid of lambdas (ascending, positive) with `folds`
// folds (at least 2). `options` gives everything but lambda and the
// interval: a finite knot spacing and degree 2 or 3. Once the criterion
// has not gone below its smallest for 2 decades of lambda (the grid's
// values past it up to 100 times it), the larger values are not tried
// (refused as "not tried"): each costs 1 + folds fits, and a wider grid
// mostly lies on the side where the curve flattens towards a geodesic.
// `progress` as for select_knot_spacing.
template <class G, class Observations, class Covariates>
RoughnessPenaltySelection<typename G::Scalar> select_roughness_penalty(
    const Observations& observations, const Covariates& covariates,
    const SplineOptions<typename G::Scalar>& options, const std::vector<typename G::Scalar>& grid,
    std::size_t folds = 5, const std::function<void(std::size_t, std::size_t)>& progress = {}) {
  using Scalar = typename G::Scalar;
  RoughnessPenaltySelection<Scalar> selection;
  selection.grid = grid;
  const auto refuse_all = [&](const std::string& message) {
    detail::refuse_every_value(selection, message);
    return selection;
  };
  if (options.degree < 2 || options.degree > 3) {
    return refuse_all(
        "roughness penalty selection needs degree 2 or 3 (the penalty couples "
        "control points two apart)");
  }
  if (!(options.knot_spacing > 0) || !std::isfinite(double(options.knot_spacing))) {
    return refuse_all("roughness penalty selection needs a finite positive knot spacing");
  }
  const std::size_t n = observations.size();
  if (grid.empty() || folds < 2 || covariates.size() != n || n < 2 * folds) {
    return refuse_all(
        "roughness penalty selection needs a grid, at least 2 folds and at least 2 "
        "observations per fold");
  }
  const std::string bad_grid = detail::grid_problem(grid, "roughness penalty", false);
  if (!bad_grid.empty()) return refuse_all(bad_grid);
  const auto dealt = detail::deal_spline_folds<Scalar>(covariates, folds);
  SplineOptions<Scalar> fixed = options;
  fixed.interval = dealt.interval;
  const std::size_t fits = grid.size() * (1 + folds);
  std::size_t fits_done = 0;
  const std::function<void()> after_fit = [&] { progress(++fits_done, fits); };
  std::size_t best = grid.size();
  for (std::size_t v = 0; v < grid.size(); ++v) {
    const Scalar lambda = grid[v];
    if (best < grid.size() && lambda > Scalar(100) * grid[best]) {
      fits_done += 1 + folds;
      selection.criterion.push_back(std::numeric_limits<Scalar>::infinity());
      selection.failures.push_back(0);
      selection.refusals.push_back("not tried: the criterion stayed above its value at lambda " +
                                   std::to_string(double(grid[best])) + " for two decades past it");
      continue;
    }
    fixed.roughness_penalty = lambda;
    const auto score = detail::spline_cross_validation_score(
        SplineRegression<G>(fixed), observations, covariates, dealt,
        progress ? after_fit : std::function<void()>());
    selection.criterion.push_back(score.criterion);
    selection.failures.push_back(score.failures);
    selection.refusals.push_back(score.refusal);
    if (score.refusal.empty() &&
        (best == grid.size() || score.criterion < selection.criterion[best]))
      best = v;
  }
  if (progress) progress(fits, fits);
  if (detail::settle_choice(selection, best, "roughness penalty"))
    selection.roughness_penalty = grid[best];
  return selection;
}

}  // namespace bireg
