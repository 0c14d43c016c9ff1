// bireg: robust geodesic regression by iteratively reweighted bi-invariant
// fits (DESIGN.md section 5, "Robust loss"; the estimator is Definition 2.1
// of Hanik & von Tycowicz, "Bi-invariant Geodesic Regression: Existence,
// Uniqueness, and Convergence", with per-observation weights).
//
// The robust fit minimises sum_i rho(d_i), with
//
//   d_i^2 = r_i^T S^{-1} r_i,   r_i = log(gamma(t_i)^{-1} f_i)   (left-trivialised),
//
// rho a loss of statistics/robust/loss.hpp and S a robust scatter of the
// residuals. Under left translation of the data r_i is unchanged; under
// right translation by h it becomes Ad_{h^{-1}} r_i, and S (built below from
// the residuals alone) becomes Ad_{h^{-1}} S Ad_{h^{-1}}^T, so d_i, the
// weights and hence the whole iteration are left AND right invariant on
// every group, SE(3) included: the robust fit keeps the equivariance of
// Theorem 2.4. (A Euclidean |r_i| would break right equivariance on SE(3),
// which has no bi-invariant metric; tests/test_robust.cpp shows it.)
//
// Iteration (IRLS), each refit warm-started from the previous endpoints:
//
//   0. the plain fit (all robust weights 1) and its scatter S (a plain fit
//      that did not converge still serves as the start);
//   1. d_i from the current residuals and S; robust weights w_i = psi(d_i)/d_i;
//   2. stop if max_i |w_i - w_i(previous)| <= weight_tolerance (the weights
//      have settled: the last fit used weights within that of the ones its
//      own residuals give); else refit with weights u_i w_i (u_i the user's
//      weights: they combine multiplicatively), update S, go to 1.
//
// Huber's loss runs this to the end. A redescending loss (Cauchy, Tukey)
// first runs Huber's (convex: its solution does not depend on the start, and
// it bounds every observation's influence), then continues from that
// solution with its own weights. Both stages together take at most
// max_rounds refits.
//
// The scatter S (affine equivariant, so d_i is invariant):
//
//   S_raw = sum_i c_i r_i r_i^T / sum_i c_i      c_i = u_i w_i, the current fit's weights
//   S     = S_raw * med_u(r_i^T S_raw^{-1} r_i) / median(chi^2_p)
//
// S_raw's shape is consistent at any elliptical residual distribution
// (the weights depend on d_i only); the rescaling by the u-weighted median
// of the squared distances (over every observation with u_i > 0, outliers
// included) makes its scale consistent at the Gaussian and gives the scale
// a 50% breakdown point. The shape is an M-estimate of scatter, whose
// breakdown point is at most 1/(p+1) against adversarial contamination
// (Maronna 1976: 25% on SO(3), 14% on SE(3)); gross outliers far from the
// data (random rotations and poses) get weight ~0 and do not reach it:
// docs/robust.md gives the measured behaviour up to 30%.
//
// Outliers: observation i is flagged when d_i^2 > chi^2_p(1 - outlier_probability)
// (default: 0.999 quantile), which for all three losses is the same as its
// robust weight being below w at that distance (weights do not increase
// with d); a Gaussian residual is flagged with probability 0.001.
//
// Failures are a status and a message, never NaN: too few observations
// with positive weight (fewer than p + 2, below which S is singular, or
// all at one covariate), a singular scatter (residuals confined to a
// subspace, e.g. planar motion fitted in SE(3), or exact data), a failed
// refit, the round limit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "bireg/concept.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/robust/loss.hpp"

