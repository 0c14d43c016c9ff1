// bireg: static against geodesic for data of any group G: does the
// element move along the covariate at all? DESIGN.md section 5. The
// criterion, its floor and margin, the refusals and the cross-validation
// are selection/criteria.hpp's.
//
// Data of any group G (orientations: SO(3)): does the element move along
// the covariate at all? select_static_or_geodesic compares
//
//   static            P(t) = m, the bi-invariant mean                          k = d
//   geodesic          P(t) = the geodesic fit                                  k = 2d
//
// (d = G::dof) with residuals log(P(t_i)^{-1} f_i) in G, and the same
// criterion, eigenvalue floor, margin and cross-validation as below. Both
// candidates are left and right equivariant (Theorem 2.4), so the criteria
// are left invariant, and right invariant where det Ad = 1 (SO(3), SE(3):
// every group whose Ad is orthogonal or unimodular).
//
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/geodesic.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/selection/criteria.hpp"

namespace bireg {

enum class TrendModel { static_element, geodesic };

inline const char* to_string(TrendModel model) {
  return model == TrendModel::static_element ? "static" : "geodesic";
}

struct TrendCandidate {
  TrendModel model = TrendModel::static_element;
  int parameters = 0;
  bool fitted = false;  // false: excluded, `note` says why
  std::string note;
  double residual_rms = 0;         // RMS of |r_i| in G's tangent coordinates
  double log_det = 0;              // log det S with the eigenvalue floor
  double criterion = 0;            // N/2 log det S + k/2 log N
  std::optional<double> cv_error;  // mean held-out |r|^2; empty if a fold failed
  bool within_margin = false;      // C <= best C + kSelectionMargin
  bool recommended = false;
};

template <class G>
struct TrendSelection {
  SelectionStatus status = SelectionStatus::invalid_input;
  std::ptrdiff_t bad_index = -1;  // invalid_input: the observation or covariate at fault, or -1
  std::vector<TrendCandidate> candidates;             // static, then geodesic
  std::optional<TrendModel> recommended;              // empty unless status is selected
  std::optional<typename G::Element> static_element;  // the mean, if fitted
  std::optional<Geodesic<G>> geodesic;  // the geodesic fit in the user's covariates, if fitted
  std::string message;

