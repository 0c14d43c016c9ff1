// bireg: bi-invariant geodesic regression (Hanik & von Tycowicz, "Bi-invariant
// Geodesic Regression: Existence, Uniqueness, and Convergence", Sections 2–4).
//
// Data (f_i, t_i), i = 1..N, f_i in a Lie group G, t_i real. The model is the
// Cartan–Schouten geodesic gamma(t; g0, g1) = g0 exp(t log(g0^{-1} g1))
// (paper, eq. "geodesic"), and the bi-invariant estimator is the pair of
// endpoints at which the "net force" vanishes (Definition
// "bi_inv_estiamtor", eqs. "bir1"/"bir2"):
//
//   v0 = sum_i w_i (1 - t_i)^2 (d_0 gamma_{t_i})^{-1} Log_{b_i}(f_i) = 0,
//   v1 = sum_i w_i t_i^2       (d_1 gamma_{t_i})^{-1} Log_{b_i}(f_i) = 0,
//
// b_i = gamma(t_i; g0, g1) the model's prediction (w_i = 1 in the paper;
// bireg allows per-observation weights). In left-trivialised coordinates
// (DESIGN.md section 2), with X = log(g0^{-1} g1), A = ad_X and residuals
// r_i = log(b_i^{-1} f_i),
//
//   v0 = sum_i w_i psi_{1 - t_i}(-A) r_i,   v1 = sum_i w_i psi_{t_i}(A) r_i,
//
// where psi_s is the series of Lemma "diff_2_gam" / Corollary "diff_1_gam"
// (core/inverse_differential.hpp).
//
// The estimator is computed by the paper's iteration (eq. "algorithm"),
//
//   g0 <- g0 exp(lambda v0),   g1 <- g1 exp(lambda v1),
//
// which is equivariant under left and right translations and inversion of
// the data (Proposition "equivariance_algorithm"). Near the solution it
// behaves like its linear part I - lambda (H kron I) (Lemma "Psi_alt"), with
//
//   H = [a b; b c],  a = sum w_i (1 - t_i)^2,  b = sum w_i t_i (1 - t_i),  c = sum w_i t_i^2,
//
// and converges linearly, ||x_n - x^|| <= (1 - lambda eta)^n ||x_0 - x^||,
// eta -> mu_min(H) as the data concentrate (Theorem "existance_and_uniquness").
//
// Covariates are mapped affinely onto [0, 1] (t_min -> 0, t_max -> 1); H,
// mu_min, mu_max and lambda refer to that unit interval.
//
// Errors: fit() never throws for bad input or numerical failure and never
// returns NaN. Invalid input is reported as Status::invalid_input with a
// message naming the problem (and `bad_index`, the observation, where there
// is one), before any iteration; a fit that does not converge reports
// max_iterations, diverged or series_diverged and returns the last finite
// iterate. Code built with -fno-exceptions is therefore served as is; the
// only exception that can escape is std::bad_alloc from the result's
// vectors (which such builds turn into termination).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/core/concept.hpp"
#include "bireg/core/exact_inverse_differential.hpp"
#include "bireg/core/inverse_differential.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/tolerance.hpp"

namespace bireg {

enum class Status {
  converged,        // step norm at or below the tolerance
  max_iterations,   // iteration limit reached first; the last iterate is returned
  diverged,         // the steps grew without bound (or became non-finite)
  series_diverged,  // a step would take the spectral radius of ad_X to 2 pi,
                    // where the inverse differentials' series no longer
                    // converges; the last endpoints inside are returned
  stalled,          // the safeguard found no step that decreases ||v||: the data
                    // lie outside the region where the estimator is defined
                    // (e.g. a rotation of more than pi along the geodesic);
                    // or, at the rounding level (sqrt(epsilon) relative to
                    // |X|), the steps stopped shrinking for kStallIterations:
                    // the tolerance is finer than the data's rounding allows
  invalid_input,    // rejected before any work; see Result::message
};

inline const char* to_string(Status status) {
  switch (status) {
    case Status::converged:
      return "converged";
    case Status::max_iterations:
      return "max_iterations";
    case Status::diverged:
      return "diverged";
    case Status::series_diverged:
      return "series_diverged";
    case Status::stalled:
      return "stalled";
    case Status::invalid_input:
      return "invalid_input";
  }
  return "unknown";
}

// How the inverse differentials psi_s(ad_X) are evaluated.
enum class Method {
  series,           // the paper's series truncated at Options::series_order
  series_adaptive,  // the series, truncated where the omitted terms fall below epsilon
  exact,            // closed form (SO2, SO3, SE2, SE3) where it is accurate, the adaptive
                    // series elsewhere and for groups without one
};

inline const char* to_string(Method method) {
  switch (method) {
    case Method::series:
      return "series";
    case Method::series_adaptive:
      return "series_adaptive";
    case Method::exact:
      return "exact";
  }
  return "unknown";
}

// The step rule. All are Exp-stepped iterations g0 <- g0 exp(d0),
// g1 <- g1 exp(d1) with the same fixed point v = 0, and all keep left, right
// and inverse equivariance (tests/test_regression.cpp checks each, iterate
// by iterate). Note: DESIGN.md's "Equivariant preconditioning" says any
// constant 2x2 mixing of (v0, v1) keeps inverse equivariance; it does not
// (v0 and v1 live in the frames of g0 and g1), see Solver::preconditioned.
enum class Solver {
  paper,           // (d0, d1) = lambda (v0, v1), lambda given or 1/mu_max (the paper's)
  optimal_linear,  // lambda = 2/(mu_min + mu_max), minimising max|1 - lambda mu|
  preconditioned,  // H^{-1} applied to (v0, v1), the coupling carried across by
                   // Ad_exp(X/2): cancels the linear part
  gauss_newton,    // (d0, d1) = K^{-1}(v0, v1), K the Jacobian of v at zero residual
};

inline const char* to_string(Solver solver) {
  switch (solver) {
    case Solver::paper:
      return "paper";
    case Solver::optimal_linear:
      return "optimal_linear";
    case Solver::preconditioned:
      return "preconditioned";
    case Solver::gauss_newton:
      return "gauss_newton";
  }
  return "unknown";
}

// Truncation order of the power series that build Gauss-Newton's K. K only
// shapes the step, not the fixed point, so it needs modest accuracy: at the
// largest spectral radius of SO(3) and SE(3) (pi) the omitted terms are
// below 2^-16 ~ 2e-5 relative, which changes the contraction factor by as
// much and nothing else.
inline constexpr int kGaussNewtonOrder = 16;

// Iterations without a new smallest step, all below the rounding level,
// after which a fit stops with Status::stalled. Every solver shrinks its
// step at least linearly while it can, so 10 iterations with no progress
// mean rounding dominates: e.g. similarities at scale e^-20 carrying an
// O(1) translation keep only ~1e-7 of their detail in double.
inline constexpr int kStallIterations = 10;

template <class G>
class GeodesicRegression {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;

