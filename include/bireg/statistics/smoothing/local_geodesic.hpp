// bireg: kernel-weighted local geodesic regression (DESIGN.md section 5):
// the estimator. statistics/smoothing/bandwidth.hpp chooses its bandwidth;
// statistics/smoothing/local_regression.hpp includes both.
//
// At a query covariate tau the local estimate is the bi-invariant geodesic
// regression (paper, Definition 2.1) of the observations with weights
// w_i = K((t_i - tau) / h), K a kernel and h the bandwidth in covariate
// units; the smoothed pose is gamma_tau(tau) and the body velocity is
// gamma_tau's constant X_tau / (t_max - t_min) per covariate unit. On R^n
// this is textbook local-linear kernel regression. Every local fit is left
// and right equivariant (Theorem 2.4) because the weights depend on the
// covariates only.
//
// Cost. The observations are sorted once (O(N log N)); a query touches only
// the observations inside the kernel's support [tau - c h, tau + c h]
// (c = kernel_support), found by binary search, and its fit's unit interval
// is that window clipped to the data there (the `interval` option), so the
// fit's conditioning does not depend on where the window lies. Queries are
// processed in ascending order and each fit starts from the previous
// query's geodesic evaluated at the new window's ends, and stops on the
// contraction it shows (Stopping::predicted, regression/iteration.hpp): on
// smooth data the first step, from the previous geodesic, and a second
// one reach the tolerance, two evaluations of the estimating equations
// per query instead of the certified stop's three. The observations and
// the options are checked once, before any query. The window and the fit's
// buffers are reused from query to query: once they have grown to the
// largest window, a query allocates nothing (tests/test_allocation.cpp),
// except the first of each block of 1024 (a cold fit; the blocks are what
// Options::threads shares out), a query whose warm fit fails (refitted
// cold, with fit()'s checks and messages) and robust queries.
//
// Fast rotation. A window is cut where it would turn by more than
// Options::max_turn (local_window.hpp), so a geodesic through it stays in
// the principal log's domain whatever the bandwidth; a local fit that still
// fails is refitted cold and then on narrower windows (estimate_at), and a
// query that fails at every width says so: ok() is false and `message`
// says why (its pose and velocity are the last iterate's, for diagnosis,
// not an estimate). Where the cut shortened the window, the wide fit
// (local_wide.hpp, Options::wide_windows) refits the window that may turn
// by max_turn on each side, carried by (g0, X) so that the turn may pass
// pi, and replaces the estimate when it converges.
//
// Options::robust makes every query a robust fit (statistics/robust/regression.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "bireg/statistics/smoothing/kernel.hpp"
#include "bireg/statistics/smoothing/local_wide.hpp"
#include "bireg/statistics/smoothing/local_window.hpp"

namespace bireg {

template <class Scalar>
struct LocalRegressionOptions {
  Kernel kernel = Kernel::gaussian;
  Scalar bandwidth = Scalar(1);  // h, in covariate units
  // Of every local fit; `interval` is set per query and must be empty here.
  RegressionOptions<Scalar> fit;
  // Compute the velocity's standard errors (statistics/inference/covariance.hpp with
  // the kernel weights, homoscedastic).
  bool standard_errors = true;
  // When set, every query is a robust fit (statistics/robust/regression.hpp) of its
  // window with the kernel weights as user weights, so an observation's
  // weight is K((t_i - tau) / h) times its robust weight. The robust fit
  // starts cold from the window's plain fit (its reweighting needs the
  // plain residuals), so a query costs a few fits instead of one or two
  // Gauss-Newton iterations. The standard errors then use the combined
  // weights as if they were fixed: a plug-in that ignores the weights'
  // dependence on the data. The robust weights depend on invariant
  // Mahalanobis distances, so the local fit stays left and right
  // equivariant.
  std::optional<RobustOptions<Scalar>> robust;
  // How far the motion within a query's window may turn (the relative
  // rotation's angle, a bi-invariant distance), in radians, on groups with
  // a rotation (has_turn_angle_v: SO(2), SE(2), SO(3), SE(3), Sim(3)); in
  // (0, 2.5]. The window is cut symmetrically in time about the query
  // where the motion leaves the ball of radius max_turn / 2 about the
  // observation nearest the query (local_window.hpp, turn_radius): a
  // geodesic through it stays inside the principal log's domain (a turn
  // below pi) with room for noise and curvature, whatever the bandwidth.
  // A single observation beyond the ball is an outlier, not a turn, and
  // stays in the window. The cut makes the bandwidth local: where the
  // motion is fast, the window is as wide as the turn allows. The turn is
  // invariant under conjugation, so the cut is left and right invariant.
  Scalar max_turn = Scalar(2.5);
  // The degree p of the local polynomial whose slope is the velocity: 1,
  // the local geodesic's own velocity; p = 2 or 3, the weighted
  // least-squares fit of the geodesic's residuals
  // r_i = log(gamma(t_i)^{-1} f_i) on (1, t_i - tau, ..., (t_i - tau)^p)
  // adds its slope to the geodesic's velocity. On R^n this is local
  // polynomial regression's derivative exactly. The quadratic (the default)
  // changes nothing in the interior of evenly sampled data (the quadratic
  // column is orthogonal to the linear one) and at the ends of the data
  // removes the local line's first-order bias in the derivative
  // (DESIGN.md section 5, "Velocity at the ends"); the cubic also removes
  // the interior's bias from the rate's curvature, for more variance at
  // the same bandwidth (DESIGN.md section 5, "The velocity's degree"):
  // select_bandwidth chooses between the two. The residuals map by Ad under
  // right translation and are left invariant, so the velocity keeps both
  // equivariances. Its standard errors are the geodesic's times the ratio
  // of the two designs' slope variances. Robust queries (`robust` below)
  // report the robust geodesic's velocity: this does not apply to them.
  int velocity_degree = 2;
  // Where the turn cut shortened a window (fast rotation), refit the
  // window that may turn by max_turn on each side of the query (its path,
  // local_window.hpp's path_radius) instead of max_turn in all, carried by
  // (g0, X) so that the whole turn may pass pi (statistics/smoothing/local_wide.hpp:
  // the same estimator in other coordinates), from the narrow window's
  // geodesic. Twice the turn is up to twice the samples in the velocity
  // when the motion is fast for its sampling rate. A wide fit that does
  // not converge leaves the narrow estimate as it was. Not for robust
  // queries.
  bool wide_windows = true;
  // Threads for the queries (>= 1; 1: the calling thread only), in blocks
  // of 1024 queries whatever the count, so the estimates do not depend on
  // it. The local fits themselves stay serial (`fit.threads` is not used).
  // A std::bad_alloc on a worker terminates.
  int threads = 1;
};

template <class G>
struct LocalEstimate {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;

