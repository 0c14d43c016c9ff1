// bireg: the inverse differentials of a Cartan–Schouten geodesic as power
// series in ad_X (paper, Lemma 3.1 and Corollary 3.2).
//
// In left-trivialised coordinates (DESIGN.md section 2), for the geodesic
// gamma(s) = g0 exp(s X) and A = ad_X,
//
//   (d_1 gamma_s)^{-1} = phi_s(A),        (d_0 gamma_s)^{-1} = phi_{1-s}(-A),
//   phi_s(z) = (1 - e^{-z}) / (1 - e^{-s z}),
//
// and the weighted form that enters the estimating equations is
//
//   psi_s(z) = s^2 phi_s(z) = sum_{m>=0} Ct_m(s) z^m,
//   Ct_m(s)  = (-1)^m sum_{k=0}^{m} s^{k+1} b_k / (m - k + 1)!,   b_k = B_k / k!
//
// (the paper's C_m(s) times s^2, the tilde-C of Lemma 3.5's proof).
// psi_s is analytic for |z| < 2 pi / s with psi_s(0) = s and psi_0 = 0, so the
// endpoints s = 0 and s = 1 are regular. The series converges when the
// spectral radius of A is below 2 pi; its terms shrink roughly like
// (rho(A) / 2 pi)^m.
//
// The coefficients factor as Ct_m(s) = (-1)^m sum_k T[m][k] s^{k+1} with the
// table T[m][k] = b_k / (m - k + 1)!, which depends on nothing but m and k:
// it is built once, at compile time.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include <Eigen/Core>

#include "bireg/math/bernoulli.hpp"

namespace bireg {

// Highest series order bireg evaluates. At rho(ad_X) = pi (the longest SO(3)
// or SE(3) geodesic) the terms shrink like 2^-m, so 64 terms reach double
// precision with room for the non-normal growth of ad_X on SE(3).
inline constexpr int kMaxSeriesOrder = 64;

namespace detail {
using PsiTable = std::array<std::array<long double, kMaxSeriesOrder + 1>, kMaxSeriesOrder + 1>;

constexpr PsiTable psi_series_table() {
  std::array<long double, kMaxSeriesOrder + 2> inverse_factorial{};
  inverse_factorial[0] = 1.0L;
  for (int n = 1; n < kMaxSeriesOrder + 2; ++n) {
    inverse_factorial[n] = inverse_factorial[n - 1] / static_cast<long double>(n);
  }
  PsiTable table{};
  for (int m = 0; m <= kMaxSeriesOrder; ++m) {
    for (int k = 0; k <= m; ++k) {
      table[m][k] = kBernoulliOverFactorial[k] * inverse_factorial[m - k + 1];
    }
  }
  return table;
}

// Sum_k |T[m][k]|: bounds |Ct_m(s)| / s for every s in [0, 1].
constexpr std::array<long double, kMaxSeriesOrder + 1> psi_series_bounds(const PsiTable& table) {
  std::array<long double, kMaxSeriesOrder + 1> bound{};
  for (int m = 0; m <= kMaxSeriesOrder; ++m) {
    for (int k = 0; k <= m; ++k)
      bound[m] += table[m][k] < 0 ? -table[m][k] : table[m][k];
  }
  return bound;
}
}  // namespace detail

// T[m][k] = b_k / (m - k + 1)! for 0 <= k <= m <= kMaxSeriesOrder.
inline constexpr detail::PsiTable kPsiSeriesTable = detail::psi_series_table();
inline constexpr std::array<long double, kMaxSeriesOrder + 1> kPsiSeriesBound =
    detail::psi_series_bounds(kPsiSeriesTable);

// Ct_m(s), the coefficient of z^m in psi_s(z).
template <class Scalar>
Scalar psi_series_coefficient(int m, Scalar s) {
  Scalar sum(0);
  Scalar s_power = s;  // s^{k+1}
  for (int k = 0; k <= m; ++k) {
    sum += static_cast<Scalar>(kPsiSeriesTable[m][k]) * s_power;
    s_power *= s;
  }
  return m % 2 == 0 ? sum : -sum;
}

// psi_s(A) r by the series truncated after the A^order term, Horner's rule.
// For one vector at a time (tests, diagnostics); the regression applies the
// same series to moments of all residuals at once.
template <class Scalar, int D>
Eigen::Matrix<Scalar, D, 1> apply_psi_series(const Eigen::Matrix<Scalar, D, D>& a, Scalar s,
                                             const Eigen::Matrix<Scalar, D, 1>& r, int order) {
  Eigen::Matrix<Scalar, D, 1> sum = psi_series_coefficient(order, s) * r;
  for (int m = order - 1; m >= 0; --m)
    sum = a * sum + psi_series_coefficient(m, s) * r;
  return sum;
}

// The truncation order at which every further term of psi_s(A) r, for all s
// in [0, 1], is below `relative_tolerance` times |s r|: the smallest M with
// bound_m ||A^m|| <= relative_tolerance for m = M + 1 and M + 2 (two in a
// row, since odd Bernoulli numbers vanish), bound_m = kPsiSeriesBound[m].
// Also returns that bound at the chosen order, which exceeds the tolerance
// only when kMaxSeriesOrder was reached first.
template <class Scalar, int D>
std::pair<int, Scalar> adaptive_series_order(const Eigen::Matrix<Scalar, D, D>& a,
                                             Scalar relative_tolerance, int max_order) {
  using std::sqrt;
  Eigen::Matrix<Scalar, D, D> power = a;  // A^{m}
  Scalar previous_bound = std::numeric_limits<Scalar>::infinity();
  for (int m = 1; m <= max_order; ++m) {
    const Scalar bound = static_cast<Scalar>(kPsiSeriesBound[m]) * sqrt(power.squaredNorm());
    if (bound <= relative_tolerance && previous_bound <= relative_tolerance) return {m - 2, bound};
    previous_bound = bound;
    power = power * a;
  }
  return {max_order, previous_bound};
}

}  // namespace bireg
