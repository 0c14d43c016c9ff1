// bireg: the knot spacing of a spline regression (bireg/spline_regression.hpp)
// by cross-validation, the criterion of the local regression's bandwidth
// (statistics/smoothing/bandwidth.hpp).
//
// The observations, in covariate order, are dealt into F folds (the r-th
// into fold r mod F: every fold spans the whole range, so no fold leaves a
// knot span empty by construction). For each spacing on the grid, each
// fold is held out in turn and the spline is fitted to the rest on the
// knots of the full data (the interval is fixed to the data's range, so
// the held-out covariates stay inside), warm-started from the full fit;
// the prediction errors e_i = log(T(t_i)^{-1} f_i) of the held-out
// observations give S = (1/N) sum e_i e_i^T and the criterion det(S)^(1/d).
// Left translation of the data leaves every e_i unchanged; right
// translation by g maps it to Ad_{g^{-1}} e_i and multiplies every det(S)
// by the same det(Ad_{g^{-1}})^2, so the choice is left and right
// invariant.
//
// A spacing is refused only for a stated reason: its full fit or one of
// its folds' fits failed (the message of the first failure is kept, e.g.
// a fold whose observations leave a knot span without data), and every
// refusal is reported. Once the fit to all observations fails at some
// spacing after succeeding at a narrower one, the wider spacings are not
// tried (refused as "not tried"): knots too sparse for the motion only get
// sparser, and each failing fit costs its iteration limit. The choice is the smallest criterion
// among the spacings not refused.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/spline_regression.hpp"

namespace bireg {

// What a spline's cross-validation over a grid reports, whatever the grid
// is of (knot spacings here, roughness penalties in spline_roughness.hpp).
template <class Scalar>
struct SplineGridCurve {
  std::vector<Scalar> grid;  // ascending
  // det(S)^(1/d) per grid value; infinite where refused.
  std::vector<Scalar> criterion;
  // Per grid value: the fits that failed (the full fit counts as one) and
  // why the value was refused (empty: it was not).
  std::vector<std::size_t> failures;
  std::vector<std::string> refusals;
  // The choice is the grid's first or last value: the best may lie beyond.
  bool at_edge = false;
  // What a user should be told (a choice at the edge, why nothing could be
  // chosen); empty when there is nothing to say.
  std::string message;
};

template <class Scalar>
struct KnotSpacingSelection : SplineGridCurve<Scalar> {
  Scalar knot_spacing = 0;  // the choice (0: none)
  bool ok() const { return knot_spacing > 0; }
};

// The median of the positive gaps between sorted covariates; 0 when there
// is none (fewer than two distinct covariates).
template <class Scalar>
Scalar median_covariate_gap(const std::vector<Scalar>& sorted) {
  std::vector<Scalar> gaps;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    if (sorted[i] > sorted[i - 1]) gaps.push_back(sorted[i] - sorted[i - 1]);
  }
  if (gaps.empty()) return Scalar(0);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

// 24 spacings, geometric, from 1.25 median covariate spacings (fewer
// control points than observations) to the whole range (one segment).
template <class Scalar>
std::vector<Scalar> auto_knot_spacing_grid(std::vector<Scalar> covariates) {
  std::vector<Scalar> grid;
  std::sort(covariates.begin(), covariates.end());
  if (covariates.size() < 2) return grid;
  const Scalar gap = median_covariate_gap(covariates);
  const Scalar range = covariates.back() - covariates.front();
  if (!(gap > 0) || !(range > 0)) return grid;
  const Scalar smallest = std::min(range, Scalar(1.25) * gap);
  constexpr int kValues = 24;
  for (int v = 0; v < kValues; ++v)
    grid.push_back(smallest * std::pow(range / smallest, Scalar(v) / Scalar(kValues - 1)));
  return grid;
}

namespace detail {

// What both selections below share: the folds (the r-th observation in
// covariate order in fold r mod F), the interval of the data's range, and
// the cross-validated criterion of one SplineOptions.
template <class Scalar>
struct SplineFolds {
  std::vector<std::size_t> fold_of;
  std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>> interval;
  std::size_t folds = 0;
};

template <class Scalar, class Covariates>
SplineFolds<Scalar> deal_spline_folds(const Covariates& covariates, std::size_t folds) {
  const std::size_t n = covariates.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return covariates[a] < covariates[b]; });
  SplineFolds<Scalar> dealt;
  dealt.folds = folds;
  dealt.fold_of.resize(n);
  for (std::size_t r = 0; r < n; ++r)
    dealt.fold_of[order[r]] = r % folds;
  dealt.interval = std::make_pair(CovariateScalar<Scalar>(covariates[order.front()]),
                                  CovariateScalar<Scalar>(covariates[order.back()]));
  return dealt;
}

