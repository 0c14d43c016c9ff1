// bireg: the share of the data's spread about their bi-invariant mean that
// the geodesic explains (DESIGN.md section 5), in two forms.
//
//   Euclidean:    R^2 = 1 - sum w |r_i|^2 / sum w |y_i|^2,
//   generalised:  1 - Lambda,  Lambda = det(S_res) / det(S_tot)  (Wilks),
//
// r_i the fit's residuals, y_i = log(m^{-1} f_i) about the mean m
// (statistics/inference/mean.hpp), S_res = sum w r r^T, S_tot = sum w y y^T.
//
// The Euclidean form is the ordinary R^2 on R^n. It is left invariant on
// every group (left translation changes neither r_i nor y_i), but right
// translation maps both by Ad_{h^{-1}}, which preserves |.| only on compact
// groups (SO(n), with its bi-invariant metric): on SE(3) it also mixes the
// units of rotation and translation. The generalised form is left and
// right invariant on every group (statistics/inference/scatter.hpp) and unit-free;
// where S_tot is singular both determinants are taken on its numerical
// range (pseudo-determinant), reported by `rank` and `pseudo_determinant`.
// Both are invariant under inversion only to first order in the residuals
// (inversion maps r_i by Ad_{f_i}, a different matrix per observation).
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "bireg/regression/result.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/scatter.hpp"

namespace bireg {

template <class Scalar>
struct ExplainedVariance {
  bool defined = false;
  std::string message;      // why not defined, or the pseudo-determinant note
  Scalar euclidean = 0;     // R^2
  Scalar generalized = 0;   // 1 - Lambda
  Scalar wilks_lambda = 1;  // det(S_res) / det(S_tot)
  int rank = 0;             // of S_tot
  bool pseudo_determinant = false;
};

// From the residuals about the geodesic and about the mean (same order,
// same weights; empty weights: all 1).
template <class Scalar, int D>
ExplainedVariance<Scalar> explained_variance(
    const std::vector<Eigen::Matrix<Scalar, D, 1>>& residuals,
    const std::vector<Eigen::Matrix<Scalar, D, 1>>& about_mean,
    const std::vector<Scalar>& given_weights = {}) {
  using std::isfinite;
  ExplainedVariance<Scalar> e;
  if (residuals.size() != about_mean.size() || residuals.empty() ||
      (!given_weights.empty() && given_weights.size() != residuals.size())) {
    e.message = "residuals, residuals about the mean and weights differ in length";
    return e;
  }
  for (std::size_t i = 0; i < given_weights.size(); ++i) {
    if (!(given_weights[i] >= 0) || !isfinite(given_weights[i])) {
      e.message = "weight " + std::to_string(i) + " is negative or not finite";
      return e;
    }
  }
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    if (!residuals[i].allFinite() || !about_mean[i].allFinite()) {
      e.message = "residual " + std::to_string(i) + " is not finite";
      return e;
    }
  }
  // Divided by the largest: the sums neither overflow nor underflow.
  const std::vector<Scalar> weights = normalised_weights(given_weights);
  const Eigen::Matrix<Scalar, D, D> s_res = scatter_matrix(residuals, weights);
  const Eigen::Matrix<Scalar, D, D> s_tot = scatter_matrix(about_mean, weights);
  if (!(s_tot.trace() > 0)) {
    e.message = "the data do not spread about their mean: nothing to explain";
    return e;
  }
  const ScatterRange<Scalar, D> range(s_tot);
  e.defined = true;
  e.euclidean = 1 - s_res.trace() / s_tot.trace();
  e.wilks_lambda = range.ratio(s_res);
  e.generalized = 1 - e.wilks_lambda;
  e.rank = range.rank();
  e.pseudo_determinant = !range.full();
  if (e.pseudo_determinant) {
    e.message = "S_tot is singular (rank " + std::to_string(e.rank) + " of " + std::to_string(D) +
                "): determinants taken on its range";
  }
  return e;
}

// From a fit and the mean of the same data.
template <class G>
ExplainedVariance<typename G::Scalar> explained_variance(
    const RegressionResult<G>& fit, const MeanResult<G>& mean,
    const std::vector<typename G::Scalar>& weights = {}) {
  if (!fit.ok() || !mean.ok()) {
    ExplainedVariance<typename G::Scalar> e;
    e.message = "the fit or the mean did not succeed";
    return e;
  }
  return explained_variance(fit.residuals, mean.residuals, weights);
}

}  // namespace bireg

// The compiled part's instantiations of explained_variance() (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/statistics/precompiled/explained_variance.hpp"
#endif