  Scalar covariate = 0;                      // tau
  Status status = Status::invalid_input;     // of the local fit
  std::string message;                       // why, when not ok()
  Element pose = G::identity();              // gamma_tau(tau); of the last
                                             // iterate when the fit failed
  Tangent velocity = Tangent::Zero();        // body velocity per covariate unit
  Tangent velocity_error = Tangent::Zero();  // its standard errors (0 if undefined)
  bool velocity_error_defined = false;
  int iterations = 0;      // Gauss-Newton iterations of the local fit(s)
  std::size_t window = 0;  // observations the estimate used
  // The fit over the whole window failed and this estimate is from the
  // window narrowed about the query (LocalGeodesicRegression's fallback).
  bool narrowed = false;
  // The estimate is the wide fit's (Options::wide_windows), on `window`
  // observations past the narrow window's turn.
  bool widened = false;
  // With Options::robust: how the reweighting ended, its rounds, and the
  // window's observations it flagged as outliers (their covariates).
  std::optional<RobustStatus> robust_status;
  int robust_rounds = 0;
  std::vector<Scalar> outlier_covariates;

  bool ok() const {
    return is_success(status) && (!robust_status || *robust_status == RobustStatus::converged);
  }

  // To the values above, keeping the message's and the outliers' capacity
  // (a query reuses its estimate without allocating).
  void reset() {
    covariate = 0;
    status = Status::invalid_input;
    message.clear();
    pose = G::identity();
    velocity.setZero();
    velocity_error.setZero();
    velocity_error_defined = false;
    iterations = 0;
    window = 0;
    narrowed = false;
    widened = false;
    robust_status.reset();
    robust_rounds = 0;
    outlier_covariates.clear();
  }
};

// What cross-validation holds out (LocalGeodesicRegression::held_out).
enum class HoldOut {
  one,     // each observation: the pose's prediction error
  chords,  // each observation's chord between its neighbours: the velocity's error
  // the velocity's error against each observation's five-point derivative
  // (local_window.hpp, five_point_target), less biased than the chord where
  // the motion is fast for its sampling rate, noisier where it is not
  derivatives,
};

template <class G>
struct HeldOut {
  std::string problem;                      // the input was refused (then nothing else is set)
  std::vector<typename G::Tangent> errors;  // per observation, input order
  std::vector<char> ok;                     // whether errors[i] exists
  // HoldOut::chords and derivatives: c_i, the covariance of v_i's noise
  // with d_i's per unit of the observations' noise covariance (held_out).
  std::vector<typename G::Scalar> cross;
  std::size_t failures = 0;   // queries whose local fit failed at every width
  std::string first_failure;  // the first of them (in covariate order), why
};

template <class G>
class LocalGeodesicRegression {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using Options = LocalRegressionOptions<Scalar>;
  using Estimate = LocalEstimate<G>;