  bool ok() const { return status == SelectionStatus::selected; }
};

namespace model_selection_detail {

// The prediction of a static or geodesic candidate fitted to `observations`
// at centred covariates `times`. The static one is the constant geodesic
// (m, m) parametrised on `span` (the centred covariates' range, first <
// second): evaluated at any covariate of the data it computes
// m exp(s log(m^{-1} m)) with s in [0, 1], so the rounding-level
// log(m^{-1} m) (a few epsilon) stays at that level; on (0, 1) it would be
// multiplied by the covariate itself (1.4e18 for nanosecond timestamps).
template <class G, class Observations>
std::optional<Geodesic<G>> fit_trend_model(TrendModel model, const Observations& observations,
                                           const std::vector<double>& times,
                                           std::pair<double, double> span) {
  using Scalar = typename G::Scalar;
  if (model == TrendModel::static_element) {
    const auto m = mean<G>(observations);
    if (!m.ok()) return std::nullopt;
    return Geodesic<G>(*m.mean, *m.mean, static_cast<Scalar>(span.first),
                       static_cast<Scalar>(span.second));
  }
  const auto fit = GeodesicRegression<G>().fit(observations, times);
  if (!fit.ok()) return std::nullopt;
  return fit.geodesic;
}

template <class G>
typename G::Tangent trend_residual(const Geodesic<G>& prediction,
                                   const typename G::Element& observation, double t) {
  return G::log(G::compose(G::inverse(prediction(t)), observation));
}

}  // namespace model_selection_detail

// Static against geodesic for `observations` of any group G (indexable,
// with size()) at covariates `times`: the recommendation is the static
// model unless the geodesic's criterion is lower by more than
// kSelectionMargin. Never throws for bad data, never returns NaN: input
// refused as select_motion_model refuses it (a covariate not finite or
// beyond half the largest double, an observation not finite or not in G)
// has status invalid_input, naming the index; a model that cannot be
// fitted or scored (N below its parameter count, a failed fit, an
// overflowing criterion) is excluded with a note; with neither left the
// status is no_candidate.
//
// Covariates are centred before any arithmetic: c_i = t_i - t_ref with
// t_ref the midpoint of their range, so that covariates far from zero
// (EuRoC nanoseconds as doubles, 1.4e18 + 5e6 i) are worked on as their
// differences, which double holds exactly enough; the geodesic returned is
// parametrised in the user's covariates again.
template <class G, class Observations>
TrendSelection<G> select_static_or_geodesic(const Observations& observations,
                                            const std::vector<double>& times,
                                            const ModelSelectionOptions& options = {}) {
  namespace detail = model_selection_detail;
  using Tangent = typename G::Tangent;
  using Scalar = typename G::Scalar;
  TrendSelection<G> selection;
  const std::size_t n = observations.size();
  if (auto rejection = detail::check_input<G>(observations, times, options.threads)) {
    selection.message = rejection->message;
    selection.bad_index = rejection->index;
    return selection;
  }
  // Centring: |t_i| <= max/2 (checked), so every c_i is finite; the
  // midpoint min/2 + max/2 cannot overflow.
  const auto [smallest, largest] = std::minmax_element(times.begin(), times.end());
  const double reference = *smallest / 2 + *largest / 2;
  std::vector<double> centred(n);
  for (std::size_t i = 0; i < n; ++i)
    centred[i] = times[i] - reference;
  const double low = *smallest - reference, high = *largest - reference;
  // The static candidate's parametrisation (any interval will do if all
  // covariates are equal).
  const std::pair<double, double> span =
      high > low ? std::pair(low, high) : std::pair(low, low + 1);
  const double n_real = static_cast<double>(n);
  std::vector<std::vector<Tangent>> residuals;
  for (TrendModel model : {TrendModel::static_element, TrendModel::geodesic}) {
    TrendCandidate report;
    report.model = model;
    report.parameters = (model == TrendModel::static_element ? 1 : 2) * G::dof;
    std::optional<Geodesic<G>> prediction;
    if (n_real < report.parameters) {
      report.note = "excluded: " + std::to_string(n) + " observations, fewer than its " +
                    std::to_string(report.parameters) + " parameters";
    } else {
      prediction = detail::fit_trend_model<G>(model, observations, centred, span);
      if (!prediction) report.note = "excluded: its fit failed";
    }
    std::vector<Tangent> r;
    if (prediction) {
      report.fitted = true;
      for (std::size_t i = 0; i < n; ++i)
        r.push_back(detail::trend_residual<G>(*prediction, observations[i], centred[i]));
      if (model == TrendModel::static_element) {
        selection.static_element = prediction->start();
      } else {
        // Back to the user's covariates: gamma(t) = fit(t - t_ref).
        selection.geodesic =
            Geodesic<G>(prediction->start(), prediction->end(),
                        static_cast<Scalar>(static_cast<double>(prediction->t_min()) + reference),
                        static_cast<Scalar>(static_cast<double>(prediction->t_max()) + reference));
      }
    }
    residuals.push_back(r);
    selection.candidates.push_back(report);
  }
  const double floor = detail::determinant_floor<G>(residuals.front(), observations);
  std::optional<double> best;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    TrendCandidate& report = selection.candidates[c];
    if (!report.fitted) continue;
    double squares = 0;
    for (const auto& ri : residuals[c])
      squares += ri.squaredNorm();
    const double log_det =
        detail::floored_log_det(detail::residual_covariance(residuals[c]), floor);
    const double criterion = n_real / 2 * log_det + report.parameters / 2.0 * std::log(n_real);
    if (!std::isfinite(floor) || !std::isfinite(squares) || !std::isfinite(criterion)) {
      report.fitted = false;
      report.note = "excluded: its residuals' squares overflow (criterion not finite)";
      if (report.model == TrendModel::static_element) {
        selection.static_element.reset();
      } else {
        selection.geodesic.reset();
      }
      continue;
    }
    report.residual_rms = std::sqrt(squares / n_real);
    report.log_det = log_det;
    report.criterion = criterion;
    if (!best || report.criterion < *best) best = report.criterion;
  }
  if (options.folds >= 2 && n >= static_cast<std::size_t>(options.folds)) {
    using Element = typename G::Element;
    const std::size_t tasks = selection.candidates.size() * static_cast<std::size_t>(options.folds);
    ChunkPool pool(options.threads, tasks);
    const std::vector<std::optional<double>> errors = detail::cv_errors<Element>(
        observations, centred, options.folds, selection.candidates.size(),
        [&](std::size_t c) { return selection.candidates[c].fitted; },
        [&](std::size_t c, const std::vector<Element>& train,
            const std::vector<double>& train_times) {
          return detail::fit_trend_model<G>(selection.candidates[c].model, train, train_times,
                                            span);
        },
        detail::trend_residual<G>, pool);
    for (std::size_t c = 0; c < selection.candidates.size(); ++c)
      selection.candidates[c].cv_error = errors[c];
  }
  if (!best) {
    selection.status = SelectionStatus::no_candidate;
    selection.message = "neither model could be fitted and scored (see each candidate's note)";
    return selection;
  }
  // The static model has fewer parameters: it wins within the margin. The
  // best finite criterion is within the margin of itself, so one does.
  for (TrendCandidate& report : selection.candidates)
    report.within_margin = report.fitted && report.criterion <= *best + kSelectionMargin;
  selection.status = SelectionStatus::selected;
  TrendCandidate& winner = selection.candidates[selection.candidates[0].within_margin ? 0 : 1];
  winner.recommended = true;
  selection.recommended = winner.model;
  return selection;
}

// The same with covariates in any indexable container with size()
// (std::array, Eigen::VectorXd, ...), read as doubles.
template <class G, class Observations, class Times,
          std::enable_if_t<model_selection_detail::kOtherTimes<Times>, int> = 0>
TrendSelection<G> select_static_or_geodesic(const Observations& observations, const Times& times,
                                            const ModelSelectionOptions& options = {}) {
  return select_static_or_geodesic<G>(observations, model_selection_detail::as_doubles(times),
                                      options);
}

}  // namespace bireg
