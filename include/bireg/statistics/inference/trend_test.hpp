// bireg: a permutation test of "f does not depend on t" (DESIGN.md
// section 5, "Trend test"; Fletcher, "Geodesic regression and the theory of
// least squares on Riemannian manifolds", 2013, for the permutation idea).
//
// Statistic: Wilks' Lambda = det(S_res) / det(S_tot), S_res = sum w r r^T
// about the fitted geodesic, S_tot = sum w y y^T about the bi-invariant
// mean (statistics/inference/mean.hpp). Lambda is in (0, 1]; small Lambda means the
// geodesic explains much of the spread: a strong trend. It is left and
// right invariant on every group (statistics/inference/scatter.hpp), so the test
// inherits the estimator's equivariance (the paper's Theorem 2.4): the
// statistic moves by rounding only, and the p-value, computed from the
// same permutations, is identical. Where S_tot is singular the ratio is
// taken on its range (pseudo-determinant) and the result says so.
//
// H0: the pairs (f_i, t_i) are exchangeable in t, i.e. the observations
// are i.i.d. (or at least exchangeable) whatever their covariates. Under
// H0 every permutation of the covariates is as likely as the observed
// assignment, so with B random permutations
//
//   p = (1 + #{b : Lambda_b <= Lambda}) / (B + 1)
//
// is exact (P(p <= alpha) <= alpha) for any B. The test is not a test of
// "the trend is a geodesic", nor of a trend in one coordinate: any
// dependence of f on t that a geodesic captures in part lowers Lambda;
// and serially correlated observations (a trajectory sampled densely) are
// not exchangeable, so there a small p says "not exchangeable", not
// "trend".
//
// Permutation b depends only on (seed, b) (statistics/inference/permutation.hpp) and
// each permuted fit's start depends on the permuted data only, so the
// result is identical for any order or thread count. With
// TrendTestOptions::threads > 1 blocks of permutations run on a pool
// (regression/parallel.hpp), each fit serial; their verdicts are counted in
// permutation order afterwards.
//
// A permuted fit only has to say whether Lambda_b <= Lambda, and for most
// permutations that is certain long before the fit converges: each one
// stops as soon as it is (trend_detail::LambdaDecision, from the
// contraction of the iteration), and only those near a tie run to
// convergence. Each starts from the least-squares line of its own data in
// the unpermuted data's log chart (PermutationStart::chart, the default;
// trend_detail::ChartCoordinates), or from the unpermuted fit's endpoints
// (PermutationStart::fitted), or from the mean as a constant geodesic
// (PermutationStart::mean, the H0 fit). Measured on SE(3), N = 100, B = 999
// (bench/README.md): 59 us per permutation against 143 us for a cold fit
// (41%), 124 us when every permuted fit converges. A permuted fit that
// fails is redone by fit(); if that fails too it counts as at least as
// extreme (the p-value stays valid, conservatively) and is reported in
// failed_permutations.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"
#include "bireg/statistics/inference/scatter.hpp"

namespace bireg {

enum class PermutationStart {
  chart,   // fit()'s own start, the least-squares line in the log chart (a cold start)
  fitted,  // the unpermuted fit's endpoints
  mean,    // (m, m), the bi-invariant mean: the fit under H0
};

struct TrendTestOptions {
  int permutations = 999;  // B >= 1
  std::uint64_t seed = 0;
  PermutationStart start = PermutationStart::chart;
  // Threads for the permuted fits (>= 1; 1: the calling thread only). The
  // result does not depend on it. A std::bad_alloc on a worker terminates.
  int threads = 1;
  // Stop each permuted fit as soon as its verdict is certain
  // (trend_detail::LambdaDecision) instead of at convergence. false: every
  // permuted fit converges, for checking that the verdicts agree.
  bool decide_early = true;
};

template <class G>
struct TrendTestResult {
  using Scalar = typename G::Scalar;
  // converged: the test ran; invalid_input: refused (message says why);
  // another status: the unpermuted fit or the mean failed (message).
  Status status = Status::invalid_input;
  std::string message;   // why it did not run; or the pseudo-determinant note
  Scalar statistic = 1;  // Wilks' Lambda of the data
  Scalar p_value = 1;
  int permutations = 0;
  int at_least_as_extreme = 0;  // #{b : Lambda_b <= Lambda}, failed fits included
  int failed_permutations = 0;
  int decided_permutations = 0;  // permuted fits stopped once their verdict was certain
  int rank = 0;                  // of S_tot
  bool pseudo_determinant = false;
  RegressionResult<G> fit;  // the unpermuted fit
  MeanResult<G> mean;

