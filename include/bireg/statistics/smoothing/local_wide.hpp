// bireg: the local geodesic on a window that turns by more than pi
// (statistics/smoothing/local_geodesic.hpp, LocalRegressionOptions::wide_windows;
// DESIGN.md section 5, "Wide windows").
//
// Why. A local fit is the bi-invariant geodesic regression of its window
// (the paper's Definition 2.1), whose iteration carries the geodesic by its
// endpoints g0, g1 and X = log(g0^{-1} g1): the principal log bounds the
// turn over the window below pi. On a spin of 20 rad/s sampled at 25 Hz
// (0.8 rad between samples) the window then holds three samples whatever
// the bandwidth, and the velocity's noise is that of three samples. The
// estimator itself does not need the bound: the net force
//
//   v0 = sum_i w_i psi_{1-t_i}(-A) r_i,   v1 = sum_i w_i psi_{t_i}(A) r_i,
//   psi_s(A) = s J_r(X) J_r(sX)^{-1}      (DESIGN.md section 2, exact form)
//
// with r_i = log(exp(-t_i X) g0^{-1} f_i) is analytic in X while the
// spectral radius of ad_X stays below 2 pi. So carry the geodesic by (g0,
// X) instead, X any vector of that domain, and the window may turn by up
// to 2 pi minus what the noise needs. The zero of v is the same estimator;
// only its coordinates changed: on a window that turns by less than pi,
// wide_fit() and fit() agree to the tolerance (tests/test_local_wide.cpp).
//
// The step. The equivariant Gauss-Newton step of DESIGN.md section 2,
// (d0, d1) = K^{-1} (v0, v1), perturbs g0 -> g0 exp(d0) and the end
// g1 = g0 exp(X) -> g1 exp(d1), with the blocks of K in the exact form
//
//   psi_{1-t}(-A) phi_t(A)^{-1}  = (1-t) t J_r(-X) J_r(-(1-t)X)^{-1} J_r(tX) J_r(X)^{-1},
//   psi_t(A) phi_{1-t}(-A)^{-1}  = t (1-t) J_r(X) J_r(tX)^{-1} J_r(-(1-t)X) J_r(-X)^{-1}.
//
// The new X solves exp(X') = exp(-d0) exp(X) exp(d1). Its first-order
// solution X'' = X + J_r(X)^{-1} d1 - J_r(-X)^{-1} d0 (exp(X + e) =
// exp(X) exp(J_r(X) e) and, on the left, exp(J_r(-X) e) exp(X)) is
// corrected once by X' = X'' + J_r(X'')^{-1} log(exp(-X'') exp(-d0)
// exp(X) exp(d1)), whose log is of a small element: no principal log of
// anything that turns far. Every piece maps by Ad under right translation
// and is unchanged by left translation, so the step and the fit keep the
// paper's Theorem 2.4 equivariance.
//
// Standard errors. The sandwich of statistics/inference/covariance.hpp (homoscedastic
// flavour) in the same coordinates: Cov(d0, d1) = K^{-1} M K^{-T},
// M = sum_i w_i^2 Psi_i S Psi_i^T, Psi_i = [psi_{1-t_i}(-A); psi_{t_i}(A)],
// S = sum_i w_i r_i r_i^T / nu, nu = W - tr(H^{-1} H_2); the velocity's
// change is dX = J_r(X)^{-1} d1 - J_r(-X)^{-1} d0 per covariate range.
//
// Cost: O(window) d x d Jacobian pairs per iteration, a few iterations
// from the narrow fit's geodesic; allocation free.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/concept.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/statistics/smoothing/local_window.hpp"

namespace bireg {

// The wide fit's geodesic gamma(t) = g0 exp(((t - t_first) / (t_last -
// t_first)) X) over its window [t_first, t_last], and how the fit ended.
template <class G>
struct WideFit {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;

  bool converged = false;
  int iterations = 0;
  Element start = G::identity();           // g0 = gamma(t_first)
  Tangent displacement = Tangent::Zero();  // X, over the window
  Scalar t_first = 0;
  Scalar t_last = 1;
  Tangent velocity_error = Tangent::Zero();  // standard errors, per covariate unit
  bool velocity_error_defined = false;

