// bireg: kernel-weighted local geodesic regression (DESIGN.md section 5).
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
// Options::robust makes every query a robust fit (statistics/robust.hpp);
// select_bandwidth chooses h by leave-one-out cross-validation (below).
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
#include <Eigen/LU>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/confidence.hpp"
#include "bireg/statistics/covariance.hpp"
#include "bireg/statistics/robust.hpp"

namespace bireg {

enum class Kernel {
  // exp(-u^2 / 2), truncated at |u| = 4: the omitted mass is
  // erfc(4 / sqrt 2) = 6.3e-5 of the whole, and no weight inside the window
  // is below exp(-8) = 3.4e-4 of the largest.
  gaussian,
  epanechnikov,  // 1 - u^2 on |u| < 1
  tricube,       // (1 - |u|^3)^3 on |u| < 1
};

inline const char* to_string(Kernel kernel) {
  switch (kernel) {
    case Kernel::gaussian:
      return "gaussian";
    case Kernel::epanechnikov:
      return "epanechnikov";
    case Kernel::tricube:
      return "tricube";
  }
  return "unknown";
}

// Half-width of the kernel's support, in bandwidths.
inline double kernel_support(Kernel kernel) {
  return kernel == Kernel::gaussian ? 4.0 : 1.0;
}

// K(u), zero outside the support.
template <class Scalar>
Scalar kernel_weight(Kernel kernel, Scalar u) {
  using std::abs;
  using std::exp;
  const Scalar magnitude = abs(u);
  if (!(magnitude < Scalar(kernel_support(kernel)))) return Scalar(0);
  switch (kernel) {
    case Kernel::gaussian:
      return exp(-u * u / Scalar(2));
    case Kernel::epanechnikov:
      return Scalar(1) - u * u;
    case Kernel::tricube: {
      const Scalar inner = Scalar(1) - magnitude * magnitude * magnitude;
      return inner * inner * inner;
    }
  }
  return Scalar(0);
}

template <class Scalar>
struct LocalRegressionOptions {
  Kernel kernel = Kernel::gaussian;
  Scalar bandwidth = Scalar(1);  // h, in covariate units
  // Of every local fit; `interval` is set per query and must be empty here.
  RegressionOptions<Scalar> fit;
  // Compute the velocity's standard errors (statistics/covariance.hpp with
  // the kernel weights, homoscedastic).
  bool standard_errors = true;
  // When set, every query is a robust fit (statistics/robust.hpp) of its
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
  std::size_t window = 0;  // observations with positive weight
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
    robust_status.reset();
    robust_rounds = 0;
    outlier_covariates.clear();
  }
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
    if (const std::string refusal = check(observations, covariates, queries); !refusal.empty()) {
      for (Estimate& estimate : estimates)
        estimate.message = refusal;
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

    const Scalar reach = Scalar(kernel_support(options_.kernel)) * options_.bandwidth;
    for_each_block(queries.size(), [&](std::size_t begin, std::size_t end) {
      Window window;
      FitBuffers buffers;
      std::optional<Geodesic<G>> previous;
      for (std::size_t k = begin; k < end; ++k) {
        const std::size_t q = query_order[k];
        fill_window(sorted_f, sorted_t, queries[q], reach, window, n);
        estimate_at(queries[q], window, previous, buffers, estimates[q]);
      }
    });
    return estimates;
  }

