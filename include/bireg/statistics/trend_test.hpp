// bireg: a permutation test of "f does not depend on t" (DESIGN.md
// section 5, "Trend test"; Fletcher, "Geodesic regression and the theory of
// least squares on Riemannian manifolds", 2013, for the permutation idea).
//
// Statistic: Wilks' Lambda = det(S_res) / det(S_tot), S_res = sum w r r^T
// about the fitted geodesic, S_tot = sum w y y^T about the bi-invariant
// mean (statistics/mean.hpp). Lambda is in (0, 1]; small Lambda means the
// geodesic explains much of the spread: a strong trend. It is left and
// right invariant on every group (statistics/scatter.hpp), so the test
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
// Permutation b depends only on (seed, b) (statistics/permutation.hpp) and
// each permuted fit's start depends on the permuted data only, so the
// result is identical for any order or thread count. With
// TrendTestOptions::threads > 1 the permuted fits run on a pool
// (regression/parallel.hpp), one permutation per task, each fit serial;
// their verdicts are counted in permutation order afterwards. Each permuted fit
// starts from fit()'s own start (PermutationStart::chart, the default), or
// warm from the unpermuted fit's endpoints (PermutationStart::fitted) or
// from the mean as a constant geodesic (PermutationStart::mean, the H0
// fit). Measured on SE(3), N = 100, 1 rad (bench/README.md): the warm
// starts need one iteration more than the chart start, whose
// least-squares line is already first-order accurate for the permuted
// data, while fit_from pays for the chart pass anyway (it validates the
// data): the chart start is the fastest, hence the default. No start
// makes a permuted fit much cheaper than a cold one: Gauss-Newton
// converges linearly here, at a rate set by the residuals' size (the
// terms of the estimating equations' derivative that K omits are
// proportional to them), so the iterations needed grow only with the
// logarithm of the start's error. A
// permuted fit that fails counts as at least as extreme (the p-value stays
// valid, conservatively) and is reported in failed_permutations.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/mean.hpp"
#include "bireg/statistics/permutation.hpp"
#include "bireg/statistics/scatter.hpp"

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
  int rank = 0;  // of S_tot
  bool pseudo_determinant = false;
  RegressionResult<G> fit;  // the unpermuted fit
  MeanResult<G> mean;

  bool ok() const { return status == Status::converged; }
};

// Runs the test with `regression`'s options (which every permuted fit
// shares). Observations, covariates and weights as for fit().
template <class G, class Observations, class Covariates>
TrendTestResult<G> trend_test(const GeodesicRegression<G>& regression,
                              const Observations& observations, const Covariates& covariates,
                              const std::vector<typename G::Scalar>& weights = {},
                              const TrendTestOptions& options = {}) {
  using Scalar = typename G::Scalar;
  using Wide = CovariateScalar<Scalar>;
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
  result.fit = regression.fit(observations, covariates, weights);
  if (!result.fit.ok()) {
    result.status = result.fit.status;
    result.message = "the fit did not succeed (" + std::string(to_string(result.fit.status)) +
                     (result.fit.message.empty() ? "" : ": " + result.fit.message) + ")";
    return result;
  }
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
  const typename GeodesicRegression<G>::Endpoints start =
      options.start == PermutationStart::mean
          ? typename GeodesicRegression<G>::Endpoints(*result.mean.mean, *result.mean.mean)
          : typename GeodesicRegression<G>::Endpoints(result.fit.geodesic->start(),
                                                      result.fit.geodesic->end());
  // Ties (a permutation that reproduces the data's assignment) must count:
  // allow rounding-level differences between the two fits' Lambda.
  const Scalar threshold = result.statistic * (1 + Scalar(1e-10));
  // Each permuted fit serial: the permutations are what runs in parallel.
  RegressionOptions<Scalar> permuted_options = regression.options();
  permuted_options.threads = 1;
  const GeodesicRegression<G> permuted_regression(permuted_options);
  enum class Verdict : unsigned char { less_extreme, at_least_as_extreme, failed };
  const std::size_t count = static_cast<std::size_t>(options.permutations);
  std::vector<Verdict> verdicts(count);
  const auto permuted_fit = [&](std::size_t b) {
    std::vector<std::size_t> order;
    permutation(options.seed, static_cast<std::uint64_t>(b), n, order);
    std::vector<Wide> permuted(n);
    for (std::size_t i = 0; i < n; ++i)
      permuted[i] = static_cast<Wide>(covariates[order[i]]);
    const RegressionResult<G> refit =
        options.start == PermutationStart::chart
            ? permuted_regression.fit(observations, permuted, weights)
            : permuted_regression.fit_from(start, observations, permuted, weights);
    verdicts[b] = !refit.ok() ? Verdict::failed
                  : range.ratio(scatter_matrix(refit.residuals, weights)) <= threshold
                      ? Verdict::at_least_as_extreme
                      : Verdict::less_extreme;
  };
  if (options.threads > 1) {
    ChunkPool pool(options.threads);
    pool.run(count, permuted_fit);
  } else {
    for (std::size_t b = 0; b < count; ++b)
      permuted_fit(b);
  }
  for (const Verdict verdict : verdicts) {
    if (verdict == Verdict::less_extreme) continue;
    ++result.at_least_as_extreme;
    if (verdict == Verdict::failed) ++result.failed_permutations;
  }
  result.permutations = options.permutations;
  result.p_value = Scalar(1 + result.at_least_as_extreme) / Scalar(1 + options.permutations);
  result.status = Status::converged;
  return result;
}

}  // namespace bireg