  struct Options {
    // Evaluation of the inverse differentials (see Method). The closed form
    // is the most accurate and, on the groups that have one, not slower.
    Method method = Method::exact;
    // Truncation order M for Method::series (M >= 1; 0 = adaptive, as
    // Method::series_adaptive, which picks the smallest M whose omitted
    // terms are below epsilon relative at every iteration, capped at
    // max_series_order).
    int series_order = 0;
    int max_series_order = kMaxSeriesOrder;
    // The step rule (see Solver). Gauss-Newton converges in a handful of
    // iterations where the paper's step needs dozens.
    Solver solver = Solver::gauss_newton;
    // lambda of the paper solver; 0 selects the paper's 1/mu_max. Must be
    // below 2/mu_max, where the linear part stops contracting. The other
    // solvers fix their own step, so a non-zero value is refused for them.
    Scalar step_size = Scalar(0);
    // Converged when the norm of the step (lambda v0, lambda v1), in
    // tangent coordinates, is at or below this. It is absolute: data whose
    // tangent coordinates are large (e.g. translations in millimetres) need
    // a proportionally larger value. 0 runs exactly max_iterations
    // iterations (no convergence or stall test), unless the fit diverges.
    Scalar tolerance = std::max(Scalar(1e-10), Scalar(64) * std::numeric_limits<Scalar>::epsilon());
    int max_iterations = 1000;
    // Endpoints at the smallest and largest covariate to start from; by
    // default the linearised least-squares fit described at initial_guess().
    // A start whose geodesic leaves the series' disc (spectral radius of
    // ad_X >= 2 pi) or the domain of the group's log is replaced by the
    // observation nearest the middle covariate, as a constant geodesic.
    std::optional<std::pair<Element, Element>> initial_guess;
    // Non-negative weight per observation; empty means all 1.
    std::vector<Scalar> weights;
    // Tolerance of the group-membership check on every observation.
    Scalar element_tolerance = default_element_tolerance<Scalar>();
    // Keep (g0, g1) after every step in Result::iterates.
    bool record_iterates = false;
  };

  struct Diagnostics {
    Scalar mu_min = 0;  // eigenvalues of H (unit covariate interval)
    Scalar mu_max = 0;
    // mu_max / mu_min: how well the covariates pin down the slope. The
    // paper solver needs ~condition_number iterations; the slope's error
    // grows like sqrt(condition_number) times the noise.
    Scalar condition_number = 0;
    Scalar step_size = 0;  // lambda used (1 for preconditioned and gauss_newton)
    // Step halvings of the safeguard (every solver but paper): a step that
    // would increase ||v|| is halved until it does not.
    int backtracks = 0;
    // Ratio of the last two step norms: the observed linear rate, which the
    // theory bounds by 1 - lambda eta (and by max|1 - lambda mu| for
    // commutative groups).
    Scalar contraction_factor = 0;
    int series_order = 0;                // order used in the last iteration
    Scalar series_truncation_bound = 0;  // relative size of the omitted terms
    Scalar force_norm = 0;  // ||(v0, v1)|| at the returned endpoints (0: series_diverged)
    // sqrt(sum w_i |r_i|^2 / sum w_i), residuals about the fitted geodesic,
    // and the data's spread about their mean, sqrt(sum w_i |y_i - ybar|^2 /
    // sum w_i) with y_i = log(f_ref^{-1} f_i) in the chart at the middle
    // observation (the constant model; see chart_fit).
    Scalar residual_rms = 0;
    Scalar residual_rms_about_mean = 0;
    // 1 - residual_rms^2 / residual_rms_about_mean^2: the share of the
    // data's spread that the geodesic explains. On R^n it is the ordinary
    // R^2. Norms are Euclidean in the tangent coordinates (which mix units
    // on SE(3)); 1 when the data do not spread.
    Scalar explained_variance = 0;
  };

