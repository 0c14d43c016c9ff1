// bireg: the covariance of a fit's endpoints by the sandwich K^{-1} M K^{-T}
// (DESIGN.md section 5, "Covariance of the estimate").
//
// Write the estimate as g0^ = g0* exp(delta0), g1^ = g1* exp(delta1)
// (left-trivialised). Linearising the estimating equations v(g^) = 0 of the
// paper's Definition 2.1 about the truth gives delta ~ K^{-1} sum_i w_i
// Psi_i eps_i, eps_i the true residuals, K the Gauss-Newton matrix of
// DESIGN.md section 2 and
//
//   Psi_i = [psi_{1-t_i}(-A); psi_{t_i}(A)]   (2d x d, A = ad_X; Lemma 3.1,
//                                              Corollary 3.2 of the paper),
//
// hence Cov(delta) ~ K^{-1} M K^{-T} with
//
//   homoscedastic:  M = sum_i w_i^2 Psi_i S Psi_i^T,  S = sum_i w_i r_i r_i^T / nu,
//   robust (HC2):   M = sum_i w_i^2 Psi_i (r_i r_i^T / v_i) Psi_i^T.
//
// Weights are design weights (e.g. kernel weights of a local fit), not
// precisions: the homoscedastic flavour assumes one error covariance for
// every observation. On R^n, where r = (I - P) eps with P the weighted
// hat matrix, E[sum w_i r_i r_i^T] = Sigma (W - tr(H^{-1} H_2)), W = sum w_i,
// H = sum w_i l_i l_i^T (the paper's Lemma 3.7 matrix), H_2 = sum w_i^2 l_i
// l_i^T, l_i = (1 - t_i, t_i); so the unbiased divisor is
//
//   nu = W - tr(H^{-1} H_2)     (= N - 2 for unit weights: the textbook N - 2),
//
// and the robust flavour divides each r_i r_i^T by its own expectation
// factor v_i = 1 - 2 w_i l_i^T H^{-1} l_i + l_i^T H^{-1} H_2 H^{-1} l_i
// (= 1 - h_ii, MacKinnon and White's HC2, for unit weights), which makes
// it unbiased under homoscedasticity too. Both are invariant to a common
// scale of the weights (K and nu scale like w, M like w^2). On R^n with
// unit weights the homoscedastic covariance is exactly H^{-1} kron S, the
// OLS covariance of the line's values at the interval's ends. The robust
// flavour stays consistent when the noise level varies along t; for
// precision weights (noise covariance Sigma / w_i) use it too.
//
// Degrees of freedom for the confidence regions. The homoscedastic flavour
// estimates one d x d matrix S from nu degrees of freedom, and the
// ellipsoids use Hotelling / Lawley-Hotelling quantiles with nu
// (statistics/inference/confidence.hpp). The robust flavour estimates the whole
// covariance of a p-dimensional quantity L delta from N rank-one terms
// z_i z_i^T, z_i = L K^{-1} w_i Psi_i r_i / sqrt(v_i), far more variable
// than S: with the homoscedastic quantiles its 95% ellipsoids covered 84%
// (SE(3) endpoints, N = 50) in simulation. Its degrees of freedom come from
// Satterthwaite's moment match of a weighted sum of Wisharts: with kappa_i
// = z_i^T C_L^{-1} z_i (C_L = sum z z^T, so sum kappa_i = p) and E[kappa_i^2]
// inflated by (p + 2)/p for Gaussian z_i,
//
//   nu_L = p (p + 2) / sum_i kappa_i^2      (= N when all z_i are alike),
//
// computed from the data, so that it falls when a few observations
// dominate (high leverage, or noise that grows along t), and used as the
// error degrees of freedom of Hotelling's T^2 in dimension p (the
// sandwich has no Kronecker structure to exploit). It is computed for the
// endpoints together (p = 2d), each endpoint, and the velocity.
//
// Under left translation of the data every quantity here is unchanged;
// under right translation by h, delta, r_i, Psi_i and K move by Ad_{h^{-1}}
// (the paper's Theorem 2.4), so the covariance becomes (I2 kron Ad) C
// (I2 kron Ad)^T.
//
// K. The fit's K (RegressionResult::jacobian) is a power series of order
// kGaussNewtonOrder = 16 in A, accurate to ~(rho(A)/2 pi)^16 relative:
// 6e-14 at 1 rad but only ~2e-5 at pi, enough to steer Newton's steps and
// not quite what a covariance quoted to 4 digits should carry. Here K is
// built exactly, per observation, from the closed forms (or fallback
// series) of J_r: with psi_s(A) = s J_r(X) J_r(sX)^{-1} (DESIGN.md section
// 2, "Exact form") and phi_s = psi_s / s^2,
//
//   K01 = sum_i w_i psi_{1-t_i}(-A) phi_{t_i}(A)^{-1}
//       = J_r(-X) [sum_i w_i t_i u_i J_r(-u_i X)^{-1} J_r(t_i X)] J_r(X)^{-1},
//   K10 = J_r(X) [sum_i w_i t_i u_i J_r(t_i X)^{-1} J_r(-u_i X)] J_r(-X)^{-1},
//
// u_i = 1 - t_i, and Psi_i = diag(J_r(-X), J_r(X)) [u_i J_r(-u_i X)^{-1};
// t_i J_r(t_i X)^{-1}]: one pass, four d x d Jacobians per observation, the
// constant outer factors applied once. On SO(3) and SE(3) every one of
// these Jacobians is a function of A = ad_X, held as five numbers in the
// basis I, A, A^2, N1, N2 of math/ad_algebra.hpp: the sums of K's blocks
// are sums of coefficients, and the homoscedastic meat sum_i w_i^2 Psi_i S
// Psi_i^T is sum_{k,l} m_kl B_k S B_l^T with m_kl = sum_i of products of
// coefficients. The pass then costs scalar arithmetic per observation and
// d x d products only once; it is exact like the matrix form, to which a
// test compares it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/math/ad_algebra.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/result.hpp"

