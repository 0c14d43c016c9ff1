// bireg: bi-invariant geodesic regression (Hanik & von Tycowicz,
// "Bi-invariant Geodesic Regression: Existence, Uniqueness, and
// Convergence", Sections 2-4). The facade users include; the parts live in
// regression/.
//
// Data (f_i, t_i), i = 1..N, f_i in a Lie group G, t_i real, weights w_i >= 0.
// The model is the Cartan-Schouten geodesic gamma(t; g0, g1) =
// g0 exp(t log(g0^{-1} g1)) (Section 2.1), and the bi-invariant estimator
// (Definition 2.1) is the pair of endpoints at which the net force vanishes,
//
//   v0 = sum_i w_i (1 - t_i)^2 (d_0 gamma_{t_i})^{-1} Log_{b_i}(f_i) = 0,
//   v1 = sum_i w_i t_i^2       (d_1 gamma_{t_i})^{-1} Log_{b_i}(f_i) = 0,
//
// b_i = gamma(t_i; g0, g1) (w_i = 1 in the paper). It is equivariant under
// left and right translation and inversion of the data (Theorem 2.4). fit()
// follows the paper's steps:
//
//   1. the problem (regression/problem.hpp): covariates mapped onto [0, 1],
//      H = [a b; b c] of Lemma 3.7 and its eigenvalues mu_min <= mu_max,
//      which exist iff the covariates are not all equal;
//   2. a start (regression/start.hpp): the least-squares line in the log
//      chart at the middle observation, equivariant like the iteration;
//   3. the iteration of Section 2.2 with a step rule (regression/solver.hpp):
//      the paper's lambda v (Proposition 2.3: equivariant; Theorem 4.8:
//      linear convergence at rate 1 - lambda eta, eta -> mu_min as the data
//      concentrate) or a faster equivariant rule, on the net force of
//      regression/estimating_equations.hpp (Lemma 3.1, Corollary 3.2);
//   4. the diagnostics (regression/diagnostics.hpp).
//
// Errors: fit() never throws for bad input or numerical failure and never
// returns NaN. Invalid input is reported as Status::invalid_input with a
// message naming the problem (and `bad_index`, the observation, where there
// is one) before any iteration; a fit that does not converge reports why
// and returns the last usable endpoints. Code built with -fno-exceptions is
// served as is; the only exception that can escape is std::bad_alloc from
// the result's vectors.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/regression/diagnostics.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/iteration.hpp"
#include "bireg/regression/options.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/result.hpp"
#include "bireg/regression/solver.hpp"
#include "bireg/regression/start.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

template <class G>
class GeodesicRegression {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using Options = RegressionOptions<Scalar>;
  using Diagnostics = RegressionDiagnostics<Scalar>;
  using Result = RegressionResult<G>;
  // A geodesic's endpoints at the ends of the covariate interval.
  using Endpoints = std::pair<Element, Element>;

  GeodesicRegression() = default;
  explicit GeodesicRegression(Options options) : options_(std::move(options)) {}
  const Options& options() const { return options_; }

  // Fits the geodesic to observations[i] at covariates[i], with weights[i]
  // (non-negative; empty or omitted: all 1; only ratios matter). Any
  // indexable containers with size() (std::vector, std::deque, ...) of
  // Element and of numbers; the order of the observations does not matter.
  template <class Observations, class Covariates>
  Result fit(const Observations& observations, const Covariates& covariates,
             const std::vector<Scalar>& weights = {}) const {
    return run(observations, covariates, weights, nullptr);
  }

  // As fit(), starting from `start` (e.g. a previous fit's endpoints, for a
  // warm start) instead of the chart line. A start whose geodesic leaves
  // the series' disc or the domain of the group's log is replaced by the
  // observation nearest the middle covariate, as a constant geodesic.
  template <class Observations, class Covariates>
  Result fit_from(const Endpoints& start, const Observations& observations,
                  const Covariates& covariates, const std::vector<Scalar>& weights = {}) const {
    return run(observations, covariates, weights, &start);
  }

 private:
  // The fit itself, defined below the class (not inline), so that an
  // explicit instantiation declaration (bireg/regression/precompiled.hpp)
  // keeps a consumer from instantiating it again.
  template <class Observations, class Covariates>
  Result run(const Observations& observations, const Covariates& covariates,
             const std::vector<Scalar>& weights, const Endpoints* start) const;