  struct Result {
    Status status = Status::invalid_input;
    std::string message;            // what was wrong, for invalid_input
    std::ptrdiff_t bad_index = -1;  // offending observation, if any
    Geodesic<G> geodesic;           // in the user's covariate units
    // Iterations: evaluations of the step at the current endpoints. Each but
    // the last of a converged fit is taken; the last, at or below the
    // tolerance, certifies the returned endpoints. step_norms holds the norm
    // of every proposed step (before any safeguard halving).
    int iterations = 0;
    std::vector<Scalar> step_norms;
    std::vector<Tangent> residuals;  // r_i = log(gamma(t_i)^{-1} f_i), input order
    std::vector<std::pair<Element, Element>> iterates;  // after each step taken, if recorded
    Diagnostics diagnostics;

    bool ok() const { return status == Status::converged; }
  };

  GeodesicRegression() = default;
  explicit GeodesicRegression(Options options) : options_(std::move(options)) {}
  const Options& options() const { return options_; }

  // Fits the geodesic to observations[i] at covariates[i]. Both are any
  // indexable containers with size() (std::vector, std::deque, ...) of
  // Element and of numbers; the order of the observations does not matter.
  template <class Observations, class Covariates>
  Result fit(const Observations& observations, const Covariates& covariates) const {
    Result result;
    Problem problem;
    if (!prepare(observations, covariates, problem, result)) return result;

    result.diagnostics.mu_min = problem.mu_min;
    result.diagnostics.mu_max = problem.mu_max;
    result.diagnostics.condition_number = problem.mu_max / problem.mu_min;
    result.diagnostics.step_size = problem.lambda;

    const Chart chart = chart_fit(observations, problem);
    if (chart.no_logarithm >= 0) {
      reject(result,
             "observation " + std::to_string(chart.no_logarithm) +
                 " is out of reach of the middle observation: no principal logarithm of "
                 "f_mid^{-1} f_i (the data leave the domain of " +
                 G::name + "'s log)",
             chart.no_logarithm);
      return result;
    }
    Element g0 = chart.g0, g1 = chart.g1;
    if (options_.initial_guess) {
      g0 = options_.initial_guess->first;
      g1 = options_.initial_guess->second;
    }
    const State final_state = iterate(observations, problem, g0, g1, chart.reference, result);
    finish(observations, problem, final_state, chart.spread, result);
    return result;
  }

 private:
  // The normalised data the iteration needs, built once per fit.
  struct Problem {
    std::vector<Scalar> t;  // covariates mapped onto [0, 1]
    std::vector<Scalar> w;  // weights
    Scalar t_min = 0, t_max = 1;
    Scalar a = 0, b = 0, c = 0;  // entries of H
    Scalar mu_min = 0, mu_max = 0;
    Scalar lambda = 0;
    Scalar weight_sum = 0;
    // Power-series coefficients of K's off-diagonal blocks (gauss_newton):
    // K01 = sum_m k01[m] A^m, K10 = sum_m k10[m] A^m.
    std::array<Scalar, kGaussNewtonOrder + 1> k01{}, k10{};
  };

  // The net force (v0, v1) and, optionally, the residuals.
  struct Force {
    Tangent v0, v1;
    Scalar norm() const {
      using std::sqrt;
      return sqrt(v0.squaredNorm() + v1.squaredNorm());
    }
  };

  static bool reject(Result& result, std::string message, std::ptrdiff_t index = -1) {
    result.status = Status::invalid_input;
    result.message = std::move(message);
    result.bad_index = index;
    return false;
  }

  static bool finite(Scalar x) {
    using std::isfinite;
    return isfinite(x);
  }