namespace bireg {

enum class CovarianceFlavour {
  homoscedastic,  // one residual covariance S for all observations
  robust,         // heteroscedasticity-robust sandwich (HC2)
};

inline const char* to_string(CovarianceFlavour flavour) {
  return flavour == CovarianceFlavour::robust ? "robust" : "homoscedastic";
}

// Whether `flavour` is one of the enumerators (an integer cast to it may not be).
constexpr bool is_valid(CovarianceFlavour flavour) {
  return flavour == CovarianceFlavour::homoscedastic || flavour == CovarianceFlavour::robust;
}

enum class CovarianceStatus {
  defined,
  invalid_input,  // the fit failed, the covariates/weights do not match it, or the flavour is
                  // unknown
  // no degrees of freedom, zero residuals, leverage 1, or (robust) a quantity
  // with zero covariance: the message says which
  undefined,
};

// Degrees of freedom of the quantities' covariance estimates.
template <class Scalar>
struct DegreesOfFreedom {
  Scalar endpoints = 0;  // (delta0, delta1) together
  Scalar start = 0;      // delta0
  Scalar end = 0;        // delta1
  Scalar velocity = 0;
};

template <class G>
struct FitCovariance {
  using Scalar = typename G::Scalar;
  static constexpr int d = G::dof;
  using AdMatrix = typename G::AdMatrix;
  using EndpointMatrix = Eigen::Matrix<Scalar, 2 * d, 2 * d>;

  CovarianceStatus status = CovarianceStatus::invalid_input;
  std::string message;
  CovarianceFlavour flavour = CovarianceFlavour::homoscedastic;
  // Cov of (delta0, delta1), left-trivialised at the endpoints (zero unless defined).
  EndpointMatrix endpoints = EndpointMatrix::Zero();
  // F with endpoints = F F^T: a linear map L of the endpoints has
  // covariance (L F)(L F)^T, positive semi-definite to rounding however
  // large L's entries (statistics/inference/confidence.hpp forms them so).
  EndpointMatrix factor = EndpointMatrix::Zero();
  // The exact K at the estimate (see above).
  EndpointMatrix jacobian = EndpointMatrix::Zero();
  // S = sum w r r^T / nu: the residual (noise) covariance, both flavours.
  AdMatrix residual = AdMatrix::Zero();
  Scalar degrees_of_freedom = 0;  // nu, of S
  // Of each quantity's covariance: nu for the homoscedastic flavour, the
  // Satterthwaite values above for the robust one.
  DegreesOfFreedom<Scalar> effective;
  Geodesic<G> geodesic;  // the fit's

