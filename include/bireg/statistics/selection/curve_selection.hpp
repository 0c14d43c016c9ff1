// bireg: which curve the data need along their covariate: one geodesic,
// a piecewise geodesic, or a cubic spline (issue 32; docs/splines.md), by
// the criterion the other model selections use (selection/criteria.hpp).
//
// Candidates, for observations f_i of any group G at covariates t_i:
//
//   geodesic                GeodesicRegression                      k = 2 d
//   piecewise geodesic, S   SplineRegression, degree 1, S segments  k = (S + 1) d
//   cubic spline, S         SplineRegression, degree 3, S segments  k = (S + 3) d
//
// for every segment count S that a knot spacing of the grid gives (S >= 2
// for the piecewise geodesic: with one segment it is the geodesic; the
// fewest equal segments of the covariates' range no longer than it, as
// SplineOptions::knot_spacing; the grid by default auto_knot_spacing_grid:
// 24 spacings from 1.25 median sample spacings to the range). Each is scored
// with residuals r_i = log(P(t_i)^{-1} f_i) in G by
//
//   C = N/2 log det S_r + k/2 log N,     S_r = (1/N) sum r_i r_i^T,
//
// with criteria.hpp's eigenvalue floor, and the recommendation is, among the
// candidates within kSelectionMargin of the best C, the one with the fewest
// parameters (the smaller C between equals). Every candidate is left and
// right equivariant (Theorem 2.4; splines.md §6), so C is left invariant,
// and right invariant where det Ad = 1 (SO(3), SE(3)). BIC counts a
// spline's control points as free parameters; with knots chosen from a
// grid the count is the usual approximation (the knots themselves are not
// counted).
//
// Refusals as the other selections': lengths, covariates, observations
// (criteria.hpp's check_input), and a grid value that is not positive and
// finite, each named; a candidate that cannot be fitted (more control points
// than observations, Schoenberg-Whitney, a failed fit, a criterion that is
// not finite) is excluded with a note; with none left the status is
// no_candidate. Nothing in a result is NaN.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bireg/regression.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/selection/criteria.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"

namespace bireg {

struct CurveCandidate {
  int degree = 0;              // 0: the geodesic; 1: piecewise geodesic; 3: cubic spline
  std::size_t segments = 1;    // knot spans (1 for the geodesic)
  double knot_spacing = 0;     // the spans' length in covariate units
  std::size_t parameters = 0;  // k: control points (2 for the geodesic) times d
  bool fitted = false;         // false: excluded, `note` says why
  std::string note;
  double residual_rms = 0;  // RMS of |r_i| in G's tangent coordinates
  double log_det = 0;       // log det S_r with the eigenvalue floor
  double criterion = 0;     // N/2 log det S_r + k/2 log N
  bool within_margin = false;
  bool recommended = false;
};

inline std::string describe(const CurveCandidate& c) {
  if (c.degree == 0) return "geodesic";
  return std::string(c.degree == 1 ? "piecewise geodesic" : "cubic spline") + ", " +
         std::to_string(c.segments) + " segments";
}

struct CurveSelectionOptions {
  // Knot spacings to try (each positive and finite); empty: the
  // auto_knot_spacing_grid of the covariates.
  std::vector<double> knot_spacings;
  int threads = 1;  // for each spline fit's passes (the result does not depend on it)
};

template <class G>
struct CurveSelection {
  SelectionStatus status = SelectionStatus::invalid_input;
  std::ptrdiff_t bad_index = -1;  // invalid_input: the observation, covariate or grid value
  std::string message;
  // The geodesic, then for each segment count (ascending) the piecewise
  // geodesic (from 2 segments) and the cubic spline.
  std::vector<CurveCandidate> candidates;
  std::optional<std::size_t> recommended;  // index into candidates, when selected