template <class Scalar>
struct SplineScore {
  Scalar criterion = std::numeric_limits<Scalar>::infinity();
  std::size_t failures = 0;
  std::string refusal;   // empty: the criterion stands
  bool full_ok = false;  // the fit to all observations succeeded
};

// The fit to all observations, then each fold held out in turn and fitted
// from it; det(S)^(1/d) of the held-out prediction errors, or the first
// failure's message. `after_fit` (if set) is called after each of the
// 1 + folds fits, tried or not.
template <class G, class Observations, class Covariates>
SplineScore<typename G::Scalar> spline_cross_validation_score(
    const SplineRegression<G>& regression, const Observations& observations,
    const Covariates& covariates, const SplineFolds<typename G::Scalar>& dealt,
    const std::function<void()>& after_fit) {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using Covariance = Eigen::Matrix<Scalar, G::dof, G::dof>;
  const std::size_t n = observations.size();
  SplineScore<Scalar> score;
  const auto full = regression.fit(observations, covariates);
  if (after_fit) after_fit();
  score.full_ok = full.ok();
  if (!full.ok()) {
    for (std::size_t fold = 0; fold < dealt.folds && after_fit; ++fold)
      after_fit();
    score.failures = 1;
    score.refusal = std::string("the fit to all observations: ") +
                    (full.message.empty() ? to_string(full.status) : full.message);
    return score;
  }
  std::vector<Element> train_f;
  std::vector<Scalar> train_t;
  Covariance scatter = Covariance::Zero();
  for (std::size_t fold = 0; fold < dealt.folds; ++fold) {
    train_f.clear();
    train_t.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (dealt.fold_of[i] == fold) continue;
      train_f.push_back(observations[i]);
      train_t.push_back(covariates[i]);
    }
    const auto fit = regression.fit_from(full.spline->control_points(), train_f, train_t);
    if (after_fit) after_fit();
    if (!fit.ok()) {
      ++score.failures;
      if (score.refusal.empty()) {
        score.refusal = "fold " + std::to_string(fold) + ": " +
                        (fit.message.empty() ? to_string(fit.status) : fit.message);
      }
      continue;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (dealt.fold_of[i] != fold) continue;
      const Tangent e =
          G::log(G::compose(G::inverse((*fit.spline)(Scalar(covariates[i]))), observations[i]));
      scatter.noalias() += e * e.transpose();
    }
  }
  if (!score.refusal.empty()) return score;
  using std::pow;
  const Scalar determinant = (scatter / Scalar(n)).determinant();
  if (determinant > 0 && std::isfinite(determinant)) {
    score.criterion = pow(determinant, Scalar(1) / Scalar(G::dof));
  } else {
    score.refusal = "the prediction errors' covariance is singular or not finite";
  }
  return score;
}

// The index of the smallest criterion among the values not refused, or
// refusals.size() when every value was refused.
template <class Scalar>
std::size_t smallest_unrefused(const std::vector<Scalar>& criterion,
                               const std::vector<std::string>& refusals) {
  std::size_t best = refusals.size();
  for (std::size_t v = 0; v < refusals.size(); ++v) {
    if (!refusals[v].empty()) continue;
    if (best == refusals.size() || criterion[v] < criterion[best]) best = v;
  }
  return best;
}

// Nothing can be tried: every grid value refused for the one reason, so
// that the per-value vectors always match the grid.
template <class Scalar>
void refuse_every_value(SplineGridCurve<Scalar>& curve, const std::string& message) {
  curve.message = message;
  curve.criterion.assign(curve.grid.size(), std::numeric_limits<Scalar>::infinity());
  curve.failures.assign(curve.grid.size(), 0);
  curve.refusals.assign(curve.grid.size(), "not tried: " + message);
}

