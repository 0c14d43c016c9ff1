// bireg: the covariance of a spline fit (spline_regression.hpp) by the
// sandwich, and what it implies at any covariate: the covariance of the
// fitted pose, of the body velocity and of a new observation
// (docs/splines.md §10, the geodesic's statistics/inference/covariance.hpp
// and confidence.hpp for a curve with M control points).
//
// With the estimate P^_c = P*_c exp(delta_c) (left-trivialised),
//
//   Cov(delta) = K^{-1} M K^{-T},   M = sum_i w_i^2 Wt_i S Wt_i^T           (splines.md (10))
//
// K the Gauss-Newton matrix of the fit (§9) at the estimate, Wt_i the stack
// of the weights W_c(t_i) = B_c^2 D_c^{-1} of the k + 1 control points of
// t_i's segment, and S = sum_i w_i r_i r_i^T / nu the homoscedastic noise
// covariance with
//
//   nu = W - tr(H^{-1} H_2),  H = B^T W B,  H_2 = B^T W^2 B     (N - M for unit weights),
//
// unbiased on R^n, where Cov(delta) is exactly H^{-1} H_2 H^{-1} kron S
// (H^{-1} kron S for unit weights: ordinary least squares). Weights are
// design weights, as for the geodesic; the robust (HC2) flavour is not
// offered for splines.
//
// Pointwise, to first order in delta: the pose T^(t) = T(t) exp(eps) with
// eps = sum_j D_{i+j}(t) delta_{i+j} (splines.md (4)), the body velocity
// omega^(t) = omega(t) + sum_j V_{i+j}(t) delta_{i+j} ((11)); their
// covariances need only the band |c - l| <= k of Cov(delta), which is what
// is kept. K^{-1} is dense, though: the band is computed as
// Z = K^{-1} M (Md banded solves) and C = K^{-1} Z^T (C is symmetric),
// O(M^2 k d^3) time and O((Md)^2) memory, refused above
// kSplineCovarianceMaxDimension coordinates.
//
// Under left translation of the data everything here is unchanged; under
// right translation by g, delta_c and the residuals move by Ad_{g^{-1}}
// (splines.md §6), so every covariance is conjugated by Ad_{g^{-1}}.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/concept.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/spline/banded.hpp"
#include "bireg/regression/spline/differentials.hpp"
#include "bireg/spline.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"

namespace bireg {

// The most control-point coordinates (M d) whose covariance is computed:
// Z = K^{-1} M is held dense (128 MiB in double at this size).
inline constexpr std::size_t kSplineCovarianceMaxDimension = 4096;

template <class G>
struct SplineCovariance {
  using Scalar = typename G::Scalar;
  using AdMatrix = typename G::AdMatrix;

  CovarianceStatus status = CovarianceStatus::invalid_input;
  std::string message;
  // Cov(delta_c, delta_l) for |c - l| <= degree (the band of (10)), at
  // band_index(c, l); zero unless defined.
  std::vector<AdMatrix> band;
  // S = sum w r r^T / nu: the noise covariance.
  AdMatrix residual = AdMatrix::Zero();
  Scalar degrees_of_freedom = 0;  // nu, of S
  Spline<G> spline;               // the fit's

  bool defined() const { return status == CovarianceStatus::defined; }