  bool ok() const { return status == Status::converged; }
};

namespace trend_detail {

// Permutations per task: each block reuses one set of buffers.
inline constexpr std::size_t kPermutationBlock = 16;

// A permuted fit's verdict on Lambda_b <= Lambda, and whether a decision
// (LambdaDecision) reached it before the fit converged.
enum class Verdict : unsigned char {
  less_extreme,
  at_least_as_extreme,
  failed,
  decided_less_extreme,
  decided_as_extreme,
};

template <class G>
struct FitBuffers {
  std::vector<std::size_t> order;
  std::vector<CovariateScalar<typename G::Scalar>> permuted;
  Problem<typename G::Scalar> problem;
  std::vector<typename G::Tangent> residuals;
  ForceWorkspace<G> workspace;
  IterationRecord<G> record;
};

// The permuted fits' chart start. fit() starts from the least-squares line
// in the log chart at the observation nearest the middle covariate; here
// the chart is the unpermuted data's, at their middle observation f_ref, for
// every permutation: the coordinates y_i = log(f_ref^{-1} f_i) do not
// depend on the covariates, so they are computed once, and a permutation's
// line costs two weighted sums instead of N logarithms. The line is as
// good a start (first-order accurate; equivariant, as f_ref moves with the
// data) and the fit it leads to is the same up to the tolerance.
template <class G>
class ChartCoordinates {
 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;

  template <class Observations, class Covariates>
  ChartCoordinates(
      const Observations& observations, const Covariates& covariates,
      const std::vector<Scalar>& weights,
      const std::optional<std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>>>& interval) {
    Problem<Scalar> problem;
    make_problem(covariates, weights, interval, problem);  // accepted by the unpermuted fit
    reference_ = observations[middle_observation(problem)];
    const Element reference_inverse = G::inverse(reference_);
    y_.resize(observations.size());
    for (std::size_t i = 0; i < observations.size(); ++i)
      y_[i] = G::log(G::compose(reference_inverse, observations[i]));
  }

  // The least-squares line through y_i at the permuted problem's t_i.
  std::pair<Element, Element> line(const Problem<Scalar>& problem) const {
    Tangent moment0 = Tangent::Zero(), moment1 = Tangent::Zero();
    for (std::size_t i = 0; i < y_.size(); ++i) {
      moment0 += problem.w[i] * (1 - problem.t[i]) * y_[i];
      moment1 += problem.w[i] * problem.t[i] * y_[i];
    }
    const auto [x0, x1] = least_squares_line(problem, moment0, moment1);
    return {exp_at<G>(reference_, x0), exp_at<G>(reference_, x1)};
  }

 private:
  Element reference_;
  std::vector<Tangent> y_;
};

// Decides Lambda_b <= threshold from a permuted fit that has not converged
// yet (iteration.hpp's Decision). At the k-th evaluated state it computes
// L_k = log Lambda_b from that state's residuals. While the iteration
// contracts with factor theta <= 1/2 (estimated from its last two steps),
// L_k converges at least as fast: linearly with the same factor, or
// faster, since on R^n Lambda_b is stationary at the fit (the OLS fit
// minimises det S_res), so its error is of second order in the state's.
// The a-posteriori bound of such a sequence, |L_inf - L_k| <= theta /
// (1 - theta) |L_k - L_{k-1}|, bounds what is left to move; the verdict is
// taken once the distance to log(threshold) exceeds kSafety times that
// bound, a margin for the estimate of theta, which comes from two steps
// only. Permutations whose Lambda_b lies near the data's Lambda never
// satisfy it and are fitted to convergence.
template <class Scalar, int D>
class LambdaDecision {
 public:
  static constexpr Scalar kSafety = 10;

  LambdaDecision(const ScatterRange<Scalar, D>& range, const std::vector<Scalar>& weights,
                 Scalar threshold, bool enabled)
      : range_(range), weights_(weights), log_threshold_(std::log(threshold)), enabled_(enabled) {}