namespace bireg {

template <class Scalar>
struct RobustOptions {
  Loss loss = Loss::huber;
  // The loss's constant c in Mahalanobis units; 0 selects 95% Gaussian
  // efficiency in dof dimensions (robust_loss.hpp; e.g. Huber 1.628 on
  // SO(3), 1.869 on SE(3)). A redescending loss's Huber stage always uses
  // Huber's 95% constant.
  Scalar loss_scale = 0;
  // The weights have settled when no weight moved by more than this in a
  // round. The estimate then moves by about this times the residuals'
  // scale per observation's share in a further round, far below the
  // statistical error at the default.
  Scalar weight_tolerance = Scalar(1e-6);
  // Refits allowed, over both stages.
  int max_rounds = 100;
  // Flag observation i as an outlier when a Gaussian residual would lie
  // as far out with at most this probability.
  Scalar outlier_probability = Scalar(1e-3);
};

enum class RobustStatus {
  converged,         // the weights settled
  max_rounds,        // the round limit came first: the last fit is returned
  too_few_good,      // fewer observations with positive weight than the model needs
  singular_scatter,  // the residuals do not spread in every direction of the algebra
  fit_failed,        // the plain fit refused the data, or the last fit did not
                     // converge: see fit.status (earlier failed refits are only
                     // starts for the next round)
  invalid_input,     // a robust option is out of range
};

inline const char* to_string(RobustStatus status) {
  switch (status) {
    case RobustStatus::converged:
      return "converged";
    case RobustStatus::max_rounds:
      return "max_rounds";
    case RobustStatus::too_few_good:
      return "too_few_good";
    case RobustStatus::singular_scatter:
      return "singular_scatter";
    case RobustStatus::fit_failed:
      return "fit_failed";
    case RobustStatus::invalid_input:
      return "invalid_input";
  }
  return "unknown";
}

template <class G>
struct RobustResult {
  using Scalar = typename G::Scalar;
  using AdMatrix = Eigen::Matrix<Scalar, G::dof, G::dof>;

  RobustStatus status = RobustStatus::invalid_input;
  std::string message;
  // The last fit (weights u_i w_i); its geodesic is the robust estimate.
  RegressionResult<G> fit;
  Loss loss = Loss::huber;
  Scalar loss_scale = 0;  // the constant c used by the final stage
  // Robust weights w_i = psi(d_i)/d_i in [0, 1] from the final residuals
  // and scatter (within weight_tolerance of those the last fit used when
  // converged), the distances d_i, input order.
  std::vector<Scalar> robust_weights;
  std::vector<Scalar> distances;
  AdMatrix scatter = AdMatrix::Zero();  // S at the final residuals
  int rounds = 0;                       // refits after the plain fit, both stages
  int huber_rounds = 0;                 // of which in the Huber stage
  int fit_iterations = 0;               // solver iterations over all fits
  std::vector<std::size_t> outliers;    // indices flagged (see the header comment)

  bool ok() const { return status == RobustStatus::converged; }
};

template <class G>
class RobustGeodesicRegression {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = Eigen::Matrix<Scalar, G::dof, G::dof>;
  using Options = RobustOptions<Scalar>;
  using RegressionOptionsType = RegressionOptions<Scalar>;
  using Result = RobustResult<G>;

  RobustGeodesicRegression() = default;
  explicit RobustGeodesicRegression(Options options, RegressionOptionsType regression = {})
      : options_(std::move(options)), regression_(std::move(regression)) {}