  std::size_t band_index(std::size_t c, std::size_t l) const {
    const auto k = static_cast<std::size_t>(spline.degree());
    return c * (2 * k + 1) + (l + k - c);
  }
  // Cov(delta_c, delta_l); precondition |c - l| <= degree, defined().
  const AdMatrix& block(std::size_t c, std::size_t l) const { return band[band_index(c, l)]; }
};

namespace spline_covariance_detail {

template <class G>
SplineCovariance<G> refused(CovarianceStatus status, std::string message) {
  SplineCovariance<G> c;
  c.status = status;
  c.message = std::move(message);
  return c;
}

// sum_{j,l} A_j Cov(delta_{i+j}, delta_{i+l}) A_l^T over t's control points.
template <class G>
typename G::AdMatrix segment_covariance(
    const SplineCovariance<G>& c, std::size_t segment,
    const std::array<typename G::AdMatrix, kMaxSplineDegree + 1>& maps) {
  using AdMatrix = typename G::AdMatrix;
  const int k = c.spline.degree();
  AdMatrix sum = AdMatrix::Zero();
  for (int j = 0; j <= k; ++j) {
    for (int l = 0; l <= k; ++l) {
      sum.noalias() += maps[std::size_t(j)] *
                       c.block(segment + std::size_t(j), segment + std::size_t(l)) *
                       maps[std::size_t(l)].transpose();
    }
  }
  return (sum + sum.transpose()) / 2;
}

}  // namespace spline_covariance_detail

// The sandwich covariance of a spline fit's control points (splines.md
// (10)), from the data it was fitted to (the same observations,
// covariates and weights). Refused (invalid_input) when the fit failed or
// the data do not match it, undefined (with the reason) when no degrees of
// freedom remain, the residuals vanish, K is singular, or the control
// points have more than kSplineCovarianceMaxDimension coordinates, or the
// fit has a roughness penalty (not built).
template <class G, class Observations, class Covariates>
SplineCovariance<G> spline_covariance(const SplineResult<G>& fit, const Observations& observations,
                                      const Covariates& covariates,
                                      const std::vector<typename G::Scalar>& weights = {}) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Scalar1 = Eigen::Matrix<Scalar, 1, 1>;
  using spline_covariance_detail::refused;
  constexpr int d = G::dof;
  if (!fit.ok() || !fit.spline) {
    return refused<G>(CovarianceStatus::invalid_input, "the fit did not succeed (" +
                                                           std::string(to_string(fit.status)) +
                                                           "): its covariance is undefined");
  }
  if (fit.roughness_penalty > 0) {
    return refused<G>(CovarianceStatus::undefined,
                      "the covariance of a spline fitted with a roughness penalty is not "
                      "computed: the sandwich would need the penalty's bias and its share of K "
                      "(docs/splines.md §12)");
  }
  const Spline<G>& spline = *fit.spline;
  const std::size_t n = observations.size();
  if (covariates.size() != n) {
    return refused<G>(CovarianceStatus::invalid_input,
                      "observations and covariates differ in length (" + std::to_string(n) +
                          " vs " + std::to_string(covariates.size()) + ")");
  }
  // The covariates' and weights' checks, and the weights normalised.
  Problem<Scalar> problem;
  if (auto rejection = make_problem(covariates, weights, std::nullopt, problem)) {
    return refused<G>(CovarianceStatus::invalid_input, rejection->message);
  }
  const auto k = static_cast<std::size_t>(spline.degree());
  const std::size_t m = spline.control_points().size();
  const std::size_t band = 2 * k + 1;
  if (m * std::size_t(d) > kSplineCovarianceMaxDimension) {
    return refused<G>(CovarianceStatus::undefined,
                      "the covariance of " + std::to_string(m) + " control points (" +
                          std::to_string(m * std::size_t(d)) + " coordinates) is not computed: " +
                          "more than " + std::to_string(kSplineCovarianceMaxDimension) +
                          " (K^{-1} is dense); use a wider knot spacing");
  }
  if (auto why = range_outside(CovariateScalar<Scalar>(spline.knot_spacing()),
                               covariance_range_limit<Scalar>(),
                               ", where the velocity's covariance (~1/h^2) is representable")) {
    return refused<G>(CovarianceStatus::undefined, "the knot spacing " + *why);
  }