  bool operator()(const std::vector<Eigen::Matrix<Scalar, D, 1>>& residuals, Scalar theta) {
    using std::abs;
    using std::isfinite;
    if (!enabled_ || !isfinite(log_threshold_)) return false;
    const Scalar log_lambda = std::log(range_.ratio(scatter_matrix(residuals, weights_)));
    const Scalar change = abs(log_lambda - previous_);
    previous_ = log_lambda;
    if (!(theta > 0 && theta <= Scalar(0.5)) || !isfinite(log_lambda) || !isfinite(change)) {
      return false;
    }
    const Scalar margin = log_lambda - log_threshold_;
    if (abs(margin) <= kSafety * theta / (1 - theta) * change) return false;
    verdict_ = margin < 0 ? Verdict::decided_as_extreme : Verdict::decided_less_extreme;
    return true;
  }

  Verdict verdict() const { return verdict_; }

 private:
  const ScatterRange<Scalar, D>& range_;
  const std::vector<Scalar>& weights_;
  Scalar log_threshold_;
  bool enabled_;
  Scalar previous_ = std::numeric_limits<Scalar>::quiet_NaN();
  Verdict verdict_ = Verdict::failed;
};

}  // namespace trend_detail

// Runs the test with `regression`'s options (which every permuted fit
// shares). Observations, covariates and weights as for fit().
template <class G, class Observations, class Covariates>
TrendTestResult<G> trend_test(const GeodesicRegression<G>& regression,
                              const Observations& observations, const Covariates& covariates,
                              const std::vector<typename G::Scalar>& given_weights = {},
                              const TrendTestOptions& options = {}) {
  using Scalar = typename G::Scalar;
  using Wide = CovariateScalar<Scalar>;
  using Endpoints = typename GeodesicRegression<G>::Endpoints;
  using trend_detail::Verdict;
  constexpr int d = G::dof;
  TrendTestResult<G> result;
  if (options.permutations < 1) {
    result.message = "the number of permutations must be at least 1, got " +
                     std::to_string(options.permutations);
    return result;
  }
  if (options.threads < 1) {
    result.message = "threads must be at least 1, got " + std::to_string(options.threads);
    return result;
  }
  result.fit = regression.fit(observations, covariates, given_weights);
  if (!result.fit.ok()) {
    result.status = result.fit.status;
    result.message = "the fit did not succeed (" + std::string(to_string(result.fit.status)) +
                     (result.fit.message.empty() ? "" : ": " + result.fit.message) + ")";
    return result;
  }
  // Accepted by the fit; from here on divided by the largest, so that the
  // scatter sums neither overflow (weights of 1e308) nor underflow (1e-320).
  const std::vector<Scalar> weights = normalised_weights(given_weights);
  result.mean = bireg::mean<G>(observations, weights);
  if (!result.mean.ok()) {
    result.status = result.mean.status;
    result.message = "the bi-invariant mean did not succeed: " + result.mean.message;
    return result;
  }
  const ScatterRange<Scalar, d> range(scatter_matrix(result.mean.residuals, weights));
  result.rank = range.rank();
  result.pseudo_determinant = !range.full();
  if (result.rank == 0) {
    result.message = "the observations do not spread: no trend to test";
    return result;
  }
  if (result.pseudo_determinant) {
    result.message = "S_tot is singular (rank " + std::to_string(result.rank) + " of " +
                     std::to_string(d) + "): Lambda is a ratio of pseudo-determinants";
  }
  result.statistic = range.ratio(scatter_matrix(result.fit.residuals, weights));

  const std::size_t n = observations.size();
  const Endpoints fixed_start =
      options.start == PermutationStart::mean
          ? Endpoints(*result.mean.mean, *result.mean.mean)
          : Endpoints(result.fit.geodesic->start(), result.fit.geodesic->end());
  // Ties (a permutation that reproduces the data's assignment) must count:
  // allow rounding-level differences between the two fits' Lambda.
  const Scalar threshold = result.statistic * (1 + Scalar(1e-10));
  // Each permuted fit serial: the permutations are what runs in parallel.
  RegressionOptions<Scalar> permuted_options = regression.options();
  permuted_options.threads = 1;
  const GeodesicRegression<G> permuted_regression(permuted_options);
  const trend_detail::ChartCoordinates<G> chart(observations, covariates, weights,
                                                permuted_options.interval);

  // One permuted fit, from iteration.hpp's loop on reused buffers: the
  // observations were checked by the unpermuted fit, and the same
  // covariates in another order pass make_problem alike. A fit that stops
  // without a decision or convergence is redone by fit() (its checks, its
  // start), and counts as failed only if that fails too.
  const auto verdict_at = [&](const std::vector<typename G::Tangent>& residuals) {
    return range.ratio(scatter_matrix(residuals, weights)) <= threshold
               ? Verdict::at_least_as_extreme
               : Verdict::less_extreme;
  };
  const auto verdict_of = [&](std::size_t b, trend_detail::FitBuffers<G>& buffers) {
    permutation(options.seed, static_cast<std::uint64_t>(b), n, buffers.order);
    buffers.permuted.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      buffers.permuted[i] = static_cast<Wide>(covariates[buffers.order[i]]);
    const Problem<Scalar>& problem = buffers.problem;
    if (!make_problem(buffers.permuted, weights, permuted_options.interval, buffers.problem)) {
      // Compiled once for every step rule, through its view.
      const auto permuted_fit = [&](const StepRuleView<G>& rule) -> std::optional<Verdict> {
        const PsiEvaluation psi = permuted_options.psi();
        const IterationControl<Scalar> control{permuted_options.tolerance,
                                               permuted_options.max_iterations, false};
        const Endpoints first =
            options.start == PermutationStart::chart ? chart.line(problem) : fixed_start;
        trend_detail::LambdaDecision<Scalar, d> decision(range, weights, threshold,
                                                         options.decide_early);
        iterate<G>(observations, problem, psi, rule, control, first.first, first.second,
                   observations[middle_observation(problem)], buffers.residuals, buffers.record,
                   &buffers.workspace, decision);
        if (buffers.record.decided) return decision.verdict();
        if (!is_success(buffers.record.status)) return std::nullopt;
        return verdict_at(buffers.residuals);
      };
      const std::optional<Verdict> verdict =
          with_step_rule<G>(permuted_options.solver, [&](auto tag) -> std::optional<Verdict> {
            using Rule = typename decltype(tag)::type;
            if (Rule::refuse(problem, permuted_options.step_size)) return std::nullopt;
            const Rule rule(problem, permuted_options.step_size);
            return permuted_fit(StepRuleView<G>(rule));
          });
      if (verdict) return *verdict;
    }
    const RegressionResult<G> refit =
        options.start == PermutationStart::chart
            ? permuted_regression.fit(observations, buffers.permuted, weights)
            : permuted_regression.fit_from(fixed_start, observations, buffers.permuted, weights);
    return refit.ok() ? verdict_at(refit.residuals) : Verdict::failed;
  };

  // Blocks of permutations, each with its own buffers (no allocation per
  // permutation once they have grown); which thread runs a block does not
  // change any verdict.
  const std::size_t count = static_cast<std::size_t>(options.permutations);
  std::vector<Verdict> verdicts(count);
  const std::size_t blocks =
      (count + trend_detail::kPermutationBlock - 1) / trend_detail::kPermutationBlock;
  ChunkPool(options.threads, blocks).run(blocks, [&](std::size_t block) {
    trend_detail::FitBuffers<G> buffers;
    const std::size_t end = std::min(count, (block + 1) * trend_detail::kPermutationBlock);
    for (std::size_t b = block * trend_detail::kPermutationBlock; b < end; ++b)
      verdicts[b] = verdict_of(b, buffers);
  });
  for (const Verdict verdict : verdicts) {
    if (verdict == Verdict::decided_less_extreme || verdict == Verdict::decided_as_extreme)
      ++result.decided_permutations;
    if (verdict == Verdict::less_extreme || verdict == Verdict::decided_less_extreme) continue;
    ++result.at_least_as_extreme;
    if (verdict == Verdict::failed) ++result.failed_permutations;
  }
  result.permutations = options.permutations;
  result.p_value = Scalar(1 + result.at_least_as_extreme) / Scalar(1 + options.permutations);
  result.status = Status::converged;
  return result;
}

}  // namespace bireg

// The compiled part's instantiations of trend_test() (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/statistics/precompiled/trend_test.hpp"
#endif