  bool defined() const { return status == CovarianceStatus::defined; }
};

namespace covariance_detail {

template <class G>
FitCovariance<G> refused(CovarianceStatus status, std::string message) {
  FitCovariance<G> c;
  c.status = status;
  c.message = std::move(message);
  return c;
}

// A square root L of a symmetric positive semi-definite S (S = L L^T).
template <class Matrix>
Matrix square_root(const Matrix& s) {
  const auto eigen = symmetric_eigen(s);
  const auto root = eigen.values.cwiseMax(typename Matrix::Scalar(0)).cwiseSqrt();
  return eigen.vectors * root.asDiagonal();
}

// nu_L = p (p + 2) / sum kappa_i^2, kappa_i = z_i^T C^{-1} z_i, z_i = M
// force_i, C = sum z z^T = M (sum force force^T) M^T (on C's numerical
// range: p its rank), for the map M of a quantity: the first `rows` rows of
// `map` (2d x 2d whatever the quantity, the rows below zero, so that one
// instantiation serves the endpoints, the start, the end and the velocity).
// `meat_root` is R with R R^T = sum force force^T, so C costs no pass, and
// C = (M R)(M R)^T is positive semi-definite to rounding relative to its
// own largest eigenvalue, which its rank needs.
template <class Matrix, class Force>
typename Matrix::Scalar satterthwaite(const Matrix& map, int rows, const std::vector<Force>& forces,
                                      const Matrix& meat_root) {
  using Scalar = typename Matrix::Scalar;
  constexpr int n = Matrix::RowsAtCompileTime;
  // Products of 2d-sized matrices are lazy (coefficient-wise) throughout:
  // Eigen's blocked product kernels cost seconds of compile time per shape
  // and win nothing at these sizes.
  const Matrix spread = map.lazyProduct(meat_root);
  // C's eigen-decomposition on its rows x rows block, stored compactly
  // (column-major, leading dimension `rows`) for the Jacobi sweeps.
  Matrix c_work, vectors;
  Scalar* c = c_work.data();
  Scalar* v = vectors.data();
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < rows; ++i) {
      c[i + j * rows] = spread.row(i).dot(spread.row(j));
      v[i + j * rows] = i == j ? Scalar(1) : Scalar(0);
    }
  }
  symmetric_eigen_detail::diagonalize(c, v, rows);
  Scalar largest = 0;
  for (int k = 0; k < rows; ++k)
    largest = std::max(largest, c[k + k * rows]);
  // The whitening W = Lambda^{-1/2} V^T M on C's numerical range, its other
  // rows zero: kappa_i = |W force_i|^2.
  Matrix whitening = Matrix::Zero();
  int rank = 0;
  for (int k = 0; k < rows; ++k) {
    const Scalar value = c[k + k * rows];
    if (!(largest > 0 && value > Scalar(1e-10) * largest)) continue;
    const Scalar inverse_root = 1 / std::sqrt(value);
    for (int i = 0; i < rows; ++i)
      whitening.row(k) += (inverse_root * v[i + k * rows]) * map.row(i);
    ++rank;
  }
  static_assert(n == Force::RowsAtCompileTime, "forces are 2d-vectors");
  Scalar sum = 0;
  for (const Force& f : forces) {
    const Scalar kappa = whitening.lazyProduct(f).squaredNorm();
    sum += kappa * kappa;
  }
  return sum > 0 ? Scalar(rank * (rank + 2)) / sum : Scalar(0);
}

// The pass over the observations: K's off-diagonal cores, the meat of the
// core Psi_i = [u J_r(-uX)^{-1}; t J_r(tX)^{-1}] by d x d blocks (the start's,
// the cross term, the end's; the fourth is the cross term's transpose) and,
// for the robust flavour, each observation's core force w_i Psi_i r_i /
// sqrt(v_i).
template <class G>
struct ObservationSums {
  using AdMatrix = typename G::AdMatrix;
  using ForceVector = Eigen::Matrix<typename G::Scalar, 2 * G::dof, 1>;
  AdMatrix k01_core = AdMatrix::Zero(), k10_core = AdMatrix::Zero();
  AdMatrix meat_start = AdMatrix::Zero(), meat_cross = AdMatrix::Zero(),
           meat_end = AdMatrix::Zero();
  std::vector<ForceVector> forces;
  std::ptrdiff_t leverage_one = -1;  // robust: an observation of leverage 1
};