  // Pass 1: residuals, H and H_2 (banded scalars), W.
  std::vector<Tangent> residuals(n);
  BlockBandedMatrix<Scalar1, Scalar1> h(m, k);
  std::vector<Scalar> h2(m * band, Scalar(0));
  SegmentAt<G> segment;
  for (std::size_t i = 0; i < n; ++i) {
    const Scalar t = static_cast<Scalar>(covariates[i]);
    const KnotPosition<Scalar> at = spline.position(t);
    const SplineBasis<Scalar> basis = spline_basis(int(k), at.u);
    evaluate_segment<G>(int(k), &spline.increments()[at.segment], basis, segment.product);
    const typename G::Element curve =
        G::compose(spline.control_points()[at.segment], segment.product.suffix[0]);
    residuals[i] = G::log(G::compose(G::inverse(curve), observations[i]));
    if (!residuals[i].allFinite()) {
      return refused<G>(CovarianceStatus::invalid_input,
                        "observation " + std::to_string(i) +
                            "'s residual from the fitted curve is not finite (not the data the "
                            "fit was given?)");
    }
    const Scalar w = problem.w[i];
    for (std::size_t j = 0; j <= k; ++j) {
      for (std::size_t l = 0; l <= k; ++l) {
        const Scalar product = basis.ordinary[j] * basis.ordinary[l];
        h(at.segment + j, at.segment + l)(0, 0) += w * product;
        h2[(at.segment + j) * band + (l + k - j)] += w * w * product;
      }
    }
  }
  // nu = W - tr(H^{-1} H_2), column by column of H_2.
  if (!h.factorize()) {
    return refused<G>(CovarianceStatus::undefined,
                      "the B-spline design (H = B^T W B) is singular: the data do not determine "
                      "the control points");
  }
  Scalar trace = 0;
  std::vector<Scalar1> column(m);
  for (std::size_t l = 0; l < m; ++l) {
    std::fill(column.begin(), column.end(), Scalar1::Zero());
    for (std::size_t c = (l > k ? l - k : 0); c <= std::min(m - 1, l + k); ++c)
      column[c](0, 0) = h2[c * band + (l + k - c)];
    if (!h.substitute(column)) {
      return refused<G>(CovarianceStatus::undefined, "the B-spline design is singular");
    }
    trace += column[l](0, 0);
  }
  const Scalar nu = problem.weight_sum - trace;
  if (!(nu > Scalar(1e-9) * problem.weight_sum)) {
    return refused<G>(CovarianceStatus::undefined,
                      "no degrees of freedom left for the noise (N = " + std::to_string(n) +
                          ", effective N - M = " + std::to_string(double(nu)) + ", M = " +
                          std::to_string(m) + " control points): the covariance is undefined");
  }
  AdMatrix scatter = AdMatrix::Zero();
  for (std::size_t i = 0; i < n; ++i)
    scatter.noalias() += problem.w[i] * residuals[i] * residuals[i].transpose();
  const AdMatrix s = scatter / nu;
  const Scalar rounding = Scalar(1000) * std::numeric_limits<Scalar>::epsilon();
  Scalar size = 1;
  for (const Tangent& increment : spline.increments())
    size = std::max(size, increment.squaredNorm());
  if (!s.allFinite() || !(s.trace() > rounding * rounding * size)) {
    return refused<G>(CovarianceStatus::undefined,
                      "the residuals vanish (noise-free data): the noise covariance, and with "
                      "it the fit's covariance, is undefined");
  }

  // Pass 2: K (splines.md §9) and the meat of (10), both banded.
  BlockBandedMatrix<AdMatrix, Tangent> jacobian(m, k);
  std::vector<AdMatrix> meat(m * band, AdMatrix::Zero());
  ControlPointDifferentials<G> differentials;
  for (std::size_t i = 0; i < n; ++i) {
    const Scalar w = problem.w[i];
    if (!(w > 0)) continue;
    segment_at(spline, static_cast<Scalar>(covariates[i]), segment);
    control_point_differentials<G>(int(k), segment.basis, segment.product, segment.jacobians.data(),
                                   differentials);
    const AdMatrix left_inverse = right_jacobian_inverse<G>((-residuals[i]).eval());
    const std::size_t first = segment.at.segment;
    for (std::size_t j = 0; j <= k; ++j) {
      const AdMatrix weighted = w * differentials.weight[j];
      const AdMatrix spread = weighted * s;
      for (std::size_t l = 0; l <= k; ++l) {
        jacobian(first + j, first + l).noalias() -=
            weighted * left_inverse * differentials.derivative[l];
        meat[(first + j) * band + (l + k - j)].noalias() +=
            spread * (w * differentials.weight[l]).transpose();
      }
    }
  }
  if (!jacobian.factorize()) {
    return refused<G>(CovarianceStatus::undefined,
                      "the Gauss-Newton matrix K is singular at the fit: the covariance is "
                      "undefined");
  }