  explicit LocalGeodesicRegression(Options options) : options_(std::move(options)) {}
  const Options& options() const { return options_; }

  // Estimates at every observation's covariate, in input order.
  template <class Observations, class Covariates>
  std::vector<Estimate> smooth(const Observations& observations,
                               const Covariates& covariates) const {
    std::vector<Scalar> queries(covariates.size());
    for (std::size_t i = 0; i < queries.size(); ++i)
      queries[i] = Scalar(covariates[i]);
    return smooth_at(observations, covariates, queries);
  }

  // Estimates at `queries` (any order, any values), in the queries' order.
  // A query outside the data's range extrapolates along its window's
  // geodesic. Never throws for bad input, never NaN: a refused input or a
  // window with fewer than two distinct covariates is reported per query.
  template <class Observations, class Covariates>
  std::vector<Estimate> smooth_at(const Observations& observations, const Covariates& covariates,
                                  const std::vector<Scalar>& queries) const {
    std::vector<Estimate> estimates(queries.size());
    for (std::size_t q = 0; q < queries.size(); ++q)
      estimates[q].covariate = queries[q];
    if (const std::string why = refusal(observations, covariates, queries); !why.empty()) {
      for (Estimate& estimate : estimates)
        estimate.message = why;
      return estimates;
    }

    // Sorted once: the covariates ascending, the observations alongside.
    const std::size_t n = observations.size();
    std::vector<std::size_t> order;
    std::vector<Scalar> sorted_t;
    std::vector<Element> sorted_f;
    sort_by_covariate(observations, covariates, order, sorted_t, sorted_f);
    std::vector<std::size_t> query_order(queries.size());
    std::iota(query_order.begin(), query_order.end(), std::size_t(0));
    std::stable_sort(query_order.begin(), query_order.end(),
                     [&](std::size_t a, std::size_t b) { return queries[a] < queries[b]; });

    for_each_block(queries.size(), [&](std::size_t begin, std::size_t end) {
      Windows windows;
      FitBuffers buffers;
      std::optional<Geodesic<G>> previous;
      for (std::size_t k = begin; k < end; ++k) {
        const std::size_t q = query_order[k];
        fill_windows(sorted_f, sorted_t, queries[q], windows, n);
        estimate_at(queries[q], windows, previous, buffers, estimates[q]);
      }
    });
    return estimates;
  }

  // Leave-one-out prediction errors: e_i = log(p_i^{-1} f_i), p_i the local
  // estimate at t_i from all observations but i (at the ends, extrapolated
  // along its window's geodesic), in input order. Left invariant; under
  // right translation by h every e_i maps to Ad_{h^{-1}} e_i. Empty, with
  // `problem` set, when the input is refused or any query fails (a window
  // too narrow, or a local fit that fails at every width); held_out()
  // reports every query instead. Cost: one local fit per observation.
  template <class Observations, class Covariates>
  std::vector<Tangent> leave_one_out(const Observations& observations, const Covariates& covariates,
                                     std::string& problem) const {
    HeldOut<G> held = held_out(observations, covariates, HoldOut::one);
    problem = held.problem;
    if (problem.empty() && held.failures > 0) problem = held.first_failure;
    if (!problem.empty()) return {};
    return std::move(held.errors);
  }

  // Cross-validation errors, one per observation in input order, and
  // which of them exist (HeldOut). HoldOut::one: leave_one_out()'s
  // prediction errors. HoldOut::chords: velocity errors e_i = v_i - d_i,
  // d_i = log(f_{i-1}^{-1} f_{i+1}) / (t_{i+1} - t_{i-1}) the chord's body
  // velocity between i's two neighbours (in covariate order) and v_i the
  // local velocity at (t_{i-1} + t_{i+1}) / 2 from all the data, with
  // c_i = (l_{i+1} - l_{i-1}) / (t_{i+1} - t_{i-1}), l_j the weight of
  // observation j's noise in v_i (its weight in the local slope): v_i and
  // d_i share the two neighbours' noise, so E e_i e_i^T = (v_i's mean
  // squared error) + (d_i's) - 2 c_i Sigma for noise of covariance Sigma,
  // which select_bandwidth adds back (DESIGN.md section 5, "Choosing the
  // bandwidth for the velocity"). Not defined for the first and last
  // observation. HoldOut::derivatives: the same with d_i the five-point
  // derivative at t_i (five_point_target) and v_i at t_i, c_i = sum_j a_j
  // l_j over its five observations; where it is undefined (the two first
  // and last observations, a turn past max_turn) the chord stands in.
  // Both kinds of error are left invariant and map by
  // Ad_{h^{-1}} under right translation by h. `cubic` (velocity modes, not
  // robust): also the errors and c_i of the local cubic's velocity
  // (velocity_degree 3) from the same held-out fits, the local geodesic's
  // residuals regressed on both designs (select_bandwidth's second curve).
  template <class Observations, class Covariates>
  HeldOut<G> held_out(const Observations& observations, const Covariates& covariates, HoldOut mode,
                      HeldOut<G>* cubic = nullptr) const {
    HeldOut<G> held;
    held.problem = refusal(observations, covariates, {});
    if (cubic) *cubic = HeldOut<G>();
    if (!held.problem.empty() || mode == HoldOut::one || options_.robust) {
      if (cubic) cubic->problem = held.problem.empty() ? "not a velocity's" : held.problem;
      if (!held.problem.empty()) return held;
      cubic = nullptr;
    }
    if (cubic) {
      // The fits without a correction, the two degrees' added below.
      Options linear_options = options_;
      linear_options.velocity_degree = 1;
      HeldOut<G> held_cubic;
      held =
          LocalGeodesicRegression(linear_options)
              .held_out_pass(observations, covariates, mode, options_.velocity_degree, &held_cubic);
      *cubic = std::move(held_cubic);
      return held;
    }
    return held_out_pass(observations, covariates, mode, options_.velocity_degree, nullptr);
  }