// What the pass needs besides the residuals: the leverages' matrices (the
// robust flavour's v_i) and S (the homoscedastic meat).
template <class G>
struct PassInputs {
  using Matrix2 = Eigen::Matrix<typename G::Scalar, 2, 2>;
  typename G::Tangent x;
  Matrix2 h_inverse, leverage_matrix;
  typename G::AdMatrix s;
  CovarianceFlavour flavour;
};

// v_i = 1 - 2 w l^T H^{-1} l + l^T H^{-1} H_2 H^{-1} l, l = (u, t).
template <class G>
typename G::Scalar hc2_factor(const PassInputs<G>& in, typename G::Scalar w, typename G::Scalar t) {
  const Eigen::Matrix<typename G::Scalar, 2, 1> l(1 - t, t);
  return 1 - 2 * w * l.dot(in.h_inverse * l) + l.dot(in.leverage_matrix * l);
}

// The robust flavour's force of one observation, from its Psi blocks
// applied to r; accumulated into the meat. False at leverage 1.
template <class G, class ApplyStart, class ApplyEnd>
bool add_robust_force(const PassInputs<G>& in, typename G::Scalar w, typename G::Scalar t,
                      const ApplyStart& start_inverse_times, const ApplyEnd& end_inverse_times,
                      ObservationSums<G>& sums) {
  using Scalar = typename G::Scalar;
  constexpr int d = G::dof;
  const Scalar v = hc2_factor(in, w, t);
  if (!(v > Scalar(1e-12))) return false;
  const Scalar force_weight = w / std::sqrt(v);
  typename ObservationSums<G>::ForceVector force;
  force.template head<d>() = (force_weight * (1 - t)) * start_inverse_times();
  force.template tail<d>() = (force_weight * t) * end_inverse_times();
  const auto head = force.template head<d>();
  const auto tail = force.template tail<d>();
  sums.meat_start.noalias() += head.lazyProduct(head.transpose());
  sums.meat_cross.noalias() += head.lazyProduct(tail.transpose());
  sums.meat_end.noalias() += tail.lazyProduct(tail.transpose());
  sums.forces.push_back(force);
  return true;
}

// The pass with d x d Jacobians per observation (every group).
template <class G>
ObservationSums<G> sums_by_matrices(const PassInputs<G>& in,
                                    const Problem<typename G::Scalar>& problem,
                                    const std::vector<typename G::Tangent>& residuals) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  ObservationSums<G> sums;
  if (in.flavour == CovarianceFlavour::robust) sums.forces.reserve(problem.size());
  // S = s_root s_root^T, so that each observation's meat is a Gram matrix.
  const AdMatrix s_root = in.flavour == CovarianceFlavour::homoscedastic
                              ? square_root(in.s)
                              : AdMatrix(AdMatrix::Zero());
  for (std::size_t i = 0; i < problem.size(); ++i) {
    const Scalar t = problem.t[i], u = 1 - t, w = problem.w[i];
    if (w == 0) continue;
    const RightJacobianPair<AdMatrix> start = right_jacobian_pair<G>(Tangent(-u * in.x));
    const RightJacobianPair<AdMatrix> end = right_jacobian_pair<G>(Tangent(t * in.x));
    // Small fixed-size products are written as lazy (coefficient-wise)
    // products: Eigen's blocked kernels cost more than the arithmetic here.
    const Scalar k_weight = w * t * u;
    sums.k01_core.noalias() += (k_weight * start.inverse).lazyProduct(end.jacobian);
    sums.k10_core.noalias() += (k_weight * end.inverse).lazyProduct(start.jacobian);
    if (in.flavour == CovarianceFlavour::homoscedastic) {
      // w Psi_i S Psi_i^T w, with S = s_root s_root^T.
      const AdMatrix start_spread = (w * u * start.inverse).lazyProduct(s_root);
      const AdMatrix end_spread = (w * t * end.inverse).lazyProduct(s_root);
      sums.meat_start.noalias() += start_spread.lazyProduct(start_spread.transpose());
      sums.meat_cross.noalias() += start_spread.lazyProduct(end_spread.transpose());
      sums.meat_end.noalias() += end_spread.lazyProduct(end_spread.transpose());
    } else if (!add_robust_force(
                   in, w, t, [&] { return Tangent(start.inverse.lazyProduct(residuals[i])); },
                   [&] { return Tangent(end.inverse.lazyProduct(residuals[i])); }, sums)) {
      sums.leverage_one = static_cast<std::ptrdiff_t>(i);
      return sums;
    }
  }
  return sums;
}