  // Leave-one-out prediction errors: e_i = log(p_i^{-1} f_i), p_i the local
  // estimate at t_i from all observations but i (at the ends, extrapolated
  // along its window's geodesic), in input order. Left invariant; under
  // right translation by h every e_i maps to Ad_{h^{-1}} e_i. Empty, with
  // `problem` set, when a query fails (a window too narrow, or a local fit
  // that does not converge). Cost: one local fit per observation.
  template <class Observations, class Covariates>
  std::vector<Tangent> leave_one_out(const Observations& observations, const Covariates& covariates,
                                     std::string& problem) const {
    problem = check(observations, covariates, {});
    if (!problem.empty()) return {};
    const std::size_t n = observations.size();
    std::vector<std::size_t> order;
    std::vector<Scalar> sorted_t;
    std::vector<Element> sorted_f;
    sort_by_covariate(observations, covariates, order, sorted_t, sorted_f);
    const Scalar reach = Scalar(kernel_support(options_.kernel)) * options_.bandwidth;
    std::vector<Tangent> errors(n);
    // Per block, why its first failing query failed: the first block's
    // reason that is set is the serial loop's.
    std::vector<std::string> block_problems(block_count(n));
    for_each_block(n, [&](std::size_t begin, std::size_t end) {
      Window window;
      FitBuffers buffers;
      std::optional<Geodesic<G>> previous;
      Estimate estimate;
      for (std::size_t i = begin; i < end; ++i) {
        fill_window(sorted_f, sorted_t, sorted_t[i], reach, window, i);
        estimate_at(sorted_t[i], window, previous, buffers, estimate);
        if (!estimate.ok()) {
          block_problems[begin / kQueryBlock] =
              "observation " + std::to_string(order[i]) + " left out: " +
              (estimate.message.empty() ? std::string(to_string(estimate.status))
                                        : estimate.message);
          return;
        }
        errors[order[i]] = G::log(G::compose(G::inverse(estimate.pose), sorted_f[i]));
      }
    });
    for (std::string& block_problem : block_problems) {
      if (block_problem.empty()) continue;
      problem = std::move(block_problem);
      return {};
    }
    return errors;
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

  struct Window {
    std::vector<Element> observations;
    std::vector<Scalar> covariates;
    std::vector<Scalar> weights;
    void clear() {
      observations.clear();
      covariates.clear();
      weights.clear();
    }
  };

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

  template <class Observations, class Covariates>
  std::string check(const Observations& observations, const Covariates& covariates,
                    const std::vector<Scalar>& queries) const {
    using std::isfinite;
    if (!(options_.bandwidth > 0) || !isfinite(options_.bandwidth)) {
      return "the bandwidth must be a finite positive number";
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

  // The observations with positive kernel weight at tau, ascending.
  // `excluded`: a sorted index left out (leave-one-out), or n for none.
  void fill_window(const std::vector<Element>& f, const std::vector<Scalar>& t, Scalar tau,
                   Scalar reach, Window& window, std::size_t excluded) const {
    window.clear();
    const auto first = std::lower_bound(t.begin(), t.end(), tau - reach);
    const auto last = std::upper_bound(t.begin(), t.end(), tau + reach);
    for (auto it = first; it != last; ++it) {
      const std::size_t i = static_cast<std::size_t>(it - t.begin());
      if (i == excluded) continue;
      const Scalar weight = kernel_weight(options_.kernel, (t[i] - tau) / options_.bandwidth);
      if (!(weight > 0)) continue;
      window.observations.push_back(f[i]);
      window.covariates.push_back(t[i]);
      window.weights.push_back(weight);
    }
  }

  // The estimate at tau from its window, into `estimate` (whose vectors
  // and message keep their capacity); `previous` is the last successful
  // local geodesic, updated here.
  void estimate_at(Scalar tau, const Window& window, std::optional<Geodesic<G>>& previous,
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
    return with_step_rule<G>(fit_options.solver, [&](auto tag) {
      using Rule = typename decltype(tag)::type;
      if (Rule::refuse(problem, fit_options.step_size)) return false;
      const Rule rule = make_rule<Rule>(problem, *previous);
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
      return true;
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

// The automatic bandwidth: the cross-validation curve over a grid and its
// minimiser.
template <class Scalar>
struct BandwidthSelection {
  Scalar bandwidth = 0;      // the grid's value with the smallest criterion
  std::vector<Scalar> grid;  // ascending
  // The criterion per grid value: the generalised variance of the
  // leave-one-out errors, det(S_h)^(1/d) with S_h = (1/N) sum e_i e_i^T.
  // Left invariant; right translation multiplies every S_h by the same
  // Ad S Ad^T, so the ratios and the choice are right invariant on every
  // group (DESIGN.md section 5). Infinite where a query failed.
  std::vector<Scalar> criterion;
  // The mean squared error (1/N) sum |e_i|^2, for reading: left
  // invariant, right invariant only on compact groups (SO(n)).
  std::vector<Scalar> mean_squared_error;
  std::vector<std::string> problems;  // why a grid value failed, else empty
  bool ok() const { return bandwidth > 0; }
};

// `count` bandwidths, geometrically spaced from `smallest_spacings` median
// sample spacings up to the covariates' whole range. Empty when the
// covariates have fewer than two distinct values.
template <class Covariates>
std::vector<double> bandwidth_grid(const Covariates& covariates, int count = 20,
                                   double smallest_spacings = 2) {
  std::vector<double> t(covariates.begin(), covariates.end());
  std::sort(t.begin(), t.end());
  std::vector<double> spacings;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) spacings.push_back(t[i] - t[i - 1]);
  }
  if (spacings.empty() || count < 2) return {};
  const auto middle = spacings.begin() + static_cast<std::ptrdiff_t>(spacings.size() / 2);
  std::nth_element(spacings.begin(), middle, spacings.end());
  const double low = smallest_spacings * *middle;
  const double high = t.back() - t.front();
  if (!(high > low)) return {high};
  std::vector<double> grid(static_cast<std::size_t>(count));
  const double ratio = std::log(high / low) / (count - 1);
  for (int k = 0; k < count; ++k)
    grid[static_cast<std::size_t>(k)] = low * std::exp(ratio * k);
  return grid;
}

// Leave-one-out cross-validation over `grid` (options.bandwidth is
// ignored). Cost: one local fit per observation per grid value, each over
// its window: O(grid size x N x mean window), and a window of the whole
// range costs O(N) per query, so the largest bandwidths dominate
// (O(N^2) each); pass a shorter grid for long recordings.
template <class G, class Observations, class Covariates>
BandwidthSelection<typename G::Scalar> select_bandwidth(
    const Observations& observations, const Covariates& covariates,
    LocalRegressionOptions<typename G::Scalar> options,
    const std::vector<typename G::Scalar>& grid) {
  using Scalar = typename G::Scalar;
  using Scatter = Eigen::Matrix<Scalar, G::dof, G::dof>;
  BandwidthSelection<Scalar> selection;
  selection.grid = grid;
  std::sort(selection.grid.begin(), selection.grid.end());
  options.standard_errors = false;
  Scalar best = std::numeric_limits<Scalar>::infinity();
  for (const Scalar h : selection.grid) {
    options.bandwidth = h;
    std::string problem;
    const std::vector<typename G::Tangent> errors =
        LocalGeodesicRegression<G>(options).leave_one_out(observations, covariates, problem);
    Scalar criterion = std::numeric_limits<Scalar>::infinity();
    Scalar mean_squared = std::numeric_limits<Scalar>::infinity();
    if (problem.empty()) {
      Scatter scatter = Scatter::Zero();
      Scalar sum_squares = 0;
      for (const auto& e : errors) {
        scatter += e * e.transpose();
        sum_squares += e.squaredNorm();
      }
      const Scalar count = Scalar(errors.size());
      scatter /= count;
      mean_squared = sum_squares / count;
      criterion = std::pow(scatter.determinant(), Scalar(1) / Scalar(G::dof));
    }
    selection.criterion.push_back(criterion);
    selection.mean_squared_error.push_back(mean_squared);
    selection.problems.push_back(problem);
    if (criterion < best) {
      best = criterion;
      selection.bandwidth = h;
    }
  }
  return selection;
}

}  // namespace bireg
