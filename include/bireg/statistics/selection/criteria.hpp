// bireg: what the model selections share (selection/motion_models.hpp,
// selection/static_or_geodesic.hpp): the criterion, its eigenvalue floor
// and margin, the checks before any work, and the cross-validation.
// DESIGN.md section 5, "Which motion does the scene require".
//
// Residuals live in one common space, r_i = log(P(t_i)^{-1} f_i) in SE(3)
// (d = 6) or Sim(3) (d = 7), and S = (1/N) sum r_i r_i^T. The criterion is
// the Bayesian information criterion on the half scale of a negative
// log-likelihood:
//
//   C = N/2 log det S + k/2 log N,
//
// the Gaussian likelihood with the residuals' full covariance maximised over
// that covariance, plus the BIC penalty. BIC, not AIC: its penalty grows with
// N, so the chosen model converges to the simplest true one (AIC keeps a
// fixed probability of choosing a richer model however long the sequence).
//
//
// Singular S (planar motion, noise-free data): the eigenvalues of every
// candidate's S are floored at kDeterminantFloor times the largest
// eigenvalue of the static model's S (the data's own spread, common to all
// candidates), and at the smallest normal double if the data are all equal.
// A perfect fit then scores d N/2 log(floor), the best possible, never -inf
// or NaN.
//
// Recommendation: among the candidates whose C is within kSelectionMargin
// of the best, the one with the fewest parameters (a margin of 1 on this
// half scale is a BIC difference of 2 on the usual scale, the start of
// "positive evidence", Kass & Raftery 1995). When another candidate with the
// same number of parameters is also within the margin (screw vs rotation and
// line at small rotation, rotation only vs translation only at tiny motion),
// `ambiguous` is set and the table says so; the recommended one is then the
// one of smaller C.
//
// Refusals and statuses. Before any work the input is checked: equal,
// non-empty lengths; every covariate finite and within half the largest
// double (so that any difference of two covariates is finite); every pose
// finite and an element of its group (SE(3): a rotation block and the last
// row (0, 0, 0, 1); Sim(3): a similarity block); the enumerations known.
// A refusal has status invalid_input, a message and bad_index naming the
// observation (or covariate) at fault. A candidate whose criterion or
// RMS is not finite (residuals whose squares overflow: translations near
// 1e154 or beyond) is excluded with a note, like one whose fit failed; if
// no candidate is left the status is no_candidate and nothing is
// recommended. Nothing in a result is NaN.
//
// Second opinion: K-fold cross-validated prediction error, folds assigned by
// the rank of the covariate (rank mod K; ties broken by the pose's input
// index, so shuffling the input keeps the folds whenever covariates are
// distinct), error = mean of |log(P(t_i)^{-1} f_i)|^2 over held-out i
// (left invariant).
#pragma once
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/tolerance.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

// The group the poses are elements of, and the residuals' space.
enum class PoseGroup { se3, sim3 };

constexpr bool is_valid(PoseGroup group) {
  return group == PoseGroup::se3 || group == PoseGroup::sim3;
}

// How a selection ended.
enum class SelectionStatus {
  selected,       // a model is recommended
  invalid_input,  // refused before any work: message and bad_index say why
  no_candidate,   // no candidate could be fitted and scored: message says why
};

inline const char* to_string(SelectionStatus status) {
  switch (status) {
    case SelectionStatus::selected:
      return "selected";
    case SelectionStatus::invalid_input:
      return "invalid_input";
    case SelectionStatus::no_candidate:
      return "no_candidate";
  }
  return "unknown";
}

// Eigenvalues of S below this times the static model's largest are raised to it.
inline constexpr double kDeterminantFloor = 1e-12;
// Criterion difference within which the simpler model is preferred.
inline constexpr double kSelectionMargin = 1.0;

struct ModelSelectionOptions {
  int folds = 5;                     // K of the cross-validation; below 2: no cross-validation
  PoseGroup group = PoseGroup::se3;  // sim3: similarities, six candidates
  // Threads (>= 1) for the candidates' fits and the cross-validation's
  // (candidate, fold) fits, each fit serial. The result does not depend on
  // it: every task writes its own slot, and the folds' sums are added in
  // fold order. A std::bad_alloc on a worker terminates.
  int threads = 1;
};

namespace model_selection_detail {

// Lengths and covariates: equal, non-empty lengths, and every covariate
// finite with |t| <= max/2, so that t_i - t_j never overflows (the range,
// the centring below, the fits' map onto [0, 1]). The first covariate at
// fault is named.
template <class Times>
std::optional<Rejection> check_covariates(std::size_t observations, const Times& times) {
  if (observations != times.size() || observations == 0) {
    return Rejection{"observations and covariates must be non-empty and of equal length (" +
                     std::to_string(observations) + " vs " + std::to_string(times.size()) + ")"};
  }
  const double half_range = std::numeric_limits<double>::max() / 2;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    const auto index = static_cast<std::ptrdiff_t>(i);
    if (!std::isfinite(t)) {
      return Rejection{"covariate " + std::to_string(i) + " is not finite", index};
    }
    if (std::abs(t) > half_range) {
      return Rejection{"covariate " + std::to_string(i) +
                           " exceeds half the largest double in magnitude: differences of "
                           "covariates would overflow",
                       index};
    }
  }
  // A range the fits refuse (make_problem: the velocity would overflow or
  // underflow) is refused here, before any candidate, so that no model is
  // recommended for lack of a rival.
  double smallest = times[0], largest = times[0];
  for (std::size_t i = 1; i < times.size(); ++i) {
    smallest = std::min<double>(smallest, times[i]);
    largest = std::max<double>(largest, times[i]);
  }
  const double range = largest - smallest;
  if (range > 0) {  // equal covariates: the fits say so in their own words
    if (auto why = range_outside(range, covariate_range_limit<double>(),
                                 ": the velocity would overflow or underflow")) {
      return Rejection{*why};
    }
  }
  return std::nullopt;
}

