// bireg: what the endpoint covariance implies (DESIGN.md section 5): the
// covariance of the body velocity and of the pose at any covariate, the
// prediction covariance of a new observation, and confidence ellipsoids.
//
// All are linear images of the endpoint perturbations (delta0, delta1),
// to first order in them. With X = log(g0^{-1} g1) and s the covariate on
// the unit interval:
//
//   displacement:  dX = J_r(X)^{-1} delta1 - J_r(-X)^{-1} delta0
//     (exp(-delta0) exp(X) exp(delta1) = exp(X + dX + O(delta^2)), J_r(-X)
//     = J_l(X), the inverse differentials of the paper's Lemma 3.1 at s = 1),
//   velocity:      dX / (t_max - t_min) per covariate unit,
//   pose at s:     eps(s) = Ad_{exp(-sX)} delta0 + s J_r(sX) dX
//     (g0 exp(delta0) exp(s (X + dX)) = gamma(s) exp(eps(s))), with eps(0) =
//     delta0 and eps(1) = delta1 (since J_r(X) J_r(-X)^{-1} = Ad_{exp(-X)}).
//
// A new observation at s is gamma(s) exp(e), e ~ (0, S): its prediction
// error log(gamma^(s)^{-1} f) ~ e - eps(s) has covariance Cov(eps(s)) + S.
//
// Confidence regions. Homoscedastic flavour: the Mahalanobis distance of a
// d-vector with covariance estimated from nu degrees of freedom follows
// Hotelling's T^2(d, nu) exactly on R^n with Gaussian noise (velocity, one
// pose, a prediction), and the two endpoints together (a d x d S shared by
// a q = 2 dimensional design) follow the Lawley-Hotelling trace
// (McKeon's approximation; statistics/inference/distributions.hpp). Robust flavour:
// Hotelling's T^2 in the quantity's full dimension with the Satterthwaite
// degrees of freedom of statistics/inference/covariance.hpp; between the endpoints
// the pose uses the smaller of the two endpoints' values (conservative).
// On curved groups all of these are first-order (small-noise) statements;
// the chi-square quantile (nu -> infinity) is available for comparison and
// is noticeably anti-conservative at N = 50 (chi2_6(0.95) = 12.6 against
// T^2_6,48(0.95) = 15.5).
//
// Singular covariances (planar motion in SE(3)) are handled on their
// numerical range: the distance uses the pseudo-inverse and the quantile
// the rank as dimension.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Core>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/inference/scatter.hpp"