  // As GeodesicRegression<G>::fit; `weights` (non-negative, empty: all 1)
  // multiply the robust weights.
  template <class Observations, class Covariates>
  Result fit(const Observations& observations, const Covariates& covariates,
             const std::vector<Scalar>& given_weights = {}) const {
    using std::isfinite;
    Result result;
    result.loss = options_.loss;
    if (!is_valid(options_.loss)) {  // it indexes the tables of constants below
      result.message = "loss must be huber, cauchy or tukey (got " +
                       std::to_string(static_cast<int>(options_.loss)) + ")";
      return result;
    }
    if (!(options_.loss_scale >= 0) || !isfinite(options_.loss_scale)) {
      result.message = "loss_scale must be a finite non-negative number (0 = 95% efficiency)";
      return result;
    }
    if (!(options_.weight_tolerance > 0) || !isfinite(options_.weight_tolerance)) {
      result.message = "weight_tolerance must be a finite positive number";
      return result;
    }
    if (options_.max_rounds < 1) {
      result.message = "max_rounds must be at least 1";
      return result;
    }
    if (!(options_.outlier_probability > 0 && options_.outlier_probability < 1)) {
      result.message = "outlier_probability must lie in (0, 1)";
      return result;
    }

    const GeodesicRegression<G> regression(regression_);
    result.fit = regression.fit(observations, covariates, given_weights);
    // Accepted by the fit (or refused below); divided by the largest, so
    // that the scatter's sums neither overflow nor underflow.
    const std::vector<Scalar> weights = normalised_weights(given_weights);
    result.fit_iterations = result.fit.iterations;
    // A plain fit that failed but returned endpoints (no_descent,
    // max_iterations, ...: gross outliers can take the data outside the
    // plain estimator's domain) is a start like any other: the reweighting
    // can bring the fit back. Only refused data end here.
    if (!result.fit.geodesic) return fit_failed(std::move(result), "the plain fit");

    const std::size_t n = observations.size();
    const std::vector<Scalar> user = weights.empty() ? std::vector<Scalar>(n, Scalar(1)) : weights;
    if (auto shortage = too_few_good(user, covariates)) {
      result.status = RobustStatus::too_few_good;
      result.message = *shortage;
      return result;
    }
    std::vector<Scalar> robust(n, Scalar(1));
    std::vector<Scalar> combined = user;
    if (!update_scatter(result, user, combined)) return result;

    const RobustConstants& constants = robust_constants<G::dof>();
    const Scalar huber_constant =
        static_cast<Scalar>(constants.efficient_constant[static_cast<int>(Loss::huber)]);
    const Scalar final_constant =
        options_.loss_scale > 0
            ? options_.loss_scale
            : static_cast<Scalar>(constants.efficient_constant[static_cast<int>(options_.loss)]);

    // Stage 1 (Huber) for a redescending loss; the only stage otherwise.
    const bool two_stages = redescends(options_.loss);
    const int stages = two_stages ? 2 : 1;
    bool settled = false;
    for (int stage = 0; stage < stages; ++stage) {
      const Loss loss = stage + 1 < stages ? Loss::huber : options_.loss;
      const Scalar c = stage + 1 < stages ? huber_constant : final_constant;
      result.loss_scale = c;
      settled = false;
      while (!settled) {
        std::vector<Scalar> next = weights_at(result, loss, c);
        Scalar largest_change = 0;
        for (std::size_t i = 0; i < n; ++i) {
          largest_change = std::max(largest_change, std::abs(next[i] - robust[i]));
        }
        robust = std::move(next);
        for (std::size_t i = 0; i < n; ++i)
          combined[i] = user[i] * robust[i];
        settled = largest_change <= options_.weight_tolerance;
        if (settled) break;
        if (auto shortage = too_few_good(combined, covariates)) {
          result.status = RobustStatus::too_few_good;
          result.message =
              *shortage + " after down-weighting by the " + std::string(to_string(loss)) + " loss";
          result.robust_weights = robust;
          return result;
        }
        if (result.rounds == options_.max_rounds) break;
        const auto& geodesic = *result.fit.geodesic;
        result.fit = regression.fit_from({geodesic.start(), geodesic.end()}, observations,
                                         covariates, combined);
        ++result.rounds;
        if (stage + 1 < stages) ++result.huber_rounds;
        result.fit_iterations += result.fit.iterations;
        if (!result.fit.geodesic) return fit_failed(std::move(result), "a reweighted fit");
        if (!update_scatter(result, user, combined)) return result;
      }
      if (!settled) break;
    }

    // The final weights, distances and flags, from the final fit and S.
    result.robust_weights = weights_at(result, options_.loss, final_constant);
    const Scalar flag_distance = static_cast<Scalar>(
        std::sqrt(options_.outlier_probability == Scalar(1e-3)
                      ? constants.chi_square_999
                      : chi_square_quantile(G::dof, 1 - double(options_.outlier_probability))));
    for (std::size_t i = 0; i < n; ++i) {
      if (user[i] > 0 && result.distances[i] > flag_distance) result.outliers.push_back(i);
    }
    if (!result.fit.ok()) return fit_failed(std::move(result), "the final fit");
    result.status = settled ? RobustStatus::converged : RobustStatus::max_rounds;
    result.message = settled ? "the weights settled after " + std::to_string(result.rounds) +
                                   " reweighted fits; " + std::to_string(result.outliers.size()) +
                                   " of " + std::to_string(n) + " observations flagged"
                             : "the weights still moved after max_rounds = " +
                                   std::to_string(options_.max_rounds) + " reweighted fits";
    return result;
  }

 private:
  static Result fit_failed(Result result, const char* which) {
    result.status = RobustStatus::fit_failed;
    result.message = std::string(which) + " failed (" + to_string(result.fit.status) + ")" +
                     (result.fit.message.empty() ? "" : ": " + result.fit.message);
    return result;
  }