  Element operator()(Scalar t) const {
    return G::compose(start, G::exp(((t - t_first) / (t_last - t_first)) * displacement));
  }
  Tangent body_velocity() const { return displacement / (t_last - t_first); }
};

namespace wide_detail {

// The largest spectral radius of ad_X at which the wide fit still steps:
// psi and J_r^{-1}(X) are singular at 2 pi, and K's conditioning goes with
// them; 0.9 of it leaves the noise room past the window's 5 rad.
template <class Scalar>
constexpr Scalar kMaxRadius = Scalar(0.9) * Scalar(2) * Scalar(3.14159265358979323846);

// J_r(x) and J_r(x)^{-1}, accurate at every angle the wide fit reaches
// (spectral radius up to 0.9 of 2 pi). G's closed forms where it has the
// inverse's (SO(3), SE(3)); elsewhere J_r's own series, which is entire,
// inverted by LU: the Bernoulli series of the inverse (capabilities.hpp's
// fallback) is accurate on the narrow fits' turns below pi but not here
// (on SE(2), |J_r J_r^{-1} - I| = 0.3 at 5 rad, 1e4 at 5.65; found in
// review, tests/test_local_wide.cpp checks SE(2) past 5 rad).
template <class G>
RightJacobianPair<typename G::AdMatrix> jacobian_pair(const typename G::Tangent& x) {
  if constexpr (provides_v<G, capability_detail::right_jacobian_inverse>) {
    return right_jacobian_pair<G>(x);
  } else {
    const typename G::AdMatrix jacobian = right_jacobian<G>(x);
    return {jacobian, SmallLU<typename G::AdMatrix>(jacobian).inverse()};
  }
}

// v, K and, when `sandwich`, M's pieces for the geodesic (g0, X) on the
// window, t_i normalised onto [0, 1].
template <class G>
struct Force {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  static constexpr int d = G::dof;
  using Vector = Eigen::Matrix<Scalar, 2 * d, 1>;
  using Matrix = Eigen::Matrix<Scalar, 2 * d, 2 * d>;
  Vector v = Vector::Zero();
  Matrix k = Matrix::Zero();
  Matrix psi_scatter = Matrix::Zero();           // sum_i w_i^2 Psi_i S Psi_i^T once S is known
  AdMatrix residual_scatter = AdMatrix::Zero();  // sum_i w_i r_i r_i^T
  Scalar weight_sum = 0;
  Eigen::Matrix<Scalar, 2, 2> h = Eigen::Matrix<Scalar, 2, 2>::Zero();   // sum w l l^T
  Eigen::Matrix<Scalar, 2, 2> h2 = Eigen::Matrix<Scalar, 2, 2>::Zero();  // sum w^2 l l^T
  bool finite = true;
};

template <class G>
Force<G> force(const LocalWindow<G>& window, const typename G::Element& g0,
               const typename G::Tangent& x, typename G::Scalar t_first, typename G::Scalar t_last,
               const typename G::AdMatrix* noise) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  constexpr int d = G::dof;
  Force<G> out;
  const RightJacobianPair<AdMatrix> forward = jacobian_pair<G>(x);    // J_r(X), J_r(X)^{-1}
  const RightJacobianPair<AdMatrix> backward = jacobian_pair<G>(-x);  // J_r(-X), inverse
  const typename G::Element g0_inverse = G::inverse(g0);
  AdMatrix k01_sum = AdMatrix::Zero(), k10_sum = AdMatrix::Zero();
  Tangent v0 = Tangent::Zero(), v1 = Tangent::Zero();
  Scalar a = 0, c = 0;
  for (std::size_t i = 0; i < window.covariates.size(); ++i) {
    const Scalar w = window.weights[i];
    const Scalar t = (window.covariates[i] - t_first) / (t_last - t_first);
    const Scalar s = 1 - t;
    const Tangent r =
        G::log(G::compose(G::exp(-t * x), G::compose(g0_inverse, window.observations[i])));
    const RightJacobianPair<AdMatrix> near = jacobian_pair<G>(t * x);  // J_r(tX)
    const RightJacobianPair<AdMatrix> far = jacobian_pair<G>(-s * x);  // J_r(-(1-t)X)
    v0.noalias() += (w * s) * (far.inverse * r);
    v1.noalias() += (w * t) * (near.inverse * r);
    k01_sum.noalias() += (w * s * t) * (far.inverse * near.jacobian);
    k10_sum.noalias() += (w * t * s) * (near.inverse * far.jacobian);
    a += w * s * s;
    c += w * t * t;
    out.weight_sum += w;
    const Eigen::Matrix<Scalar, 2, 1> l(s, t);
    out.h.noalias() += w * l * l.transpose();
    out.h2.noalias() += (w * w) * l * l.transpose();
    out.residual_scatter.noalias() += w * r * r.transpose();
    if (noise) {
      Eigen::Matrix<Scalar, 2 * d, d> psi;
      psi.template topRows<d>() = s * (backward.jacobian * far.inverse);
      psi.template bottomRows<d>() = t * (forward.jacobian * near.inverse);
      out.psi_scatter.noalias() += (w * w) * psi * (*noise) * psi.transpose();
    }
  }
  out.v.template head<d>() = backward.jacobian * v0;
  out.v.template tail<d>() = forward.jacobian * v1;
  out.k.template topLeftCorner<d, d>() = a * AdMatrix::Identity();
  out.k.template bottomRightCorner<d, d>() = c * AdMatrix::Identity();
  out.k.template topRightCorner<d, d>() = backward.jacobian * k01_sum * forward.inverse;
  out.k.template bottomLeftCorner<d, d>() = forward.jacobian * k10_sum * backward.inverse;
  out.finite = out.v.allFinite() && out.k.allFinite() && out.residual_scatter.allFinite();
  return out;
}

}  // namespace wide_detail