namespace bireg {

enum class QuantileRule {
  small_sample,  // Hotelling's T^2 / Lawley-Hotelling with nu degrees of freedom
  chi_square,    // the large-sample limit
};

template <class G>
using EndpointMap = Eigen::Matrix<typename G::Scalar, G::dof, 2 * G::dof>;

// d(X) as a map of (delta0, delta1): [-J_r(-X)^{-1}, J_r(X)^{-1}].
template <class G>
EndpointMap<G> displacement_map(const typename G::Tangent& x) {
  EndpointMap<G> map;
  map.template leftCols<G::dof>() = -right_jacobian_inverse<G>(typename G::Tangent(-x));
  map.template rightCols<G::dof>() = right_jacobian_inverse<G>(x);
  return map;
}

// eps(s) as a map of (delta0, delta1), s on the unit interval.
template <class G>
EndpointMap<G> pose_map(const typename G::Tangent& x, typename G::Scalar s) {
  using Tangent = typename G::Tangent;
  const typename G::AdMatrix carry = s * right_jacobian<G>(Tangent(s * x));
  EndpointMap<G> map = carry.lazyProduct(displacement_map<G>(x));
  map.template leftCols<G::dof>() += G::Ad(G::exp(Tangent(-s * x)));
  return map;
}

// Outside their domain (a covariate that is not finite, or so far from the
// data that the covariance overflows) the covariances below are
// unbounded: +infinity on the diagonal, 0 off it, never NaN. Their
// standard errors and half-widths are then +infinity.
template <class Matrix>
Matrix unbounded_covariance() {
  Matrix c = Matrix::Zero();
  c.diagonal().setConstant(std::numeric_limits<typename Matrix::Scalar>::infinity());
  return c;
}

template <class Matrix>
Matrix bounded_or_unbounded(const Matrix& c) {
  return c.allFinite() ? c : unbounded_covariance<Matrix>();
}

// Covariance of the body velocity X / (t_max - t_min), per covariate unit
// squared.
template <class G>
typename G::AdMatrix velocity_covariance(const FitCovariance<G>& c) {
  // Lazy products: see covariance.hpp's satterthwaite.
  const EndpointMap<G> spread =
      displacement_map<G>(c.geodesic.displacement()).lazyProduct(c.factor);
  const typename G::Scalar range = c.geodesic.t_max() - c.geodesic.t_min();
  return bounded_or_unbounded<typename G::AdMatrix>(spread.lazyProduct(spread.transpose()) /
                                                    (range * range));
}

// Covariance of the fitted pose at covariate t (user units), as the
// left-trivialised perturbation eps with gamma^(t) = gamma(t) exp(eps).
template <class G>
typename G::AdMatrix pose_covariance(const FitCovariance<G>& c, typename G::Scalar t) {
  using std::isfinite;
  const typename G::Scalar s = c.geodesic.normalized(t);
  if (!isfinite(s)) return unbounded_covariance<typename G::AdMatrix>();
  const EndpointMap<G> spread = pose_map<G>(c.geodesic.displacement(), s).lazyProduct(c.factor);
  return bounded_or_unbounded<typename G::AdMatrix>(spread.lazyProduct(spread.transpose()));
}

// Covariance of the prediction error of a new observation at t.
template <class G>
typename G::AdMatrix prediction_covariance(const FitCovariance<G>& c, typename G::Scalar t) {
  return bounded_or_unbounded<typename G::AdMatrix>(pose_covariance(c, t) + c.residual);
}

// Square roots of the diagonal; +infinity where a variance is NaN or
// +infinity (undefined or unbounded), 0 where it is negative (rounding).
template <class Matrix>
Eigen::Matrix<typename Matrix::Scalar, Matrix::RowsAtCompileTime, 1> standard_errors(
    const Matrix& c) {
  using Scalar = typename Matrix::Scalar;
  using std::isnan;
  using std::sqrt;
  Eigen::Matrix<Scalar, Matrix::RowsAtCompileTime, 1> errors(c.rows());
  for (Eigen::Index k = 0; k < c.rows(); ++k) {
    const Scalar variance = c(k, k);
    errors[k] = isnan(variance) ? std::numeric_limits<Scalar>::infinity()
                                : sqrt(variance > 0 ? variance : Scalar(0));
  }
  return errors;
}

// Rank of a covariance on its numerical range (kRangeTolerance).
template <class Matrix>
int covariance_rank(const Matrix& c) {
  return ScatterRange<typename Matrix::Scalar, Matrix::RowsAtCompileTime>(c).rank();
}

// v^T C^+ v, C^+ the pseudo-inverse on C's numerical range; +infinity
// when v or C has an entry that is not finite (outside the domain).
template <class Matrix, class Vector>
typename Matrix::Scalar mahalanobis_squared(const Matrix& c, const Vector& v) {
  using Scalar = typename Matrix::Scalar;
  if (!c.allFinite() || !v.allFinite()) return std::numeric_limits<Scalar>::infinity();
  const auto eigen = symmetric_eigen(c);
  const auto& values = eigen.values;
  const Scalar largest = values[values.size() - 1];
  const auto coordinates = (eigen.vectors.transpose() * v).eval();
  Scalar sum = 0;
  for (int k = 0; k < values.size(); ++k) {
    if (largest > 0 && values[k] > Scalar(kRangeTolerance) * largest) {
      sum += coordinates[k] * coordinates[k] / values[k];
    }
  }
  return sum;
}

// The squared radius of the confidence ellipsoid at `level` for `vectors`
// (1: one d-vector; 2: both endpoints) of dimension `dimension` each, with
// nu degrees of freedom; nullopt where the quantile is undefined (too few
// degrees of freedom).
inline std::optional<double> ellipsoid_quantile(double level, int dimension, int vectors, double nu,
                                                QuantileRule rule = QuantileRule::small_sample) {
  if (rule == QuantileRule::chi_square) {
    return chi_square_quantile(level, static_cast<double>(dimension * vectors));
  }
  return lawley_hotelling_quantile(level, dimension, vectors, nu);
}

// The squared radius of the `level` confidence ellipsoid of the endpoints
// (covariance c.endpoints), of the velocity (velocity_covariance), of the
// pose at a covariate (pose_covariance) and of a new observation
// (prediction_covariance); nullopt where too few degrees of freedom remain.
template <class G>
std::optional<double> endpoint_quantile(const FitCovariance<G>& c, double level,
                                        QuantileRule rule = QuantileRule::small_sample) {
  const int rank = covariance_rank(c.endpoints);
  if (rule == QuantileRule::chi_square) return chi_square_quantile(level, rank);
  if (c.flavour == CovarianceFlavour::robust) {
    return hotelling_quantile(level, rank, static_cast<double>(c.effective.endpoints));
  }
  // The Lawley-Hotelling trace of two d-vectors sharing S, in S's rank.
  return lawley_hotelling_quantile(level, covariance_rank(c.residual), 2,
                                   static_cast<double>(c.degrees_of_freedom));
}

template <class G>
std::optional<double> velocity_quantile(const FitCovariance<G>& c, double level,
                                        QuantileRule rule = QuantileRule::small_sample) {
  const int rank = covariance_rank(velocity_covariance(c));
  if (rule == QuantileRule::chi_square) return chi_square_quantile(level, rank);
  return hotelling_quantile(level, rank, static_cast<double>(c.effective.velocity));
}

template <class G>
std::optional<double> pose_quantile(const FitCovariance<G>& c, double level,
                                    QuantileRule rule = QuantileRule::small_sample) {
  const int rank = covariance_rank(c.residual);
  if (rule == QuantileRule::chi_square) return chi_square_quantile(level, rank);
  using std::min;
  return hotelling_quantile(level, rank,
                            static_cast<double>(min(c.effective.start, c.effective.end)));
}

// A new observation's prediction error, e - eps(s), is dominated by S,
// which both flavours estimate with nu degrees of freedom.
template <class G>
std::optional<double> prediction_quantile(const FitCovariance<G>& c, double level,
                                          QuantileRule rule = QuantileRule::small_sample) {
  const int rank = covariance_rank(c.residual);
  if (rule == QuantileRule::chi_square) return chi_square_quantile(level, rank);
  return hotelling_quantile(level, rank, static_cast<double>(c.degrees_of_freedom));
}

// Half-widths of a confidence ellipsoid with covariance c and squared
// radius q along each coordinate (its projections: simultaneous intervals);
// +infinity for a q that is negative or NaN (no quantile: unbounded) and
// wherever the radius or the variance is unbounded.
template <class Matrix>
Eigen::Matrix<typename Matrix::Scalar, Matrix::RowsAtCompileTime, 1> half_widths(
    const Matrix& c, typename Matrix::Scalar q) {
  using Scalar = typename Matrix::Scalar;
  using std::sqrt;
  if (!(q >= 0)) {
    return Eigen::Matrix<Scalar, Matrix::RowsAtCompileTime, 1>::Constant(
        c.rows(), std::numeric_limits<Scalar>::infinity());
  }
  constexpr Scalar kUnbounded = std::numeric_limits<Scalar>::infinity();
  const auto errors = standard_errors(c);
  Eigen::Matrix<Scalar, Matrix::RowsAtCompileTime, 1> widths(c.rows());
  for (Eigen::Index k = 0; k < c.rows(); ++k) {
    // An unbounded radius or variance is unbounded, even against a zero.
    widths[k] = (q == kUnbounded || errors[k] == kUnbounded) ? kUnbounded : sqrt(q) * errors[k];
  }
  return widths;
}

}  // namespace bireg

// The compiled part's instantiations of the covariances and quantiles derived from a FitCovariance
// (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/statistics/precompiled/confidence.hpp"
#endif