// The same pass in the algebra of functions of ad_X (math/ad_algebra.hpp;
// groups with ad_algebra_basis): per observation, the coefficients of
// J_r(-uX)^{-1} and J_r(tX)^{-1}, their inverses J_r (two 2 x 2 solves),
// and two products, all scalar. Psi's blocks have p = 0, so the
// homoscedastic meat needs the sums of coefficient products over the
// basis I, A, A^2, N2 only.
template <class G>
ObservationSums<G> sums_by_algebra(const PassInputs<G>& in,
                                   const Problem<typename G::Scalar>& problem,
                                   const std::vector<typename G::Tangent>& residuals) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Function = AdFunction<Scalar>;
  using Vector4 = Eigen::Matrix<Scalar, 4, 1>;
  using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
  const AdAlgebraBasis<AdMatrix> basis = G::ad_algebra_basis(in.x);
  const auto psi_coefficients = [](const Function& f, Scalar k) {
    return Vector4(k * f.a, k * f.b, k * f.c, k * f.q);
  };
  ObservationSums<G> sums;
  if (in.flavour == CovarianceFlavour::robust) sums.forces.reserve(problem.size());
  Function k01, k10;
  Matrix4 m_start = Matrix4::Zero(), m_cross = Matrix4::Zero(), m_end = Matrix4::Zero();
  for (std::size_t i = 0; i < problem.size(); ++i) {
    const Scalar t = problem.t[i], u = 1 - t, w = problem.w[i];
    if (w == 0) continue;
    const Function start_inverse = basis.right_jacobian_inverse(-u);
    const Function end_inverse = basis.right_jacobian_inverse(t);
    const Scalar k_weight = w * t * u;
    k01 += basis.product(start_inverse, basis.inverse(end_inverse)).scaled(k_weight);
    k10 += basis.product(end_inverse, basis.inverse(start_inverse)).scaled(k_weight);
    if (in.flavour == CovarianceFlavour::homoscedastic) {
      const Vector4 alpha = psi_coefficients(start_inverse, w * u);
      const Vector4 beta = psi_coefficients(end_inverse, w * t);
      m_start.noalias() += alpha.lazyProduct(alpha.transpose());
      m_cross.noalias() += alpha.lazyProduct(beta.transpose());
      m_end.noalias() += beta.lazyProduct(beta.transpose());
      continue;
    }
    const Tangent& r = residuals[i];
    const Tangent a_r = basis.a.lazyProduct(r), a2_r = basis.a2.lazyProduct(r),
                  n2_r = basis.n2.lazyProduct(r);
    const auto times = [&](const Function& f) {
      return Tangent(f.a * r + f.b * a_r + f.c * a2_r + f.q * n2_r);
    };
    if (!add_robust_force(
            in, w, t, [&] { return times(start_inverse); }, [&] { return times(end_inverse); },
            sums)) {
      sums.leverage_one = static_cast<std::ptrdiff_t>(i);
      return sums;
    }
  }
  sums.k01_core = basis.matrix(k01);
  sums.k10_core = basis.matrix(k10);
  if (in.flavour == CovarianceFlavour::homoscedastic) {
    // sum_{k,l} m_kl B_k S B_l^T = sum_k (B_k S) (sum_l m_kl B_l)^T.
    const AdMatrix b[4] = {AdMatrix::Identity(), basis.a, basis.a2, basis.n2};
    const auto meat = [&](const Matrix4& m) {
      AdMatrix sum = AdMatrix::Zero();
      for (int k = 0; k < 4; ++k) {
        const AdMatrix combined = m(k, 0) * b[0] + m(k, 1) * b[1] + m(k, 2) * b[2] + m(k, 3) * b[3];
        sum.noalias() += (b[k] * in.s) * combined.transpose();
      }
      return sum;
    };
    sums.meat_start = meat(m_start);
    sums.meat_cross = meat(m_cross);
    sums.meat_end = meat(m_end);
  }
  return sums;
}

}  // namespace covariance_detail