 private:
  // held_out() after the refusal; `degree` the velocity's, and with `cubic`
  // (then this smoother's own degree is 1) the local cubic's as well.
  template <class Observations, class Covariates>
  HeldOut<G> held_out_pass(const Observations& observations, const Covariates& covariates,
                           HoldOut mode, int degree, HeldOut<G>* cubic) const {
    HeldOut<G> held;
    const std::size_t n = observations.size();
    std::vector<std::size_t> order;
    std::vector<Scalar> sorted_t;
    std::vector<Element> sorted_f;
    sort_by_covariate(observations, covariates, order, sorted_t, sorted_f);
    held.errors.assign(n, Tangent::Zero());
    held.ok.assign(n, 0);
    if (mode != HoldOut::one) held.cross.assign(n, Scalar(0));
    if (cubic) {
      cubic->errors.assign(n, Tangent::Zero());
      cubic->ok.assign(n, 0);
      cubic->cross.assign(n, Scalar(0));
    }
    // Robust queries report the robust geodesic's velocity.
    if (options_.robust) degree = 1;
    // Per block, its first failure: the first block's that is set is the
    // serial loop's.
    std::vector<std::string> block_failures(block_count(n));
    std::vector<std::size_t> block_counts(block_count(n), 0);
    for_each_block(n, [&](std::size_t begin, std::size_t end) {
      Windows windows;
      FitBuffers buffers;
      std::optional<Geodesic<G>> previous;
      Estimate estimate;
      for (std::size_t i = begin; i < end; ++i) {
        Scalar tau = sorted_t[i];
        Tangent target = Tangent::Zero();
        DerivativeTarget<G> five;
        if (mode != HoldOut::one) {
          if (i == 0 || i + 1 == n || !(sorted_t[i + 1] > sorted_t[i - 1])) continue;
          if (mode == HoldOut::derivatives) {
            five = five_point_target<G>(sorted_f, sorted_t, i, options_.max_turn);
          }
          if (five.defined) {
            target = five.velocity;
          } else {
            tau = (sorted_t[i - 1] + sorted_t[i + 1]) / 2;
            target = G::log(G::compose(G::inverse(sorted_f[i - 1]), sorted_f[i + 1])) /
                     (sorted_t[i + 1] - sorted_t[i - 1]);
          }
          fill_windows(sorted_f, sorted_t, tau, windows, n);
        } else {
          fill_windows(sorted_f, sorted_t, tau, windows, i);
        }
        estimate_at(tau, windows, previous, buffers, estimate);
        if (!estimate.ok()) {
          const std::size_t block = begin / kQueryBlock;
          if (block_counts[block]++ == 0) {
            block_failures[block] = "observation " + std::to_string(order[i]) +
                                    (mode == HoldOut::one ? " left out: " : "'s chord: ") +
                                    estimate.message;
          }
          continue;
        }
        // A chord whose velocity came from a narrowed window has no c_i
        // from this window: left out, neither compared nor a failure.
        if (mode != HoldOut::one && estimate.narrowed) continue;
        held.ok[order[i]] = 1;
        if (mode == HoldOut::one) {
          held.errors[order[i]] = G::log(G::compose(G::inverse(estimate.pose), sorted_f[i]));
          continue;
        }
        const Window& used = estimate.widened ? windows.wide : windows.narrow;
        // c_i for the velocity of degree p: the weights of the five-point
        // target's (or the chord's) observations in the local slope.
        const auto cross_of = [&](int p) {
          const SlopeWeights<G> weight(used, tau, p);
          if (!five.defined) {
            return (weight(sorted_t[i + 1]) - weight(sorted_t[i - 1])) /
                   (sorted_t[i + 1] - sorted_t[i - 1]);
          }
          Scalar cross = 0;
          for (std::size_t k = 0; k < 5; ++k)
            cross += five.weights[k] * weight(sorted_t[i - 2 + k]);
          return cross;
        };
        if (!cubic) {
          held.errors[order[i]] = estimate.velocity - target;
          held.cross[order[i]] = cross_of(degree);
          continue;
        }
        // The uncorrected local geodesic through the estimate (its pose at
        // tau, its body velocity) and its residuals' two polynomial slopes.
        const Element pose = estimate.pose;
        const Tangent velocity = estimate.velocity;
        const auto local = [&](Scalar t) { return G::compose(pose, G::exp((t - tau) * velocity)); };
        const auto corrected = [&](int p) {
          if (p < 2) return velocity;
          const PolynomialSlope<G> slope = polynomial_slope<G>(local, used, tau, p);
          return slope.defined ? Tangent(velocity + slope.slope) : velocity;
        };
        held.errors[order[i]] = corrected(degree) - target;
        held.cross[order[i]] = cross_of(degree);
        cubic->ok[order[i]] = 1;
        cubic->errors[order[i]] = corrected(3) - target;
        cubic->cross[order[i]] = cross_of(3);
      }
    });
    for (std::size_t block = 0; block < block_failures.size(); ++block) {
      held.failures += block_counts[block];
      if (held.first_failure.empty()) held.first_failure = std::move(block_failures[block]);
    }
    if (cubic) {
      cubic->failures = held.failures;
      cubic->first_failure = held.first_failure;
    }
    return held;
  }