  // The model needs p + 2 observations with positive weight (the line's 2
  // coefficients per coordinate leave N - 2 residual degrees of freedom,
  // and S needs p of them), at two covariates at least.
  template <class Covariates>
  static std::optional<std::string> too_few_good(const std::vector<Scalar>& weights,
                                                 const Covariates& covariates) {
    constexpr std::size_t needed = static_cast<std::size_t>(G::dof) + 2;
    std::size_t good = 0;
    bool first_found = false, two_covariates = false;
    double first_covariate = 0;
    for (std::size_t i = 0; i < weights.size(); ++i) {
      if (!(weights[i] > 0)) continue;
      ++good;
      const double covariate = static_cast<double>(covariates[i]);
      if (!first_found) {
        first_found = true;
        first_covariate = covariate;
      } else if (covariate != first_covariate) {
        two_covariates = true;
      }
    }
    if (good < needed) {
      return "fewer good observations than needed: " + std::to_string(good) +
             " with positive weight, the robust fit in " + G::name + " needs " +
             std::to_string(needed) + " (dof + 2)";
    }
    if (!two_covariates) {
      return std::string(
          "fewer good observations than needed: those with positive weight share one "
          "covariate, so the slope is not identifiable");
    }
    return std::nullopt;
  }

  // S from the fit's residuals (header comment); false, with the status
  // set, when it is singular.
  static bool update_scatter(Result& result, const std::vector<Scalar>& user,
                             const std::vector<Scalar>& combined) {
    using std::isfinite;
    const std::vector<Tangent>& residuals = result.fit.residuals;
    const std::size_t n = residuals.size();
    AdMatrix raw = AdMatrix::Zero();
    Scalar weight_sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!(combined[i] > 0)) continue;
      raw.noalias() += combined[i] * residuals[i] * residuals[i].transpose();
      weight_sum += combined[i];
    }
    raw /= weight_sum;
    std::vector<Scalar> squared(n, Scalar(0));
    const bool raw_ok = squared_distances(raw, residuals, squared);
    const Scalar median = raw_ok ? weighted_median(squared, user) : Scalar(0);
    const Scalar consistency = static_cast<Scalar>(robust_constants<G::dof>().chi_square_median);
    if (!raw_ok || !(median > 0) || !isfinite(median)) {
      result.status = RobustStatus::singular_scatter;
      result.message =
          std::string("the residuals do not spread in every direction of the algebra of ") +
          G::name +
          " (their scatter is singular, e.g. exact data or planar motion in SE3): the "
          "Mahalanobis distances are undefined; use the plain fit";
      result.scatter = raw;
      return false;
    }
    result.scatter = raw * (median / consistency);
    result.distances.assign(n, Scalar(0));
    const Scalar unscale = consistency / median;
    for (std::size_t i = 0; i < n; ++i) {
      result.distances[i] = std::sqrt(squared[i] * unscale);
    }
    return true;
  }

  // r_i^T S^{-1} r_i for every residual; false if S is not positive definite.
  static bool squared_distances(const AdMatrix& scatter, const std::vector<Tangent>& residuals,
                                std::vector<Scalar>& squared) {
    const Eigen::LLT<AdMatrix> cholesky(scatter);
    if (cholesky.info() != Eigen::Success) return false;
    const auto lower = cholesky.matrixL();
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      const Tangent whitened = lower.solve(residuals[i]);
      squared[i] = whitened.squaredNorm();
      if (!std::isfinite(static_cast<double>(squared[i]))) return false;
    }
    const Scalar smallest_pivot = cholesky.matrixLLT().diagonal().minCoeff();
    return smallest_pivot > 0;
  }

  // The lower weighted median of values with weights (zero weights ignored).
  static Scalar weighted_median(const std::vector<Scalar>& values,
                                const std::vector<Scalar>& weights) {
    std::vector<std::size_t> order;
    Scalar total = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (weights[i] > 0) {
        order.push_back(i);
        total += weights[i];
      }
    }
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    Scalar cumulative = 0;
    for (std::size_t i : order) {
      cumulative += weights[i];
      if (cumulative >= total / 2) return values[i];
    }
    return order.empty() ? Scalar(0) : values[order.back()];
  }

  static std::vector<Scalar> weights_at(const Result& result, Loss loss, Scalar c) {
    std::vector<Scalar> weights(result.distances.size());
    for (std::size_t i = 0; i < weights.size(); ++i) {
      weights[i] = robust_weight(loss, result.distances[i], c);
    }
    return weights;
  }

  Options options_;
  RegressionOptionsType regression_;
};

}  // namespace bireg