// The covariance of the endpoints of the geodesic fitted to a problem
// (regression/problem.hpp: the fit's covariates on its interval, and its
// weights), from the residuals at those endpoints in the problem's order.
// For callers that hold the problem already (the local regression, one
// fit per window): the homoscedastic flavour allocates nothing, except the
// message of a refusal. CovariancePass::matrices forces the pass with
// d x d matrices per observation where the group has the algebra of ad_X
// (for tests; the two agree to rounding). A template argument, not a run-time
// flag, so that a caller compiles only the pass it runs.
enum class CovariancePass { fastest, matrices };

template <class G, CovariancePass Pass = CovariancePass::fastest>
FitCovariance<G> covariance_of(const Geodesic<G>& geodesic,
                               const std::vector<typename G::Tangent>& residuals,
                               const Problem<typename G::Scalar>& problem,
                               CovarianceFlavour flavour = CovarianceFlavour::homoscedastic) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Result = FitCovariance<G>;
  using EndpointMatrix = typename Result::EndpointMatrix;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using Matrix2 = Eigen::Matrix<Scalar, 2, 2>;
  constexpr int d = G::dof;
  using covariance_detail::refused;
  using std::sqrt;
  const std::size_t n = problem.size();
  if (!is_valid(flavour)) {
    return refused<G>(CovarianceStatus::invalid_input,
                      "flavour must be homoscedastic or robust (got " +
                          std::to_string(static_cast<int>(flavour)) + ")");
  }
  if (residuals.size() != n) {
    return refused<G>(CovarianceStatus::invalid_input,
                      "the residuals are not the problem's (" + std::to_string(residuals.size()) +
                          " vs " + std::to_string(n) + " covariates)");
  }
  // The velocity's covariance is C / range^2 for C on the unit interval:
  // beyond covariance_range_limit (1e-146 .. 1e146 in double) it overflows
  // or underflows to a zero standard error, which would be a wrong number.
  if (auto why = range_outside(problem.t_max - problem.t_min, covariance_range_limit<Scalar>(),
                               ", where the velocity's covariance (~1/range^2) is representable")) {
    return refused<G>(CovarianceStatus::undefined, *why);
  }

  // nu = W - tr(H^{-1} H_2), and the matrix H^{-1} H_2 H^{-1} of the
  // leverages, from the normalised weights (scale-free).
  Matrix2 h, h2 = Matrix2::Zero();
  h << problem.a, problem.b, problem.b, problem.c;
  for (std::size_t i = 0; i < n; ++i) {
    const Vector2 l(1 - problem.t[i], problem.t[i]);
    h2.noalias() += problem.w[i] * problem.w[i] * l * l.transpose();
  }
  const Matrix2 h_inverse = h.inverse();
  const Scalar nu = problem.weight_sum - h_inverse.cwiseProduct(h2.transpose()).sum();
  // Below this nu is rounding noise (N = 2 gives exactly 0 in exact arithmetic).
  const Scalar nu_floor = Scalar(1e-9) * problem.weight_sum;
  if (!(nu > nu_floor)) {
    return refused<G>(CovarianceStatus::undefined,
                      "no degrees of freedom left for the noise (N = " + std::to_string(n) +
                          ", effective N - 2 = " + std::to_string(double(nu)) +
                          "): the covariance is undefined");
  }
  const Matrix2 leverage_matrix = h_inverse * h2 * h_inverse;

  AdMatrix residual_scatter = AdMatrix::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    residual_scatter.noalias() += problem.w[i] * residuals[i] * residuals[i].transpose();
  }
  const AdMatrix s = residual_scatter / nu;
  if (!s.allFinite()) {
    return refused<G>(CovarianceStatus::undefined, "the residuals are not finite");
  }
  // Zero residuals (noise-free data): residuals at the rounding level (rms
  // below 1000 epsilon relative to the geodesic's size) estimate the noise
  // as zero, which no confidence statement can be built on.
  const Scalar rounding = Scalar(1000) * std::numeric_limits<Scalar>::epsilon();
  const Scalar size = geodesic.displacement().squaredNorm() + 1;
  if (!(s.trace() > rounding * rounding * size)) {
    return refused<G>(CovarianceStatus::undefined,
                      "the residuals vanish (noise-free data): the noise covariance, and with "
                      "it the fit's covariance, is undefined");
  }

  const Tangent x = geodesic.displacement();
  const covariance_detail::PassInputs<G> inputs{x, h_inverse, leverage_matrix, s, flavour};
  covariance_detail::ObservationSums<G> sums;
  if constexpr (Pass == CovariancePass::fastest &&
                provides_v<G, capability_detail::ad_algebra_basis>) {
    sums = covariance_detail::sums_by_algebra(inputs, problem, residuals);
  } else {
    sums = covariance_detail::sums_by_matrices(inputs, problem, residuals);
  }
  if (sums.leverage_one >= 0) {
    return refused<G>(CovarianceStatus::undefined,
                      "observation " + std::to_string(sums.leverage_one) +
                          " has leverage 1 (its residual is zero by construction): the "
                          "robust covariance is undefined");
  }
  EndpointMatrix meat;
  meat.template topLeftCorner<d, d>() = sums.meat_start;
  meat.template topRightCorner<d, d>() = sums.meat_cross;
  meat.template bottomLeftCorner<d, d>() = sums.meat_cross.transpose();
  meat.template bottomRightCorner<d, d>() = sums.meat_end;

  const AdMatrix identity = AdMatrix::Identity();
  const AdMatrix jacobian_back = right_jacobian<G>(Tangent(-x));
  const AdMatrix jacobian_forward = right_jacobian<G>(x);
  EndpointMatrix k;
  k.template topLeftCorner<d, d>() = problem.a * identity;
  k.template topRightCorner<d, d>() = jacobian_back * sums.k01_core * right_jacobian_inverse<G>(x);
  k.template bottomLeftCorner<d, d>() =
      jacobian_forward * sums.k10_core * right_jacobian_inverse<G>(Tangent(-x));
  k.template bottomRightCorner<d, d>() = problem.c * identity;
  // Cov = K^{-1} D meat D^T K^{-T}, D = diag(J_r(-X), J_r(X)).
  EndpointMatrix outer = EndpointMatrix::Zero();
  outer.template topLeftCorner<d, d>() = jacobian_back;
  outer.template bottomRightCorner<d, d>() = jacobian_forward;
  const SmallLU<EndpointMatrix> k_lu(k);
  if (!k_lu.invertible()) {
    return refused<G>(CovarianceStatus::undefined, "K is singular at the estimate");
  }
  const EndpointMatrix bread = k_lu.solve(outer);
  // Cov = F F^T, F = bread R, meat = R R^T (R from meat's eigenvectors:
  // rank-deficient meats, planar SE(3) data or small N, are the rule, and
  // pivoted LDL^T's noise pivots would blow up there). A Gram matrix is
  // positive semi-definite up to rounding relative to its own largest
  // eigenvalue; bread meat bread^T is not when bread's entries are large
  // and cancel (a fuzzer found an eigenvalue of -5% of the largest on an
  // SE(3) fit of poses 1e16 m apart).
  const EndpointMatrix meat_root = covariance_detail::square_root(meat);
  const EndpointMatrix factor = bread.lazyProduct(meat_root);
  EndpointMatrix c = factor.lazyProduct(factor.transpose());
  c = ((c + c.transpose()) / 2).eval();
  if (!c.allFinite()) {
    return refused<G>(CovarianceStatus::undefined, "the covariance is not finite");
  }

  Result result;
  result.effective = {nu, nu, nu, nu};
  if (flavour == CovarianceFlavour::robust) {
    // The maps of the start, the end and the velocity, d x 2d each, as the
    // top rows of 2d x 2d matrices (satterthwaite reads `rows` rows).
    EndpointMatrix start_map = EndpointMatrix::Zero(), end_map = EndpointMatrix::Zero(),
                   velocity_map = EndpointMatrix::Zero();
    start_map.template topLeftCorner<d, d>().setIdentity();
    end_map.template topRightCorner<d, d>().setIdentity();
    velocity_map.template topLeftCorner<d, d>() = -right_jacobian_inverse<G>(Tangent(-x));
    velocity_map.template topRightCorner<d, d>() = right_jacobian_inverse<G>(x);
    const auto effective = [&](const EndpointMatrix& map, int rows) {
      return covariance_detail::satterthwaite(EndpointMatrix(map.lazyProduct(bread)), rows,
                                              sums.forces, meat_root);
    };
    result.effective.endpoints =
        covariance_detail::satterthwaite(bread, 2 * d, sums.forces, meat_root);
    result.effective.start = effective(start_map, d);
    result.effective.end = effective(end_map, d);
    result.effective.velocity = effective(velocity_map, d);
    // Zero degrees of freedom: the quantity's robust covariance is zero,
    // every observation that bears on it fitting exactly (two identical
    // observations at t_min pin the start, whatever the others do).
    const std::pair<const char*, Scalar> quantities[] = {{"endpoints", result.effective.endpoints},
                                                         {"start", result.effective.start},
                                                         {"end", result.effective.end},
                                                         {"velocity", result.effective.velocity}};
    for (const auto& [name, quantity_nu] : quantities) {
      if (!(quantity_nu > 0)) {
        return refused<G>(CovarianceStatus::undefined,
                          std::string("the robust covariance of the ") + name +
                              " is zero: every observation that bears on it has a zero "
                              "residual (the homoscedastic flavour pools the residuals)");
      }
    }
  }
  result.status = CovarianceStatus::defined;
  result.flavour = flavour;
  result.endpoints = c;
  result.factor = factor;
  result.jacobian = k;
  result.residual = s;
  result.degrees_of_freedom = nu;
  result.geodesic = geodesic;
  return result;
}