 public:
  // Why smooth_at() would refuse these inputs (each of its estimates then
  // carries this message), or empty: the options, the lengths, the
  // observations (check_observations) and every covariate and query
  // finite. Nothing is fitted.
  template <class Observations, class Covariates>
  std::string refusal(const Observations& observations, const Covariates& covariates,
                      const std::vector<Scalar>& queries) const {
    using std::isfinite;
    if (!(options_.bandwidth > 0) || !isfinite(options_.bandwidth)) {
      return "the bandwidth must be a finite positive number";
    }
    if (!(options_.max_turn > 0) || !(options_.max_turn <= Scalar(2.5))) {
      return "max_turn must be in (0, 2.5] radians";
    }
    if (options_.velocity_degree < 1 || options_.velocity_degree > 3) {
      return "velocity_degree must be 1, 2 or 3, got " + std::to_string(options_.velocity_degree);
    }
    if (options_.fit.interval) return "the local fits set their own interval: leave it empty";
    if (options_.threads < 1)
      return "threads must be at least 1, got " + std::to_string(options_.threads);
    if (auto rejection = validate_options(options_.fit)) return rejection->message;
    if (observations.size() != covariates.size()) {
      return "observations and covariates differ in length";
    }
    if (auto rejection = check_observations<G>(observations, options_.fit.element_tolerance)) {
      return rejection->message;
    }
    for (std::size_t i = 0; i < covariates.size(); ++i) {
      if (!isfinite(Scalar(covariates[i])))
        return "covariate " + std::to_string(i) + " is not finite";
    }
    for (std::size_t q = 0; q < queries.size(); ++q) {
      if (!isfinite(queries[q])) return "query " + std::to_string(q) + " is not finite";
    }
    return {};
  }