  // Validates everything before any work and fills `problem`.
  template <class Observations, class Covariates>
  bool prepare(const Observations& observations, const Covariates& covariates, Problem& problem,
               Result& result) const {
    using std::sqrt;
    const std::size_t n = observations.size();
    if (covariates.size() != n) {
      return reject(result, "observations and covariates differ in length (" + std::to_string(n) +
                                " vs " + std::to_string(covariates.size()) + ")");
    }
    if (n < 2) {
      return reject(result, "need at least 2 observations, got " + std::to_string(n));
    }
    if (!options_.weights.empty() && options_.weights.size() != n) {
      return reject(result, "weights and observations differ in length (" +
                                std::to_string(options_.weights.size()) + " vs " +
                                std::to_string(n) + ")");
    }
    if (!(options_.tolerance >= 0) || !finite(options_.tolerance)) {
      return reject(result, "tolerance must be a finite non-negative number");
    }
    if (options_.max_iterations < 1) return reject(result, "max_iterations must be at least 1");
    if (options_.max_series_order < 1 || options_.max_series_order > kMaxSeriesOrder) {
      return reject(result,
                    "max_series_order must be in [1, " + std::to_string(kMaxSeriesOrder) + "]");
    }
    if (options_.method == Method::series && options_.series_order < 1) {
      return reject(result, "method series needs series_order >= 1");
    }
    if (options_.series_order < 0 || options_.series_order > kMaxSeriesOrder) {
      return reject(result, "series_order must be 0 (adaptive) or in [1, " +
                                std::to_string(kMaxSeriesOrder) + "]");
    }
    if (!(options_.step_size >= 0) || !finite(options_.step_size)) {
      return reject(result, "step_size must be a finite non-negative number (0 = 1/mu_max)");
    }

    problem.t.resize(n);
    problem.w.assign(n, Scalar(1));
    for (std::size_t i = 0; i < n; ++i) {
      const Scalar t = static_cast<Scalar>(covariates[i]);
      if (!finite(t)) {
        return reject(result, "covariate " + std::to_string(i) + " is not finite", index(i));
      }
      problem.t[i] = t;
      if (!options_.weights.empty()) {
        const Scalar w = options_.weights[i];
        if (!(w >= 0) || !finite(w)) {
          return reject(result, "weight " + std::to_string(i) + " is negative or not finite",
                        index(i));
        }
        problem.w[i] = w;
      }
      const Element& f = observations[i];
      if (!f.allFinite()) {
        return reject(result, "observation " + std::to_string(i) + " has non-finite entries",
                      index(i));
      }
      if (!G::is_element(f, options_.element_tolerance)) {
        return reject(result,
                      "observation " + std::to_string(i) + " is not an element of " + G::name +
                          " (to tolerance " + std::to_string(double(options_.element_tolerance)) +
                          ")",
                      index(i));
      }
    }

    // Affine map onto [0, 1] (DESIGN.md section 1).
    const auto [min_it, max_it] = std::minmax_element(problem.t.begin(), problem.t.end());
    problem.t_min = *min_it;
    problem.t_max = *max_it;
    const Scalar range = problem.t_max - problem.t_min;
    if (!(range > 0) || !finite(range)) {
      return reject(result, range > 0 ? "covariate range overflows"
                                      : "all covariates are equal: the slope is not identifiable");
    }
    for (Scalar& t : problem.t)
      t = std::clamp((t - problem.t_min) / range, Scalar(0), Scalar(1));

    // H of Lemma "Psi_alt", and its eigenvalues in a cancellation-free form.
    for (std::size_t i = 0; i < n; ++i) {
      const Scalar t = problem.t[i], w = problem.w[i];
      problem.a += w * (1 - t) * (1 - t);
      problem.b += w * t * (1 - t);
      problem.c += w * t * t;
      problem.weight_sum += w;
    }
    const Scalar half_trace = (problem.a + problem.c) / 2;
    const Scalar half_gap = (problem.a - problem.c) / 2;
    problem.mu_max = half_trace + sqrt(half_gap * half_gap + problem.b * problem.b);
    const Scalar determinant = problem.a * problem.c - problem.b * problem.b;
    problem.mu_min = problem.mu_max > 0 ? determinant / problem.mu_max : Scalar(0);
    // mu_min is computed to ~eps mu_max; below a few of those it is noise.
    if (!(problem.mu_min > 16 * std::numeric_limits<Scalar>::epsilon() * problem.mu_max)) {
      return reject(result,
                    "the observations with positive weight share one covariate: the slope is not "
                    "identifiable (mu_min = 0)");
    }

    if (options_.solver != Solver::paper && options_.step_size != 0) {
      return reject(result, std::string("step_size applies to the paper solver only, not to ") +
                                to_string(options_.solver));
    }
    const Scalar lambda_limit = 2 / problem.mu_max;
    switch (options_.solver) {
      case Solver::paper:
        problem.lambda = options_.step_size > 0 ? options_.step_size : 1 / problem.mu_max;
        break;
      case Solver::optimal_linear:
        problem.lambda = 2 / (problem.mu_min + problem.mu_max);
        break;
      case Solver::preconditioned:
      case Solver::gauss_newton:
        problem.lambda = 1;
        break;
    }
    if (options_.solver == Solver::paper && !(problem.lambda < lambda_limit)) {
      return reject(result,
                    "step_size " + std::to_string(double(problem.lambda)) +
                        " is at or above 2/mu_max = " + std::to_string(double(lambda_limit)) +
                        ": the linear part of the iteration no longer contracts");
    }
    if (options_.solver == Solver::gauss_newton) gauss_newton_coefficients(problem);

    if (options_.initial_guess) {
      if (!G::is_element(options_.initial_guess->first, options_.element_tolerance) ||
          !G::is_element(options_.initial_guess->second, options_.element_tolerance)) {
        return reject(result, std::string("initial_guess is not a pair of elements of ") + G::name);
      }
    }
    return true;
  }

  static std::ptrdiff_t index(std::size_t i) { return static_cast<std::ptrdiff_t>(i); }