// The choice at grid index `best` (grid.size(): none) said in `curve`'s
// message where there is something to say; `what` names the grid's values
// ("knot spacing"). Returns whether there is a choice.
template <class Scalar>
bool settle_choice(SplineGridCurve<Scalar>& curve, std::size_t best, const std::string& what) {
  const std::size_t size = curve.grid.size();
  if (best == size) {
    curve.message = "every " + what + " was refused; the first: " + curve.refusals[0];
    return false;
  }
  curve.at_edge = best == 0 || best + 1 == size;
  if (curve.at_edge) {
    curve.message = "the chosen " + what + " is the grid's " +
                    (best == 0 ? "smallest" : "largest") +
                    " value: the best may lie beyond the grid";
  }
  return true;
}

// Empty when the grid is positive and ascending (and finite unless
// `infinite_allowed`: a knot spacing may be infinite, one segment), else
// what is wrong.
template <class Scalar>
std::string grid_problem(const std::vector<Scalar>& grid, const char* what, bool infinite_allowed) {
  for (std::size_t v = 0; v < grid.size(); ++v) {
    if (!(grid[v] > 0) || (!infinite_allowed && !std::isfinite(grid[v])) ||
        (v > 0 && !(grid[v] > grid[v - 1]))) {
      return std::string("the ") + what + " grid must be positive" +
             (infinite_allowed ? "" : ", finite") + " and ascending (value " + std::to_string(v) +
             ")";
    }
  }
  return {};
}

}  // namespace detail

// Cross-validates the grid (ascending, positive) with `folds` folds (at
// least 2). `options` gives everything but the spacing and the interval.
// `progress`, when set, is called with (fits done, fits in all) after each
// of the grid's (1 + folds) fits per value, values not tried counted done.
template <class G, class Observations, class Covariates>
KnotSpacingSelection<typename G::Scalar> select_knot_spacing(
    const Observations& observations, const Covariates& covariates,
    const SplineOptions<typename G::Scalar>& options, const std::vector<typename G::Scalar>& grid,
    std::size_t folds = 5, const std::function<void(std::size_t, std::size_t)>& progress = {}) {
  using Scalar = typename G::Scalar;
  KnotSpacingSelection<Scalar> selection;
  selection.grid = grid;
  const auto refuse_all = [&](const std::string& message) {
    detail::refuse_every_value(selection, message);
    return selection;
  };
  const std::size_t n = observations.size();
  if (grid.empty() || folds < 2 || covariates.size() != n || n < 2 * folds) {
    return refuse_all(
        "knot spacing selection needs a grid, at least 2 folds and at least 2 "
        "observations per fold");
  }
  const std::string bad_grid = detail::grid_problem(grid, "knot spacing", true);
  if (!bad_grid.empty()) return refuse_all(bad_grid);
  const auto dealt = detail::deal_spline_folds<Scalar>(covariates, folds);
  SplineOptions<Scalar> fixed = options;
  fixed.interval = dealt.interval;

  bool fitted = false;          // a narrower spacing's fit to all observations succeeded
  Scalar failed_after_fit = 0;  // the first spacing whose fit failed after one succeeded
  const std::size_t fits = grid.size() * (1 + folds);
  std::size_t fits_done = 0;
  const std::function<void()> after_fit = [&] { progress(++fits_done, fits); };
  for (const Scalar spacing : grid) {
    if (failed_after_fit > 0) {
      fits_done += 1 + folds;
      selection.criterion.push_back(std::numeric_limits<Scalar>::infinity());
      selection.failures.push_back(0);
      selection.refusals.push_back(
          "not tried: the fit to all observations failed at the narrower spacing " +
          std::to_string(double(failed_after_fit)) + " after a narrower one succeeded");
      continue;
    }
    fixed.knot_spacing = spacing;
    const auto score = detail::spline_cross_validation_score(
        SplineRegression<G>(fixed), observations, covariates, dealt,
        progress ? after_fit : std::function<void()>());
    if (score.full_ok) fitted = true;
    if (!score.full_ok && fitted) failed_after_fit = spacing;
    selection.criterion.push_back(score.criterion);
    selection.failures.push_back(score.failures);
    selection.refusals.push_back(score.refusal);
  }
  if (progress) progress(fits, fits);
  const std::size_t best = detail::smallest_unrefused(selection.criterion, selection.refusals);
  if (detail::settle_choice(selection, best, "knot spacing")) selection.knot_spacing = grid[best];
  return selection;
}

}  // namespace bireg