// The bi-invariant geodesic regression of `window` (kernel weights as
// weights) carried by (g0, X), from the geodesic through `start_pose` at tau
// with body velocity `start_velocity` per covariate unit (the narrow fit's),
// stopping when both parts of the step are below `tolerance` (radians) or
// after `max_iterations`. converged is false when it ran out of iterations,
// when ad_X's spectral radius reached 0.9 of 2 pi (outside the domain), or
// when anything became non-finite; the caller then keeps the narrow fit.
// The velocity's standard errors are set when `standard_errors` and the
// residuals leave degrees of freedom and are not all zero.
template <class G>
WideFit<G> wide_fit(const LocalWindow<G>& window, typename G::Scalar tau,
                    const typename G::Element& start_pose,
                    const typename G::Tangent& start_velocity, typename G::Scalar tolerance,
                    int max_iterations, bool standard_errors) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  constexpr int d = G::dof;
  using Force = wide_detail::Force<G>;
  using std::sqrt;
  WideFit<G> fit;
  if (window.covariates.size() < 3) return fit;
  fit.t_first = window.covariates.front();
  fit.t_last = window.covariates.back();
  if (!(fit.t_last > fit.t_first)) return fit;
  const Scalar range = fit.t_last - fit.t_first;
  fit.start = G::compose(start_pose, G::exp((fit.t_first - tau) * start_velocity));
  fit.displacement = range * start_velocity;
  const auto inverse_jacobian = [](const Tangent& x) {
    return wide_detail::jacobian_pair<G>(x).inverse;
  };
  const auto inside = [](const Tangent& x) {
    return ad_spectral_radius<G>(x) < wide_detail::kMaxRadius<Scalar>;
  };
  if (!fit.start.allFinite() || !fit.displacement.allFinite() || !inside(fit.displacement)) {
    return fit;
  }
  for (fit.iterations = 1; fit.iterations <= max_iterations; ++fit.iterations) {
    const Force force = wide_detail::force<G>(window, fit.start, fit.displacement, fit.t_first,
                                              fit.t_last, nullptr);
    if (!force.finite) return fit;
    const SmallLU<typename Force::Matrix> lu(force.k);
    if (!lu.invertible()) return fit;
    const typename Force::Vector step = lu.solve(force.v);
    const Tangent d0 = step.template head<d>(), d1 = step.template tail<d>();
    // exp(X') = exp(-d0) exp(X) exp(d1): first order, then one correction.
    const Tangent x = fit.displacement;
    const Tangent first_order = x + inverse_jacobian(x) * d1 - inverse_jacobian(-x) * d0;
    const Tangent correction = G::log(G::compose(G::compose(G::exp(-first_order), G::exp(-d0)),
                                                 G::compose(G::exp(x), G::exp(d1))));
    fit.displacement = first_order + inverse_jacobian(first_order) * correction;
    fit.start = G::compose(fit.start, G::exp(d0));
    if (!fit.displacement.allFinite() || !fit.start.allFinite() || !inside(fit.displacement)) {
      return fit;
    }
    if (d0.norm() <= tolerance && d1.norm() <= tolerance) {
      fit.converged = true;
      break;
    }
  }
  fit.iterations = std::min(fit.iterations, max_iterations);
  if (!fit.converged || !standard_errors) return fit;

  // The homoscedastic sandwich (covariance.hpp's, in these coordinates).
  const Force plain =
      wide_detail::force<G>(window, fit.start, fit.displacement, fit.t_first, fit.t_last, nullptr);
  const Scalar nu = plain.weight_sum - (plain.h.inverse() * plain.h2).trace();
  if (!(nu > Scalar(1e-9) * plain.weight_sum)) return fit;
  const AdMatrix noise = plain.residual_scatter / nu;
  const Scalar rounding = Scalar(1000) * std::numeric_limits<Scalar>::epsilon();
  if (!(noise.trace() > rounding * rounding * (fit.displacement.squaredNorm() + 1))) return fit;
  const Force sandwich =
      wide_detail::force<G>(window, fit.start, fit.displacement, fit.t_first, fit.t_last, &noise);
  const typename Force::Matrix k_transpose = sandwich.k.transpose();
  const SmallLU<typename Force::Matrix> transposed(k_transpose);
  if (!transposed.invertible()) return fit;
  Eigen::Matrix<Scalar, d, 2 * d> to_velocity;
  to_velocity.template leftCols<d>() = -inverse_jacobian(-fit.displacement);
  to_velocity.template rightCols<d>() = inverse_jacobian(fit.displacement);
  // L K^{-1} M K^{-T} L^T = (K^{-T} L^T)^T M (K^{-T} L^T).
  const Eigen::Matrix<Scalar, 2 * d, d> spread =
      transposed.solve(Eigen::Matrix<Scalar, 2 * d, d>(to_velocity.transpose()));
  const AdMatrix velocity =
      spread.transpose().lazyProduct(sandwich.psi_scatter.lazyProduct(spread)) / (range * range);
  if (!velocity.allFinite()) return fit;
  fit.velocity_error = velocity.diagonal().cwiseMax(Scalar(0)).cwiseSqrt();
  fit.velocity_error_defined = true;
  return fit;
}

}  // namespace bireg