  Options options_;
};

template <class G>
template <class Observations, class Covariates>
typename GeodesicRegression<G>::Result GeodesicRegression<G>::run(
    const Observations& observations, const Covariates& covariates,
    const std::vector<Scalar>& weights, const Endpoints* start) const {
  // 1. The problem, every input checked before any work.
  if (auto rejection = validate_options(options_)) return rejected_result<G>(*rejection);
  const std::size_t n = observations.size();
  if (covariates.size() != n) {
    return rejected_result<G>({"observations and covariates differ in length (" +
                               std::to_string(n) + " vs " + std::to_string(covariates.size()) +
                               ")"});
  }
  if (n < 2) return rejected_result<G>({"need at least 2 observations, got " + std::to_string(n)});
  Problem<Scalar> problem;
  if (auto rejection = make_problem(covariates, weights, options_.interval, problem)) {
    return rejected_result<G>(*rejection);
  }
  // The pool lives as long as this fit and serves every pass over the
  // observations (parallel.hpp); below kParallelMinimum there is none.
  std::optional<ChunkPool> pool;
  if (options_.threads > 1 && n >= kParallelMinimum) pool.emplace(options_.threads, chunk_count(n));
  ChunkPool* const chunk_pool = pool ? &*pool : nullptr;
  if (auto rejection =
          check_observations<G>(observations, options_.element_tolerance, chunk_pool)) {
    return rejected_result<G>(*rejection);
  }
  if (start && (!G::is_element(start->first, options_.element_tolerance) ||
                !G::is_element(start->second, options_.element_tolerance))) {
    return rejected_result<G>({std::string("the start is not a pair of elements of ") + G::name});
  }

  // 2. The start.
  const ChartStart<G> chart = chart_start<G>(observations, problem, chunk_pool);
  if (auto rejection = chart_rejection<G>(chart)) return rejected_result<G>(*rejection);
  const Endpoints first = start ? *start : Endpoints(chart.g0, chart.g1);

  // 3. The iteration, with the chosen step rule (compiled once for every
  // rule, through its view); 4. the diagnostics.
  const auto iterate_and_diagnose = [&](const StepRuleView<G>& rule) {
    const PsiEvaluation psi = options_.psi();
    const IterationControl<Scalar> control{options_.tolerance, options_.max_iterations,
                                           options_.record_iterates};
    Result result;
    IterationRecord<G> record;
    ForceWorkspace<G> workspace(chunk_pool, n);
    const State<G> state =
        iterate<G>(observations, problem, psi, rule, control, first.first, first.second,
                   chart.reference, result.residuals, record, &workspace);
    // The estimating equations are not finite at the start nor at the
    // middle observation: some residual log(g(t_i)^{-1} f_i) cannot be
    // computed in this scalar type (a matrix observation too
    // ill-conditioned to invert and take the log of, next to the
    // others). There is no iterate to report, and no finite diagnostic.
    if (state.series_converges && !state.usable()) {
      std::ptrdiff_t first_bad = -1;
      for (std::size_t i = 0; i < n && first_bad < 0; ++i) {
        if (!result.residuals[i].allFinite()) first_bad = static_cast<std::ptrdiff_t>(i);
      }
      return rejected_result<G>(unevaluable_start<G>(first_bad));
    }
    if (!state.series_converges) {  // no force was evaluated there: residuals alone
      residuals_alone<G>(observations, problem, state, result.residuals);
    } else {  // K at the endpoints: the Gauss-Newton rule's, or built here (O(N))
      result.jacobian = rule.gauss_newton()
                            ? rule.gauss_newton()->matrix(state.a)
                            : GaussNewtonStep<G>(problem, Scalar(0)).matrix(state.a);
    }
    fill_result<G>(
        result, problem, state, record,
        diagnose<G>(problem, rule, record, state, chart.spread, result.residuals, chunk_pool));
    return result;
  };
  // The Gauss-Newton rule sums its moments on the pool.
  return with_step_rule_view<G>(
      options_.solver, problem, options_.step_size,
      [&] {
        return GaussNewtonStep<G>(problem, options_.step_size, kGaussNewtonOrder, chunk_pool);
      },
      rejected_result<G>, iterate_and_diagnose);
}

}  // namespace bireg

// The compiled part's instantiations of the fit (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/regression/precompiled.hpp"
#endif