// The covariance of `fit`'s endpoints. `covariates` and `weights` must be
// those of the fit (the interval is taken from fit.geodesic). Never throws
// for bad input and never returns NaN: a covariance that cannot be
// estimated is reported as undefined with a message.
template <class G, class Covariates>
FitCovariance<G> covariance(const RegressionResult<G>& fit, const Covariates& covariates,
                            const std::vector<typename G::Scalar>& weights = {},
                            CovarianceFlavour flavour = CovarianceFlavour::homoscedastic) {
  using Scalar = typename G::Scalar;
  using covariance_detail::refused;
  if (!is_valid(flavour)) {
    return refused<G>(CovarianceStatus::invalid_input,
                      "flavour must be homoscedastic or robust (got " +
                          std::to_string(static_cast<int>(flavour)) + ")");
  }
  if (!fit.ok() || !fit.geodesic) {
    return refused<G>(CovarianceStatus::invalid_input,
                      std::string("the fit did not succeed (status ") + to_string(fit.status) +
                          "): no covariance");
  }
  const std::size_t n = covariates.size();
  if (fit.residuals.size() != n) {
    return refused<G>(CovarianceStatus::invalid_input,
                      "the covariates are not the fit's (" + std::to_string(n) + " vs " +
                          std::to_string(fit.residuals.size()) + " residuals)");
  }
  const Geodesic<G>& geodesic = *fit.geodesic;
  Problem<Scalar> problem;
  const std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>> interval(geodesic.t_min(),
                                                                             geodesic.t_max());
  if (auto rejection = make_problem(covariates, weights, std::optional(interval), problem)) {
    return refused<G>(CovarianceStatus::invalid_input, rejection->message);
  }
  return covariance_of(geodesic, fit.residuals, problem, flavour);
}

}  // namespace bireg

// The compiled part's instantiations of covariance() and covariance_of()
// (bireg::bireg_precompiled).
#if defined(BIREG_PRECOMPILED)
#include "bireg/statistics/precompiled/covariance.hpp"
#endif