  // Coefficients of K's off-diagonal blocks (DESIGN.md section 2,
  // "Equivariant Gauss-Newton"). With u = 1 - t,
  //   K01 = sum_i w_i g_{t_i}(A),  g_t(z) = psi_{1-t}(-z) / phi_t(z)
  //                                     = u t E(t z) B(-u z),
  //   K10 = sum_i w_i g_{1-t_i}(-A),
  // where E(w) = (e^w - 1)/w = sum_n w^n/(n+1)! and B(w) = w/(e^w - 1) =
  // sum_k b_k w^k (the identity e^{uz} B(uz) = B(-uz) turns DESIGN.md's
  // u^2 e^{uz} (e^{tz} - 1)/(e^{uz} - 1) into this product). Hence
  //   [z^m] g_t = sum_{n+k=m} t^{n+1}/(n+1)! (-1)^k b_k u^{k+1},
  // summed over the observations once per fit: O(kGaussNewtonOrder^2) per
  // observation, and K then costs O(kGaussNewtonOrder d^3) per iteration,
  // independent of N. At z = 0 both blocks reduce to b = sum w t (1 - t), so
  // K = H kron I on commutative groups.
  static void gauss_newton_coefficients(Problem& problem) {
    // Mixed moments S[p][q] = sum_i w_i t_i^p u_i^q for p, q >= 1,
    // p + q <= kOrder + 2: then [z^m] sum_i w_i g_{t_i} =
    // sum_k (-1)^k T[m][k] S[m-k+1][k+1] (T[m][k] = b_k / (m-k+1)!), and the
    // mirror block swaps p and q.
    constexpr int kOrder = kGaussNewtonOrder;
    constexpr int kPowers = kOrder + 2;
    std::array<std::array<Scalar, kPowers + 1>, kPowers + 1> moments{};
    std::array<Scalar, kPowers + 1> t_power{}, u_power{};
    for (std::size_t i = 0; i < problem.t.size(); ++i) {
      const Scalar t = problem.t[i], u = 1 - t;
      t_power[0] = problem.w[i];
      u_power[0] = 1;
      for (int j = 1; j <= kPowers; ++j) {
        t_power[j] = t_power[j - 1] * t;
        u_power[j] = u_power[j - 1] * u;
      }
      for (int p = 1; p < kPowers; ++p) {
        for (int q = 1; p + q <= kPowers; ++q)
          moments[p][q] += t_power[p] * u_power[q];
      }
    }
    for (int m = 0; m <= kOrder; ++m) {
      Scalar start = 0, end = 0;
      for (int k = 0; k <= m; ++k) {
        const Scalar coefficient = static_cast<Scalar>(kPsiSeriesTable[m][k]);
        const Scalar signed_coefficient = k % 2 == 0 ? coefficient : -coefficient;
        start += signed_coefficient * moments[m - k + 1][k + 1];
        end += signed_coefficient * moments[k + 1][m - k + 1];
      }
      problem.k01[m] = start;
      problem.k10[m] = m % 2 == 0 ? end : -end;
    }
  }

  // One pass over the data in the log chart at f_ref, the observation nearest
  // the middle of the covariate range, y_i = log(f_ref^{-1} f_i). It gives
  //
  //  * the default start: the weighted least-squares line y_i ~ (1 - t_i) x0
  //    + t_i x1, i.e. (x0, x1) = (H^{-1} kron I)(sum w (1-t) y, sum w t y),
  //    (g0, g1) = (f_ref exp(x0), f_ref exp(x1)). It is exact on commutative
  //    groups, first-order accurate otherwise, and, like the iteration,
  //    equivariant under left and right translation and inversion (the chart
  //    moves with f_ref), so the whole fit stays equivariant. The middle
  //    observation keeps the chart's distortion smallest for the endpoints;
  //  * the data's spread about their mean in that chart,
  //    sum w |y_i - ybar|^2: on commutative groups exactly the total sum of
  //    squares of ordinary regression; otherwise the spread about the
  //    bi-invariant mean up to terms of third order in the data's radius.
  struct Chart {
    Element g0, g1;
    Element reference;  // the observation nearest the middle of the covariates
    Scalar spread = 0;
    std::ptrdiff_t no_logarithm = -1;  // an observation whose log was not finite
  };

  template <class Observations>
  Chart chart_fit(const Observations& observations, const Problem& problem) const {
    const std::size_t n = observations.size();
    std::size_t reference = 0;
    for (std::size_t i = 1; i < n; ++i) {
      using std::abs;
      if (abs(problem.t[i] - Scalar(0.5)) < abs(problem.t[reference] - Scalar(0.5))) reference = i;
    }
    const Element& f_ref = observations[reference];
    const Element f_ref_inverse = G::inverse(f_ref);
    Tangent moment0 = Tangent::Zero(), moment1 = Tangent::Zero();
    Scalar square_sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Tangent y = G::log(G::compose(f_ref_inverse, observations[i]));
      if (!y.allFinite()) {
        Chart outside;
        outside.g0 = outside.g1 = outside.reference = f_ref;
        outside.no_logarithm = index(i);
        return outside;
      }
      moment0 += problem.w[i] * (1 - problem.t[i]) * y;
      moment1 += problem.w[i] * problem.t[i] * y;
      square_sum += problem.w[i] * y.squaredNorm();
    }
    const Scalar determinant = problem.a * problem.c - problem.b * problem.b;
    const Tangent x0 = (problem.c * moment0 - problem.b * moment1) / determinant;
    const Tangent x1 = (problem.a * moment1 - problem.b * moment0) / determinant;
    const Tangent total = moment0 + moment1;  // sum w y
    Chart chart;
    chart.reference = f_ref;
    chart.g0 = exp_at<G>(f_ref, x0);
    chart.g1 = exp_at<G>(f_ref, x1);
    chart.spread = std::max(Scalar(0), square_sum - total.squaredNorm() / problem.weight_sum);
    return chart;
  }

  // r_i = log(b_i^{-1} f_i), the residual of one observation at the
  // prediction b_i = g0 exp(t_i X), with b_i^{-1} = exp(-t_i X) g0^{-1}.
  static Tangent residual(const Element& g0_inverse, const Tangent& x, Scalar t, const Element& f) {
    return G::log(G::compose(G::exp(-t * x), G::compose(g0_inverse, f)));
  }