  // Z = K^{-1} M by columns, then C = K^{-1} Z^T keeping C's band.
  const std::size_t dimension = m * std::size_t(d);
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> z(dimension, dimension);
  std::vector<Tangent> rhs(m);
  for (std::size_t l = 0; l < m; ++l) {
    for (int e = 0; e < d; ++e) {
      std::fill(rhs.begin(), rhs.end(), Tangent::Zero());
      for (std::size_t c = (l > k ? l - k : 0); c <= std::min(m - 1, l + k); ++c)
        rhs[c] = meat[c * band + (l + k - c)].col(e);
      if (!jacobian.substitute(rhs)) {
        return refused<G>(CovarianceStatus::undefined, "K^{-1} M is not finite");
      }
      for (std::size_t c = 0; c < m; ++c)
        z.col(Eigen::Index(l * d + std::size_t(e))).segment(Eigen::Index(c * d), d) = rhs[c];
    }
  }
  SplineCovariance<G> result;
  result.spline = spline;
  result.band.assign(m * band, AdMatrix::Zero());
  for (std::size_t l = 0; l < m; ++l) {
    for (int e = 0; e < d; ++e) {
      const auto row = z.row(Eigen::Index(l * d + std::size_t(e)));
      for (std::size_t c = 0; c < m; ++c)
        rhs[c] = row.segment(Eigen::Index(c * d), d).transpose();
      if (!jacobian.substitute(rhs)) {
        return refused<G>(CovarianceStatus::undefined, "the covariance is not finite");
      }
      for (std::size_t c = (l > k ? l - k : 0); c <= std::min(m - 1, l + k); ++c)
        result.band[result.band_index(c, l)].col(e) = rhs[c];
    }
  }
  // Symmetric by construction, to rounding: made exactly so.
  for (std::size_t c = 0; c < m; ++c) {
    for (std::size_t l = c; l <= std::min(m - 1, c + k); ++l) {
      const AdMatrix mean = (result.band[result.band_index(c, l)] +
                             result.band[result.band_index(l, c)].transpose()) /
                            2;
      result.band[result.band_index(c, l)] = mean;
      result.band[result.band_index(l, c)] = mean.transpose();
    }
  }
  result.residual = s;
  result.degrees_of_freedom = nu;
  result.status = CovarianceStatus::defined;
  return result;
}

namespace spline_covariance_detail {

// sum_{j,l} A_j Cov_{jl} A_l^T at t for the maps A_j that `maps_at(segment,
// maps)` writes; unbounded for a t that is not finite or an undefined
// covariance.
template <class G, class MapsAt>
typename G::AdMatrix pointwise_covariance(const SplineCovariance<G>& c, typename G::Scalar t,
                                          const MapsAt& maps_at) {
  using AdMatrix = typename G::AdMatrix;
  using std::isfinite;
  if (!c.defined() || !isfinite(t)) return unbounded_covariance<AdMatrix>();
  SegmentAt<G> segment;
  segment_at(c.spline, t, segment);
  std::array<AdMatrix, kMaxSplineDegree + 1> maps;
  maps_at(segment, maps);
  return bounded_or_unbounded<AdMatrix>(segment_covariance(c, segment.at.segment, maps));
}

}  // namespace spline_covariance_detail

// Covariance of the fitted pose at covariate t (user units), as the
// left-trivialised eps with T^(t) = T(t) exp(eps), through D_c (splines.md
// (4)); unbounded for a t that is not finite or an undefined covariance.
// t outside the knots is the nearer end's, as the curve's value is.
template <class G>
typename G::AdMatrix pose_covariance(const SplineCovariance<G>& c, typename G::Scalar t) {
  return spline_covariance_detail::pointwise_covariance(c, t, [&](const auto& segment, auto& maps) {
    ControlPointDifferentials<G> differentials;
    control_point_differentials<G>(c.spline.degree(), segment.basis, segment.product,
                                   segment.jacobians.data(), differentials);
    maps = differentials.derivative;
  });
}

// Covariance of the body velocity at t, per covariate unit squared,
// through V_c (splines.md (11)).
template <class G>
typename G::AdMatrix velocity_covariance(const SplineCovariance<G>& c, typename G::Scalar t) {
  return spline_covariance_detail::pointwise_covariance(c, t, [&](const auto& segment, auto& maps) {
    velocity_differentials<G>(c.spline.degree(), c.spline.knot_spacing(), segment.basis,
                              segment.product, segment.jacobians.data(), maps);
  });
}

// Covariance of a new observation's prediction error at t: the pose's plus S.
template <class G>
typename G::AdMatrix prediction_covariance(const SplineCovariance<G>& c, typename G::Scalar t) {
  return bounded_or_unbounded<typename G::AdMatrix>(pose_covariance(c, t) + c.residual);
}

// The squared radius of the pointwise `level` ellipsoid of the pose, the
// velocity or a prediction (Hotelling's T^2 in S's rank with nu degrees of
// freedom, exact on R^n with Gaussian noise); nullopt where undefined.
template <class G>
std::optional<double> pointwise_quantile(const SplineCovariance<G>& c, double level,
                                         QuantileRule rule = QuantileRule::small_sample) {
  if (!c.defined()) return std::nullopt;
  const int rank = covariance_rank(c.residual);
  if (rule == QuantileRule::chi_square) return chi_square_quantile(level, rank);
  return hotelling_quantile(level, rank, static_cast<double>(c.degrees_of_freedom));
}

}  // namespace bireg