  bool ok() const { return status == SelectionStatus::selected; }
};

template <class G, class Observations>
CurveSelection<G> select_curve(const Observations& observations, const std::vector<double>& times,
                               const CurveSelectionOptions& options = {}) {
  namespace detail = model_selection_detail;
  using Tangent = typename G::Tangent;
  CurveSelection<G> selection;
  const std::size_t n = observations.size();
  if (auto rejection = detail::check_input<G>(observations, times, std::max(1, options.threads))) {
    selection.message = rejection->message;
    selection.bad_index = rejection->index;
    return selection;
  }
  if (options.threads < 1) {
    selection.message = "threads must be at least 1, got " + std::to_string(options.threads);
    return selection;
  }
  const auto [smallest, largest] = std::minmax_element(times.begin(), times.end());
  const double range = *largest - *smallest;
  if (!(range > 0)) {
    selection.message = "all covariates are equal: no curve along them can be told apart";
    return selection;
  }
  const std::vector<double> grid =
      options.knot_spacings.empty() ? auto_knot_spacing_grid(times) : options.knot_spacings;
  std::vector<std::size_t> segment_counts;
  for (std::size_t v = 0; v < grid.size(); ++v) {
    if (!(grid[v] > 0) || !std::isfinite(grid[v])) {
      selection.message = "knot spacing " + std::to_string(v) +
                          " of the grid is not a positive "
                          "finite number";
      selection.bad_index = static_cast<std::ptrdiff_t>(v);
      return selection;
    }
    // The fewest equal segments no longer than the spacing (SplineOptions),
    // at most one per observation: more are refused by every fit anyway.
    const double count = std::max(1.0, std::ceil(range / grid[v] * (1 - 1e-12)));
    segment_counts.push_back(static_cast<std::size_t>(std::min(count, double(n))));
  }
  std::sort(segment_counts.begin(), segment_counts.end());
  segment_counts.erase(std::unique(segment_counts.begin(), segment_counts.end()),
                       segment_counts.end());

  const double n_real = static_cast<double>(n);
  const double floor = detail::determinant_floor<G>({}, observations);
  const auto score = [&](CurveCandidate& report, const std::vector<Tangent>& r) {
    double squares = 0;
    for (const Tangent& ri : r)
      squares += ri.squaredNorm();
    const double log_det = detail::floored_log_det(detail::residual_covariance(r), floor);
    const double criterion =
        n_real / 2 * log_det + double(report.parameters) / 2 * std::log(n_real);
    if (!std::isfinite(squares) || !std::isfinite(criterion)) {
      report.note = "excluded: its residuals' squares overflow (criterion not finite)";
      return;
    }
    report.fitted = true;
    report.residual_rms = std::sqrt(squares / n_real);
    report.log_det = log_det;
    report.criterion = criterion;
  };

  CurveCandidate geodesic;
  geodesic.knot_spacing = range;
  geodesic.parameters = 2 * std::size_t(G::dof);
  const auto line = GeodesicRegression<G>().fit(observations, times);
  if (line.ok()) {
    score(geodesic, line.residuals);
  } else {
    geodesic.note = std::string("excluded: its fit ended ") + to_string(line.status) +
                    (line.message.empty() ? "" : ": " + line.message);
  }
  selection.candidates.push_back(geodesic);
  for (const std::size_t segments : segment_counts) {
    for (const int degree : {1, 3}) {
      if (degree == 1 && segments == 1) continue;  // the geodesic itself
      CurveCandidate report;
      report.degree = degree;
      report.segments = segments;
      report.knot_spacing = range / double(segments);
      report.parameters = (segments + std::size_t(degree)) * std::size_t(G::dof);
      SplineOptions<typename G::Scalar> spline_options;
      spline_options.degree = degree;
      spline_options.knot_spacing = report.knot_spacing;
      spline_options.threads = options.threads;
      const auto fit = SplineRegression<G>(spline_options).fit(observations, times);
      if (fit.ok()) {
        score(report, fit.residuals);
      } else {
        std::string why = fit.message;  // a refusal says why itself
        if (fit.status != Status::invalid_input) {
          why = "its fit ended " + std::string(to_string(fit.status)) +
                (why.empty() ? "" : ": " + why);
        }
        report.note = "excluded: " + why;
      }
      selection.candidates.push_back(report);
    }
  }

  std::optional<double> best;
  for (const CurveCandidate& c : selection.candidates) {
    if (c.fitted && (!best || c.criterion < *best)) best = c.criterion;
  }
  if (!best) {
    selection.status = SelectionStatus::no_candidate;
    selection.message = "no curve could be fitted and scored (see each candidate's note)";
    return selection;
  }
  std::optional<std::size_t> winner;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    CurveCandidate& report = selection.candidates[c];
    report.within_margin = report.fitted && report.criterion <= *best + kSelectionMargin;
    if (!report.within_margin) continue;
    const CurveCandidate* current = winner ? &selection.candidates[*winner] : nullptr;
    if (!current || report.parameters < current->parameters ||
        (report.parameters == current->parameters && report.criterion < current->criterion)) {
      winner = c;
    }
  }
  selection.candidates[*winner].recommended = true;
  selection.recommended = winner;
  selection.status = SelectionStatus::selected;
  return selection;
}

}  // namespace bireg