  // The net force of eq. "v" at (g0, g1), x = log(g0^{-1} g1), a = ad_x.
  //
  // Moment form: psi_s(z) = sum_m (-1)^m sum_k T[m][k] s^{k+1} z^m, and A is
  // the same for every observation, so
  //   v1 = sum_m (-A)^m u_m,  u_m = sum_k T[m][k] P_{k+1},  P_j = sum_i w_i t_i^j r_i,
  //   v0 = sum_m   A^m z_m,   z_m = sum_k T[m][k] Q_{k+1},  Q_j = sum_i w_i (1 - t_i)^j r_i
  // (psi_{1-t}(-A) flips the sign of z and of (-1)^m together). Each
  // observation then costs one exp, one log, two compositions and
  // 2 (M + 1) vector updates; the M matrix-vector products of Horner's rule
  // are paid once per iteration, not once per observation.
  template <class Observations>
  Force net_force(const Observations& observations, const Problem& problem, const Element& g0,
                  const Tangent& x, const AdMatrix& a, int order,
                  std::vector<Tangent>& residuals) const {
    std::array<Tangent, kMaxSeriesOrder + 2> p, q;  // P_j, Q_j for j = 1 .. order + 1
    for (int j = 1; j <= order + 1; ++j) {
      p[j].setZero();
      q[j].setZero();
    }
    const Element g0_inverse = G::inverse(g0);
    const std::size_t n = observations.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Scalar t = problem.t[i];
      const Tangent r = residual(g0_inverse, x, t, observations[i]);
      residuals[i] = r;
      Scalar t_power = problem.w[i];
      Scalar one_minus_t_power = problem.w[i];
      for (int j = 1; j <= order + 1; ++j) {
        t_power *= t;
        one_minus_t_power *= 1 - t;
        p[j] += t_power * r;
        q[j] += one_minus_t_power * r;
      }
    }
    const auto series_term = [&](const std::array<Tangent, kMaxSeriesOrder + 2>& moments, int m) {
      Tangent term = Tangent::Zero();
      for (int k = 0; k <= m; ++k)
        term += static_cast<Scalar>(kPsiSeriesTable[m][k]) * moments[k + 1];
      return term;
    };
    Force force{series_term(q, order), series_term(p, order)};
    for (int m = order - 1; m >= 0; --m) {  // Horner's rule
      force.v0 = a * force.v0 + series_term(q, m);
      force.v1 = -(a * force.v1) + series_term(p, m);
    }
    return force;
  }

  // The net force with psi in closed form (core/exact_inverse_differential):
  // v0 = sum w psi_{1-t}(-A) r, v1 = sum w psi_t(A) r, and psi_s(-A) is
  // psi_s of ad_{-X}. Both use the angles t theta/2 and (1 - t) theta/2 with
  // their roles swapped: per observation, the residual, two sin/cos pairs
  // and two closed forms.
  template <class Observations>
  Force net_force_exact(const Observations& observations, const Problem& problem, const Element& g0,
                        const Tangent& x, std::vector<Tangent>& residuals) const {
    using SinCos = exact_detail::SinCos<Scalar>;
    const auto forward = ExactPsi<G>::prepare(x);
    const auto backward = ExactPsi<G>::prepare(-x);
    const Element g0_inverse = G::inverse(g0);
    Force force{Tangent::Zero(), Tangent::Zero()};
    const std::size_t n = observations.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Scalar t = problem.t[i], w = problem.w[i];
      const Tangent r = residual(g0_inverse, x, t, observations[i]);
      residuals[i] = r;
      const SinCos t_half = SinCos::of(t * forward.theta / 2);
      const SinCos u_half = SinCos::of((1 - t) * forward.theta / 2);
      force.v0 += w * ExactPsi<G>::apply(backward, 1 - t, u_half, t_half, r);
      force.v1 += w * ExactPsi<G>::apply(forward, t, t_half, u_half, r);
    }
    return force;
  }

  // The series order for the current X (fixed or adaptive).
  std::pair<int, Scalar> series_order(const AdMatrix& a) const {
    if (options_.method == Method::series && options_.series_order > 0) {
      return {options_.series_order, Scalar(0)};
    }
    return adaptive_series_order(a, std::numeric_limits<Scalar>::epsilon(),
                                 options_.max_series_order);
  }

  // Everything the iteration needs at one pair of endpoints.
  struct State {
    Element g0, g1;
    Tangent x;   // log(g0^{-1} g1)
    AdMatrix a;  // ad_x
    int order = 0;
    Scalar truncation = 0;
    Force force;
    bool series_converges = true;  // spectral radius of ad_x below 2 pi
  };

  // Evaluates x, ad_x, the series order and the force at (g0, g1), writing
  // the residuals there into `residuals` (sized N).
  template <class Observations>
  State evaluate(const Observations& observations, const Problem& problem, const Element& g0,
                 const Element& g1, std::vector<Tangent>& residuals) const {
    constexpr Scalar kTwoPi = Scalar(6.283185307179586476925286766559L);
    State state;
    state.g0 = g0;
    state.g1 = g1;
    state.x = log_at<G>(g0, g1);
    state.a = G::ad(state.x);
    if (!(ad_spectral_radius<G>(state.x) < kTwoPi)) {
      state.series_converges = false;
      return state;
    }
    if constexpr (ExactPsi<G>::available) {
      if (options_.method == Method::exact &&
          ExactPsi<G>::angle(state.x) >= static_cast<Scalar>(kExactMinAngle)) {
        state.order = 0;  // no truncation
        state.truncation = 0;
        state.force = net_force_exact(observations, problem, g0, state.x, residuals);
        return state;
      }
    }
    std::tie(state.order, state.truncation) = series_order(state.a);
    state.force = net_force(observations, problem, g0, state.x, state.a, state.order, residuals);
    return state;
  }

  // The full step (d0, d1) of the chosen solver at `state`.
  std::pair<Tangent, Tangent> step(const Problem& problem, const State& state) const {
    const Tangent& v0 = state.force.v0;
    const Tangent& v1 = state.force.v1;
    switch (options_.solver) {
      case Solver::paper:
      case Solver::optimal_linear:
        return {problem.lambda * v0, problem.lambda * v1};
      case Solver::preconditioned: {
        // H^{-1} mixes v0 (left-trivialised at g0) with v1 (at g1). Mixed
        // as they are, the step would keep left and right equivariance but
        // not inverse equivariance: inversion maps v0 -> -Ad_g0 v0 and
        // v1 -> -Ad_g1 v1, two different frames. Carrying each across by
        // half the geodesic, T = Ad_exp(X/2), restores it (T transforms as
        // Ad_g0 T Ad_g1^{-1} under inversion), and it is also the first-order
        // term of Gauss-Newton's coupling, K01 = b (I + A/2) + O(A^2).
        const Scalar determinant = problem.a * problem.c - problem.b * problem.b;
        const AdMatrix forward = G::Ad(G::exp(state.x / 2));    // from g1's frame to g0's
        const AdMatrix backward = G::Ad(G::exp(-state.x / 2));  // from g0's frame to g1's
        return {(problem.c * v0 - problem.b * (forward * v1)) / determinant,
                (problem.a * v1 - problem.b * (backward * v0)) / determinant};
      }
      case Solver::gauss_newton:
        return gauss_newton_step(problem, state);
    }
    return {v0, v1};
  }

  // (d0, d1) = K^{-1} (v0, v1) with K = [a I, K01; K10, c I] (DESIGN.md,
  // "Equivariant Gauss-Newton"); the blocks by Horner's rule in A = ad_X.
  // Fixed-size throughout: no heap allocation.
  std::pair<Tangent, Tangent> gauss_newton_step(const Problem& problem, const State& state) const {
    constexpr int d = G::dof;
    using KMatrix = Eigen::Matrix<Scalar, 2 * d, 2 * d>;
    using KVector = Eigen::Matrix<Scalar, 2 * d, 1>;
    const AdMatrix identity = AdMatrix::Identity();
    AdMatrix k01 = problem.k01[kGaussNewtonOrder] * identity;
    AdMatrix k10 = problem.k10[kGaussNewtonOrder] * identity;
    for (int m = kGaussNewtonOrder - 1; m >= 0; --m) {
      k01 = state.a * k01 + problem.k01[m] * identity;
      k10 = state.a * k10 + problem.k10[m] * identity;
    }
    KMatrix k;
    k.template topLeftCorner<d, d>() = problem.a * identity;
    k.template topRightCorner<d, d>() = k01;
    k.template bottomLeftCorner<d, d>() = k10;
    k.template bottomRightCorner<d, d>() = problem.c * identity;
    KVector v;
    v.template head<d>() = state.force.v0;
    v.template tail<d>() = state.force.v1;
    const KVector delta = k.partialPivLu().solve(v);
    return {delta.template head<d>(), delta.template tail<d>()};
  }

  // The iteration g0 <- g0 exp(d0), g1 <- g1 exp(d1) (the paper's eq.
  // "algorithm" for Solver::paper) until the step proposed at the current
  // endpoints has norm at or below the tolerance; those endpoints are
  // returned (for the paper solver ||v|| <= tolerance / lambda holds there). Every solver but paper
  // carries a safeguard: a step that would increase ||v|| is halved (up to kMaxHalvings times), so
  // a fast step cannot overshoot where the paper's step converges (a full step on a long geodesic
  // can carry an endpoint past pi). The test uses the Euclidean norm of v in left-trivialised
  // coordinates: left-invariant, and only approximately right-invariant on groups without a
  // bi-invariant metric (SE(3)), which matters only for a borderline halving decision. No heap
  // allocation happens inside the loop (the history is reserved). Returns the state at the returned
  // endpoints; result.residuals hold the residuals there (unless the series did not converge at
  // that state).
  //
  // Every state it returns has a convergent series and a finite force, hence
  // finite residuals, except when even the fallback start (the middle
  // observation as a constant model, whose residuals the chart fit checked)
  // is unusable, which cannot happen: there X = 0.
  template <class Observations>
  State iterate(const Observations& observations, const Problem& problem, const Element& start0,
                const Element& start1, const Element& fallback, Result& result) const {
    using std::isfinite;
    using std::sqrt;
    // A step this much larger than the smallest one seen means the
    // iteration left the basin where it contracts, unless both are at the
    // rounding level (below sqrt(epsilon), or the tolerance), where steps
    // fluctuate by orders of magnitude without meaning anything.
    constexpr Scalar kDivergenceGrowth = Scalar(1e3);
    const Scalar divergence_floor =
        kDivergenceGrowth *
        std::max(options_.tolerance, sqrt(std::numeric_limits<Scalar>::epsilon()));
    constexpr int kMaxHalvings = 20;
    int iterations_without_progress = 0;

    result.step_norms.reserve(static_cast<std::size_t>(options_.max_iterations));
    if (options_.record_iterates) {
      result.iterates.reserve(static_cast<std::size_t>(options_.max_iterations));
    }
    result.status = Status::max_iterations;
    result.residuals.resize(observations.size());
    const bool safeguarded = options_.solver != Solver::paper;
    Scalar smallest_step = std::numeric_limits<Scalar>::infinity();
    const auto usable = [](const State& s) {
      return s.series_converges && s.force.v0.allFinite() && s.force.v1.allFinite();
    };
    State state = evaluate(observations, problem, start0, start1, result.residuals);
    // A start beyond the series' disc or the log's domain (an extrapolated
    // chart line on a matrix group, a far initial guess): start from the
    // middle observation instead.
    if (!usable(state))
      state = evaluate(observations, problem, fallback, fallback, result.residuals);
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      if (!state.series_converges) {
        result.status = Status::series_diverged;
        return state;
      }
      result.diagnostics.series_order = state.order;
      result.diagnostics.series_truncation_bound = state.truncation;

      const auto [d0, d1] = step(problem, state);
      const Scalar step_norm = sqrt(d0.squaredNorm() + d1.squaredNorm());
      if (!isfinite(step_norm) ||
          (step_norm > kDivergenceGrowth * smallest_step && step_norm > divergence_floor)) {
        result.status = Status::diverged;
        return state;
      }
      result.step_norms.push_back(step_norm);
      result.iterations = iteration + 1;
      // The step proposed at the current endpoints certifies them: it is
      // what remains to be moved, so it is not taken when below tolerance.
      if (step_norm <= options_.tolerance) {
        result.status = Status::converged;
        return state;
      }
      // Steps below sqrt(epsilon) relative to the geodesic's size are at
      // the rounding level, where they fluctuate without meaning.
      const Scalar rounding_level =
          std::max(options_.tolerance, sqrt(std::numeric_limits<Scalar>::epsilon()) *
                                           std::max(Scalar(1), sqrt(state.x.squaredNorm())));
      if (step_norm < smallest_step) {
        smallest_step = step_norm;
        iterations_without_progress = 0;
      } else if (options_.tolerance > 0 && step_norm <= rounding_level &&
                 ++iterations_without_progress >= kStallIterations) {
        result.status = Status::stalled;
        return state;
      }

      Scalar fraction = 1;
      State next = evaluate(observations, problem, exp_at<G>(state.g0, d0), exp_at<G>(state.g1, d1),
                            result.residuals);
      if (safeguarded) {
        const Scalar force_norm = state.force.norm();
        const auto acceptable = [&](const State& trial) {
          return trial.series_converges && trial.force.norm() <= force_norm;
        };
        for (int halving = 0; halving < kMaxHalvings && !acceptable(next); ++halving) {
          fraction /= 2;
          ++result.diagnostics.backtracks;
          next = evaluate(observations, problem, exp_at<G>(state.g0, fraction * d0),
                          exp_at<G>(state.g1, fraction * d1), result.residuals);
        }
        // Every halving failed: no step along this direction decreases the
        // force. Above the rounding level that means the data are outside
        // the estimator's domain; stop rather than wander.
        if (!acceptable(next) && step_norm > rounding_level) {
          result.status = Status::stalled;
          evaluate(observations, problem, state.g0, state.g1, result.residuals);
          return state;
        }
      }
      // The step left the series' disc, or the domain of the group's log
      // (MatrixGroup returns NaN there, so the force is not finite). Keep
      // the last usable endpoints.
      if (!usable(next)) {
        result.status = next.series_converges ? Status::diverged : Status::series_diverged;
        evaluate(observations, problem, state.g0, state.g1, result.residuals);
        return state;
      }
      state = next;
      if (options_.record_iterates) result.iterates.emplace_back(state.g0, state.g1);
    }
    return state;
  }

  // The geodesic and the diagnostics at the returned endpoints.
  template <class Observations>
  void finish(const Observations& observations, const Problem& problem, const State& state,
              Scalar spread, Result& result) const {
    using std::sqrt;
    const std::size_t n = observations.size();
    result.geodesic = Geodesic<G>(state.g0, state.g1, problem.t_min, problem.t_max);
    Diagnostics& d = result.diagnostics;
    if (state.series_converges) {
      d.force_norm = state.force.norm();
    } else {  // no force to report (0); the residuals need no series
      const Element g0_inverse = G::inverse(state.g0);
      for (std::size_t i = 0; i < n; ++i) {
        result.residuals[i] = residual(g0_inverse, state.x, problem.t[i], observations[i]);
      }
    }
    const std::size_t steps = result.step_norms.size();
    if (steps >= 2 && result.step_norms[steps - 2] > 0) {
      d.contraction_factor = result.step_norms[steps - 1] / result.step_norms[steps - 2];
    }
    Scalar residual_sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      residual_sum += problem.w[i] * result.residuals[i].squaredNorm();
    }
    d.residual_rms = sqrt(residual_sum / problem.weight_sum);
    d.residual_rms_about_mean = sqrt(spread / problem.weight_sum);
    d.explained_variance = spread > 0 ? 1 - residual_sum / spread : Scalar(1);
  }

  Options options_;
};

}  // namespace bireg