// The covariates as doubles, for the public entry points' overloads that
// take any indexable container with size() (std::array, std::deque, Eigen
// vectors, ...), as the fits do.
template <class Times>
std::vector<double> as_doubles(const Times& times) {
  using Index = decltype(times.size());
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(times.size()));
  for (Index i = 0; i < times.size(); ++i)
    out.push_back(static_cast<double>(times[i]));
  return out;
}

template <class Times>
constexpr bool kOtherTimes = !std::is_same_v<std::decay_t<Times>, std::vector<double>>;

// Lengths, covariates, then every observation finite and an element of G
// (to the default element tolerance); the first at fault is named.
template <class G, class Observations>
std::optional<Rejection> check_input(const Observations& observations,
                                     const std::vector<double>& times, int threads) {
  if (auto rejection = check_covariates(observations.size(), times)) return rejection;
  // One observation has no residual scatter for any candidate: refused
  // here, where the reason can be said, rather than every candidate
  // excluded and no_candidate reported.
  if (observations.size() < 2) {
    return Rejection{"model selection needs at least 2 observations, got " +
                     std::to_string(observations.size())};
  }
  if (threads < 1) return Rejection{"threads must be at least 1, got " + std::to_string(threads)};
  return check_observations<G>(observations, default_element_tolerance<typename G::Scalar>());
}

// Fold of observation i: rank of (t_i, i) modulo K.
inline std::vector<int> fold_of(const std::vector<double>& times, int folds) {
  std::vector<std::size_t> order(times.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return times[a] < times[b]; });
  std::vector<int> fold(times.size());
  for (std::size_t rank = 0; rank < order.size(); ++rank)
    fold[order[rank]] = static_cast<int>(rank % static_cast<std::size_t>(folds));
  return fold;
}

// K-fold cross-validated prediction errors of `candidates` models: for
// each, the mean over i of |residual(the prediction fitted without i's
// fold, f_i, t_i)|^2, or nothing if the model is not `fitted(c)` or a fold's
// fit fails. `fit(c, train, train_times)` returns an optional prediction;
// training sets are vectors of Element. The (candidate, fold) fits run as
// tasks on `pool`; each fold's squared sum is kept apart and the folds are
// added in order, so the errors do not depend on the pool's threads.
template <class Element, class Observations, class Fitted, class Fit, class Residual>
std::vector<std::optional<double>> cv_errors(const Observations& observations,
                                             const std::vector<double>& times, int folds,
                                             std::size_t candidates, const Fitted& fitted,
                                             const Fit& fit, const Residual& residual,
                                             ChunkPool& pool) {
  const std::vector<int> fold = fold_of(times, folds);
  const std::size_t fold_count = static_cast<std::size_t>(folds);
  std::vector<std::optional<double>> fold_sums(candidates * fold_count);
  pool.run(candidates * fold_count, [&](std::size_t task) {
    const std::size_t c = task / fold_count;
    const int k = static_cast<int>(task % fold_count);
    if (!fitted(c)) return;
    std::vector<Element> train;
    std::vector<double> train_times;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (fold[i] == k) continue;
      train.push_back(observations[i]);
      train_times.push_back(times[i]);
    }
    const auto prediction = fit(c, train, train_times);
    if (!prediction) return;
    double squared_sum = 0;
    for (std::size_t i = 0; i < observations.size(); ++i)
      if (fold[i] == k)
        squared_sum += residual(*prediction, observations[i], times[i]).squaredNorm();
    fold_sums[task] = squared_sum;
  });
  std::vector<std::optional<double>> errors(candidates);
  for (std::size_t c = 0; c < candidates; ++c) {
    double squared_sum = 0;
    bool complete = true;
    for (std::size_t k = 0; k < fold_count && complete; ++k) {
      complete = fold_sums[c * fold_count + k].has_value();
      if (complete) squared_sum += *fold_sums[c * fold_count + k];
    }
    const double error = squared_sum / static_cast<double>(observations.size());
    if (complete && std::isfinite(error)) errors[c] = error;
  }
  return errors;
}

template <class Tangent>
auto residual_covariance(const std::vector<Tangent>& r) {
  using Square = Eigen::Matrix<double, Tangent::RowsAtCompileTime, Tangent::RowsAtCompileTime>;
  Square s = Square::Zero();
  for (const auto& ri : r)
    s += ri * ri.transpose();
  return Square(s / static_cast<double>(r.size()));
}

// The eigenvalue floor of every candidate's S: kDeterminantFloor times the
// largest eigenvalue of the static model's S (`spread`: its residuals), or,
// if the static model was excluded (`spread` empty), of the spread about
// the middle observation; at least the smallest normal double.
template <class G, class Observations>
double determinant_floor(std::vector<typename G::Tangent> spread,
                         const Observations& observations) {
  const std::size_t n = observations.size();
  if (spread.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      spread.push_back(G::log(G::compose(G::inverse(observations[n / 2]), observations[i])));
  }
  const auto spread_covariance = residual_covariance(spread);
  const double largest_spread = symmetric_eigen(spread_covariance).values.maxCoeff();
  return std::max(kDeterminantFloor * largest_spread, std::numeric_limits<double>::min());
}

template <class Square>
double floored_log_det(const Square& s, double floor) {
  const auto values = symmetric_eigen(s).values;
  double log_det = 0;
  for (Eigen::Index j = 0; j < s.rows(); ++j)
    log_det += std::log(std::max(values[j], floor));
  return log_det;
}

}  // namespace model_selection_detail

}  // namespace bireg