 private:
  // The observations in ascending covariate order (stable: ties keep their
  // input order), with the permutation that sorts them.
  template <class Observations, class Covariates>
  static void sort_by_covariate(const Observations& observations, const Covariates& covariates,
                                std::vector<std::size_t>& order, std::vector<Scalar>& sorted_t,
                                std::vector<Element>& sorted_f) {
    const std::size_t n = observations.size();
    order.resize(n);
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return Scalar(covariates[a]) < Scalar(covariates[b]);
    });
    sorted_t.resize(n);
    sorted_f.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      sorted_t[i] = Scalar(covariates[order[i]]);
      sorted_f[i] = observations[order[i]];
    }
  }

  using Window = LocalWindow<G>;

  WindowShape<Scalar> shape() const {
    return {options_.kernel, options_.bandwidth, options_.max_turn, false};
  }

  // A query's window, and its wide window when the turn cut shortened it
  // (Options::wide_windows; otherwise `wide` is empty).
  struct Windows {
    Window narrow;
    Window wide;
  };
  void fill_windows(const std::vector<Element>& f, const std::vector<Scalar>& t, Scalar tau,
                    Windows& windows, std::size_t excluded) const {
    const bool cut = fill_window<G>(f, t, tau, shape(), windows.narrow, excluded);
    windows.wide.clear();
    if (!cut || !options_.wide_windows || options_.robust) return;
    WindowShape<Scalar> wide = shape();
    wide.wide = true;
    fill_window<G>(f, t, tau, wide, windows.wide, excluded);
  }

  // Queries run in blocks of kQueryBlock consecutive ones (in ascending
  // covariate order), each block starting cold and warm-starting within
  // itself. The blocks are the units of work of Options::threads and do
  // not depend on it, so the results are bit-identical for any thread
  // count; a cold start every 1024 queries costs nothing measurable.
  static constexpr std::size_t kQueryBlock = 1024;
  static std::size_t block_count(std::size_t queries) {
    return (queries + kQueryBlock - 1) / kQueryBlock;
  }

  // Calls smooth_block(begin, end) for every block of [0, queries), on
  // Options::threads threads (a pool of one runs them in order, here).
  template <class Body>
  void for_each_block(std::size_t queries, const Body& smooth_block) const {
    ChunkPool(options_.threads).run(block_count(queries), [&](std::size_t block) {
      smooth_block(block * kQueryBlock, std::min(queries, (block + 1) * kQueryBlock));
    });
  }

  // The warm local fits' buffers, reused from query to query.
  struct FitBuffers {
    Problem<Scalar> problem;
    std::vector<Tangent> residuals;
    ForceWorkspace<G> workspace;
    IterationRecord<G> record;
  };

  // The estimate at tau from its window, into `estimate` (whose vectors
  // and message keep their capacity); `previous` is the last successful
  // local geodesic, updated here.
  void estimate_at(Scalar tau, const Windows& windows, std::optional<Geodesic<G>>& previous,
                   FitBuffers& buffers, Estimate& estimate) const {
    estimate_narrow(tau, windows.narrow, previous, buffers, estimate);
    if (estimate.ok() && windows.wide.covariates.size() > windows.narrow.covariates.size()) {
      widen(windows.wide, estimate);
    }
    refuse_unrepresentable(estimate);
    explain_failure(estimate);
  }

  // A failed estimate says why. fit() keeps its message for refusals, so a
  // local fit's own failure (no_descent, max_iterations, ...) is named here
  // with the query and the window.
  static void explain_failure(Estimate& estimate) {
    if (estimate.ok() || !estimate.message.empty()) return;
    const char* how = is_success(estimate.status) && estimate.robust_status
                          ? to_string(*estimate.robust_status)
                          : to_string(estimate.status);
    estimate.message = "the local fit at " + std::to_string(double(estimate.covariate)) +
                       " ended " + how + " (" + std::to_string(estimate.window) +
                       " observations in its window)";
  }

  // Never a number where the computation failed: an estimate whose pose or
  // velocity is not finite (a query and bandwidth ~1e200 on SO(3), ~1e8 on
  // SL(3), where the local geodesic's value overflows) is a failure, and
  // standard errors that overflow are undefined (0, not infinity or NaN).
  static void refuse_unrepresentable(Estimate& estimate) {
    if (estimate.velocity_error_defined && !estimate.velocity_error.allFinite()) {
      estimate.velocity_error_defined = false;
      estimate.velocity_error.setZero();
    }
    if (!estimate.ok() || (estimate.pose.allFinite() && estimate.velocity.allFinite())) return;
    estimate.status = Status::diverged;
    estimate.message = "the estimate at " + std::to_string(double(estimate.covariate)) +
                       " is not representable: its pose or velocity overflows";
  }

  // Options::wide_windows: the wide fit from the narrow estimate's
  // geodesic, which it replaces when it converges.
  void widen(const Window& wide, Estimate& estimate) const {
    const WideFit<G> fit =
        wide_fit<G>(wide, estimate.covariate, estimate.pose, estimate.velocity,
                    options_.fit.tolerance, options_.fit.max_iterations, options_.standard_errors);
    estimate.iterations += fit.iterations;
    if (!fit.converged) return;
    estimate.pose = fit(estimate.covariate);
    estimate.velocity = fit.body_velocity();
    estimate.velocity_error = fit.velocity_error;
    estimate.velocity_error_defined = fit.velocity_error_defined;
    estimate.window = wide.covariates.size();
    estimate.widened = true;
    add_polynomial_slope(fit, wide, estimate);
  }

  // The estimate on the narrow window, with the fallback below.
  void estimate_narrow(Scalar tau, const Window& window, std::optional<Geodesic<G>>& previous,
                       FitBuffers& buffers, Estimate& estimate) const {
    estimate_in(tau, window, previous, buffers, estimate);
    if (estimate.ok() || options_.robust || estimate.window < 3 ||
        estimate.status == Status::max_iterations) {
      return;
    }
    // The fallback, still a local estimate: a fit that fails from the
    // previous geodesic is refitted cold (fit()'s own start), and if that
    // fails too, on the window narrowed to the observations within half its
    // reach of tau, repeatedly, while it keeps at least three: a narrower
    // window is the local estimate at a smaller bandwidth. A query that
    // fails at every width is reported with the widest window's failure.
    // Not after max_iterations: a fit that ran out of iterations is not
    // outside the domain, and refitting it would multiply the worst case
    // (README, "The most a fit can cost") by the number of widths.
    // Allocates (the narrowed window), on this path only.
    // When the first fit had no previous geodesic it already was fit() on
    // this window: narrow straight away instead of repeating it.
    std::optional<Geodesic<G>> cold;
    Estimate attempt;
    Window narrowed = previous ? window : halved(window, tau);
    while (narrowed.covariates.size() >= 3) {
      estimate_in(tau, narrowed, cold, buffers, attempt);
      attempt.iterations += estimate.iterations;
      if (attempt.ok()) {
        attempt.narrowed = narrowed.covariates.size() < window.covariates.size();
        estimate = std::move(attempt);
        previous = cold;
        return;
      }
      estimate.iterations = attempt.iterations;
      narrowed = halved(narrowed, tau);
    }
  }

  // The observations of `window` within half its reach of tau.
  static Window halved(const Window& window, Scalar tau) {
    using std::abs;
    Scalar reach = 0;
    for (const Scalar t : window.covariates)
      reach = std::max(reach, abs(t - tau));
    Window kept;
    for (std::size_t i = 0; i < window.covariates.size(); ++i) {
      if (!(abs(window.covariates[i] - tau) < reach / 2)) continue;
      kept.observations.push_back(window.observations[i]);
      kept.covariates.push_back(window.covariates[i]);
      kept.weights.push_back(window.weights[i]);
    }
    return kept;
  }

  // One attempt at tau on `window`: the warm fit from `previous`, else a
  // fit from `previous` with fit()'s checks, else (no previous) fit().
  void estimate_in(Scalar tau, const Window& window, std::optional<Geodesic<G>>& previous,
                   FitBuffers& buffers, Estimate& estimate) const {
    estimate.reset();
    estimate.covariate = tau;
    estimate.window = window.covariates.size();
    // Ascending: distinct iff the ends differ.
    if (window.covariates.empty() || !(window.covariates.back() > window.covariates.front())) {
      estimate.message = "fewer than two distinct covariates within the kernel's support at " +
                         std::to_string(double(tau)) + " (" + std::to_string(estimate.window) +
                         " observations): widen the bandwidth";
      return;
    }
    // The unit interval of the local fit: the window's data.
    const Scalar start_t = window.covariates.front();
    const Scalar end_t = window.covariates.back();
    if (!options_.robust && previous && warm_estimate(window, previous, buffers, estimate)) return;
    RegressionOptions<Scalar> fit_options = options_.fit;
    fit_options.interval = std::make_pair(start_t, end_t);
    fit_options.threads = 1;
    if (options_.robust) {
      estimate = robust_estimate_at(std::move(estimate), fit_options, window);
      return;
    }
    const RegressionResult<G> fit =
        previous ? GeodesicRegression<G>(fit_options)
                       .fit_from({(*previous)(start_t), (*previous)(end_t)}, window.observations,
                                 window.covariates, window.weights)
                 : GeodesicRegression<G>(fit_options)
                       .fit(window.observations, window.covariates, window.weights);
    estimate.status = fit.status;
    estimate.message = fit.message;
    estimate.iterations += fit.iterations;  // after a failed warm fit's
    if (!fit.geodesic) return;
    // A failed fit still returns its last usable endpoints: the pose and
    // velocity are reported with the failure's status, and the next query
    // does not start from them.
    const Geodesic<G>& local = *fit.geodesic;
    estimate.pose = local(tau);
    estimate.velocity = local.body_velocity();
    if (!fit.ok()) return;
    previous = local;
    if (options_.standard_errors) {
      set_velocity_error(covariance(fit, window.covariates, window.weights), estimate);
    }
    add_polynomial_slope(local, window, estimate);
  }

  // The local fit from the previous query's geodesic at the window's ends,
  // stopping on Stopping::predicted, in the reused buffers. False, with
  // `estimate` untouched but for its counters, when it does not succeed:
  // the caller then refits the window with fit()'s checks and messages.
  bool warm_estimate(const Window& window, std::optional<Geodesic<G>>& previous,
                     FitBuffers& buffers, Estimate& estimate) const {
    using Wide = CovariateScalar<Scalar>;
    const Scalar start_t = window.covariates.front();
    const Scalar end_t = window.covariates.back();
    Problem<Scalar>& problem = buffers.problem;
    if (make_problem(window.covariates, window.weights,
                     std::optional(std::make_pair(Wide(start_t), Wide(end_t))), problem)) {
      return false;
    }
    const RegressionOptions<Scalar>& fit_options = options_.fit;
    // Compiled once for every step rule, through its view.
    const auto warm_fit = [&](const StepRuleView<G>& rule) {
      const PsiEvaluation psi = fit_options.psi();
      const IterationControl<Scalar> control{fit_options.tolerance, fit_options.max_iterations,
                                             false, Stopping::predicted};
      const State<G> state =
          iterate<G>(window.observations, problem, psi, rule, control, (*previous)(start_t),
                     (*previous)(end_t), window.observations[middle_observation(problem)],
                     buffers.residuals, buffers.record, &buffers.workspace);
      estimate.iterations = buffers.record.iterations;
      if (!is_success(buffers.record.status)) return false;
      const Geodesic<G> local(state.g0, state.g1, start_t, end_t);
      estimate.status = buffers.record.status;
      estimate.pose = local(estimate.covariate);
      estimate.velocity = local.body_velocity();
      previous = local;
      if (options_.standard_errors) {
        if (buffers.record.unevaluated) {  // the residuals are the previous endpoints'
          const Element g0_inverse = G::inverse(state.g0);
          for (std::size_t i = 0; i < problem.size(); ++i) {
            buffers.residuals[i] =
                residual<G>(g0_inverse, state.x, problem.t[i], window.observations[i]);
          }
        }
        set_velocity_error(covariance_of(local, buffers.residuals, problem), estimate);
      }
      add_polynomial_slope(local, window, estimate);
      return true;
    };
    return with_step_rule<G>(fit_options.solver, [&](auto tag) {
      using Rule = typename decltype(tag)::type;
      if (Rule::refuse(problem, fit_options.step_size)) return false;
      const Rule rule = make_rule<Rule>(problem, *previous);
      return warm_fit(StepRuleView<G>(rule));
    });
  }

  // The step rule of a warm fit. Gauss-Newton's K is a power series in
  // ad_X: its terms are truncated where they fall below sqrt(epsilon) at
  // the previous geodesic's X (math/psi_series.hpp's bound, which holds
  // for K's coefficients too), a handful of terms on the short windows of
  // a dense trajectory instead of kGaussNewtonOrder. K only shapes the
  // step, so an iterate whose X outgrows that order converges a little
  // more slowly, to the same estimate.
  template <class Rule>
  Rule make_rule(const Problem<Scalar>& problem, const Geodesic<G>& previous) const {
    if constexpr (std::is_same_v<Rule, GaussNewtonStep<G>>) {
      using std::sqrt;
      const Scalar tolerance = sqrt(std::numeric_limits<Scalar>::epsilon());
      const int order =
          adaptive_series_order(G::ad(previous.displacement()), tolerance, kGaussNewtonOrder).first;
      return Rule(problem, options_.fit.step_size, order);
    } else {
      return Rule(problem, options_.fit.step_size);
    }
  }

  // Options::velocity_degree p >= 2: the slope of the degree-p fit of the
  // local geodesic's residuals (local_window.hpp, polynomial_slope) added
  // to its velocity, the standard errors scaled to that design's.
  template <class Curve>
  void add_polynomial_slope(const Curve& local, const Window& window, Estimate& estimate) const {
    if (options_.velocity_degree < 2) return;
    const PolynomialSlope<G> polynomial =
        polynomial_slope<G>(local, window, estimate.covariate, options_.velocity_degree);
    if (!polynomial.defined) return;
    estimate.velocity += polynomial.slope;
    if (estimate.velocity_error_defined) estimate.velocity_error *= polynomial.error_ratio;
  }

  static void set_velocity_error(const FitCovariance<G>& c, Estimate& estimate) {
    if (!c.defined()) return;
    estimate.velocity_error = standard_errors(velocity_covariance(c));
    estimate.velocity_error_defined = true;
  }

  Estimate robust_estimate_at(Estimate estimate, const RegressionOptions<Scalar>& fit_options,
                              const Window& window) const {
    const RobustGeodesicRegression<G> regression(*options_.robust, fit_options);
    const RobustResult<G> robust =
        regression.fit(window.observations, window.covariates, window.weights);
    estimate.status = robust.fit.status;
    estimate.robust_status = robust.status;
    estimate.robust_rounds = robust.rounds;
    estimate.iterations = robust.fit_iterations;
    estimate.message = robust.ok() ? robust.fit.message : robust.message;
    for (const std::size_t i : robust.outliers)
      estimate.outlier_covariates.push_back(window.covariates[i]);
    if (!robust.fit.geodesic) return estimate;
    const Geodesic<G>& local = *robust.fit.geodesic;
    estimate.pose = local(estimate.covariate);
    estimate.velocity = local.body_velocity();
    if (!estimate.ok() || !options_.standard_errors) return estimate;
    std::vector<Scalar> combined(window.weights.size());
    for (std::size_t i = 0; i < combined.size(); ++i)
      combined[i] = window.weights[i] * robust.robust_weights[i];
    set_velocity_error(covariance(robust.fit, window.covariates, combined), estimate);
    return estimate;
  }

  Options options_;
};

}  // namespace bireg
