// bireg: coefficient functions with removable singularities, evaluated
// without cancellation over their whole range.
//
// The closed forms of exp and log on SO(3), SE(2) and SE(3) need functions
// such as (1 - cos x)/x^2 or (x - sin x)/x^3. Evaluated naively they lose
// digits as x -> 0 (at x = 1e-4, x - sin x keeps only 8 of 16 digits).
// Each function below is either rewritten so that no subtraction of nearly
// equal numbers occurs (half-angle forms), or evaluated by its Taylor series in
// x^2 below a threshold and by the direct formula above it. The thresholds are
// chosen where the direct formula's cancellation costs at most a factor ~3 in
// rounding (derivation beside each function); the series are truncated where
// the first omitted term is below long double's epsilon at the threshold, so
// the same code is accurate for float, double and long double.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "bireg/math/bernoulli.hpp"

namespace bireg {
namespace small_angle {

// The coefficients, derived in long double, rounded once to the caller's
// precision (at compile time: a polynomial loop over long doubles would convert
// each coefficient at run time, on x86 through the x87 unit).
template <class Scalar, std::size_t Count>
constexpr std::array<Scalar, Count> in_precision(const std::array<long double, Count>& exact) {
  std::array<Scalar, Count> rounded{};
  for (std::size_t k = 0; k < Count; ++k)
    rounded[k] = static_cast<Scalar>(exact[k]);
  return rounded;
}

// sum_k coefficients[k] * x^k in the caller's precision, as four Horner
// chains in x^4 (chain j takes the coefficients k = j mod 4):
//   p(x) = P0(x^4) + x (P1(x^4) + x (P2(x^4) + x P3(x^4))).
// The chains do not depend on one another, so a 20-term series is 5
// dependent multiply-adds deep instead of Horner's 20: one Horner chain made
// SE(3)'s log and exp wait on it in the fit's per-observation loop (about 50
// of SE(3) log's 100 ns there). The series below are used where their terms
// decrease geometrically, so the rounding error stays, as for one chain, a
// few ulps of the sum.
template <class Scalar, std::size_t Count>
Scalar polynomial(const std::array<Scalar, Count>& coefficients, Scalar x) {
  constexpr std::size_t kChains = 4;
  constexpr std::size_t kRows = (Count + kChains - 1) / kChains;
  const Scalar x2 = x * x;
  const Scalar x4 = x2 * x2;
  std::array<Scalar, kChains> chain{};
  for (std::size_t row = kRows; row-- > 0;) {
    for (std::size_t j = 0; j < kChains; ++j) {
      const std::size_t k = row * kChains + j;
      if (k < Count) chain[j] = chain[j] * x4 + coefficients[k];
    }
  }
  return chain[0] + x * (chain[1] + x * (chain[2] + x * chain[3]));
}

namespace detail {
// (-1)^k / (2k + first)!, k = 0..Count-1: the Taylor coefficients in powers
// of x^2 of (1 - cos x)/x^2 (first = 2) and of (x - sin x)/x^3 (first = 3).
template <std::size_t Count>
constexpr std::array<long double, Count> alternating_factorial_series(int first) {
  std::array<long double, Count> c{};
  long double factorial = 1.0L;
  for (int n = 2; n <= first; ++n)
    factorial *= static_cast<long double>(n);
  for (std::size_t k = 0; k < Count; ++k) {
    c[k] = (k % 2 == 0 ? 1.0L : -1.0L) / factorial;
    const long double next = static_cast<long double>(2 * k) + first + 1;
    factorial *= next * (next + 1);
  }
  return c;
}
template <std::size_t Count>
constexpr std::array<long double, Count> x_minus_sin_series() {
  return alternating_factorial_series<Count>(3);
}
template <std::size_t Count>
constexpr std::array<long double, Count> one_minus_cos_series() {
  return alternating_factorial_series<Count>(2);
}

// Taylor coefficients of (1 - (x/2) cot(x/2))/x^2 in powers of x^2. From
// y cot y = sum_n (-4)^n B_2n y^2n / (2n)!, with y = x/2:
// (x/2) cot(x/2) = 1 - sum_{n>=1} |B_2n| x^2n / (2n)!, so the coefficient of
// x^(2n-2) is |b_2n|.
template <std::size_t Count>
constexpr std::array<long double, Count> one_minus_half_cot_series() {
  std::array<long double, Count> c{};
  for (std::size_t n = 1; n <= Count; ++n) {
    const long double b = kBernoulliOverFactorial[2 * n];
    c[n - 1] = b < 0 ? -b : b;
  }
  return c;
}

// Taylor coefficients of e'(x)/x in powers of x^2, e(x) = (1 - (x/2)
// cot(x/2))/x^2 = sum_{n>=1} |b_2n| x^(2n-2): the coefficient of x^(2n-4) is
// (2n - 2) |b_2n|, n >= 2.
template <std::size_t Count>
constexpr std::array<long double, Count> one_minus_half_cot_derivative_series() {
  std::array<long double, Count> c{};
  for (std::size_t n = 2; n < Count + 2; ++n) {
    const long double b = kBernoulliOverFactorial[2 * n];
    c[n - 2] = static_cast<long double>(2 * n - 2) * (b < 0 ? -b : b);
  }
  return c;
}
}  // namespace detail

// Below this |x| the two-term Taylor polynomials used for sin(x)/x and
// atan(x)/x are exact to long double epsilon: the first omitted term is
// x^4/120 (resp. x^4/5), 1e-20/5 at x = 1e-5 (long double epsilon ~ 1.1e-19).
template <class Scalar>
constexpr Scalar tiny_angle() {
  return Scalar(1e-5);
}

// sin(x)/x. The quotient of two correctly rounded numbers has no cancellation;
// only x = 0 (and x so small that x^2 underflows) needs the series.
template <class Scalar>
Scalar sin_over_x(Scalar x) {
  using std::abs;
  using std::sin;
  if (abs(x) < tiny_angle<Scalar>()) return Scalar(1) - x * x / Scalar(6);
  return sin(x) / x;
}

// (1 - cos x)/x^2 = (1/2) (sin(x/2) / (x/2))^2: the half-angle form has no
// cancellation at any x.
template <class Scalar>
Scalar one_minus_cos_over_x2(Scalar x) {
  const Scalar s = sin_over_x(x / Scalar(2));
  return s * s / Scalar(2);
}

// The same from x^2 (x >= 0 its square root), for callers holding
// |omega|^2: below x = 2 the series in x^2, which converges with ratio
// x^2/((2k+3)(2k+4)) (14 terms leave 4^14/30! < 1e-23 at x = 2), needs
// neither the square root nor a sine.
template <class Scalar>
Scalar one_minus_cos_over_x2_from_square(Scalar x2) {
  using std::sqrt;
  static constexpr auto kSeries = in_precision<Scalar>(detail::one_minus_cos_series<14>());
  if (x2 < Scalar(4)) return polynomial(kSeries, x2);
  return one_minus_cos_over_x2(sqrt(x2));
}

// (x - sin x)/x^3. The direct formula's relative rounding error is about
// eps * x / (x - sin x): 6/x^2 eps for small x, below 2 eps for |x| >= 2
// (x - sin x = 1.09 at x = 2). Below 2 the series in x^2 converges with ratio
// x^2/((2k+4)(2k+5)); 14 terms leave 4^14/31! < 1e-25 at x = 2.
template <class Scalar>
inline constexpr auto kXMinusSinSeries = in_precision<Scalar>(detail::x_minus_sin_series<14>());

template <class Scalar>
Scalar x_minus_sin_over_x3(Scalar x) {
  using std::abs;
  using std::sin;
  if (abs(x) < Scalar(2)) return polynomial(kXMinusSinSeries<Scalar>, x * x);
  return (x - sin(x)) / (x * x * x);
}
// The same from x^2 (x >= 0 its square root).
template <class Scalar>
Scalar x_minus_sin_over_x3_from_square(Scalar x2) {
  using std::sqrt;
  if (x2 < Scalar(4)) return polynomial(kXMinusSinSeries<Scalar>, x2);
  return x_minus_sin_over_x3(sqrt(x2));
}

// (x/2) cot(x/2), the diagonal of the inverse of SE(2)'s V matrix. As a
// quotient of cos and sin it has no cancellation; it is finite for
// |x| < 2 pi and the series 1 - x^2/12 covers x -> 0 (next term x^4/720).
template <class Scalar>
Scalar half_x_cot_half_x(Scalar x) {
  using std::abs;
  using std::cos;
  using std::sin;
  if (abs(x) < tiny_angle<Scalar>()) return Scalar(1) - x * x / Scalar(12);
  const Scalar half = x / Scalar(2);
  return half * cos(half) / sin(half);
}

// (1 - (x/2) cot(x/2))/x^2, the W^2 coefficient of SE(3)'s V^{-1}. Direct
// evaluation cancels like 12/x^2; at |x| >= 2 the subtraction 1 - 0.642 costs
// at most a factor 3. Below 2 the Bernoulli series converges with ratio
// (x/(2 pi))^2 <= 0.1; 20 terms leave < 1e-20. Finite for |x| < 2 pi.
// The same from x^2 (x >= 0 its square root), for callers holding |omega|^2:
// the series needs no square root.
template <class Scalar>
Scalar one_minus_half_x_cot_half_x_over_x2_from_square(Scalar x2) {
  using std::sqrt;
  static constexpr auto kSeries = in_precision<Scalar>(detail::one_minus_half_cot_series<20>());
  if (x2 < Scalar(4)) return polynomial(kSeries, x2);
  return (Scalar(1) - half_x_cot_half_x(sqrt(x2))) / x2;
}
template <class Scalar>
Scalar one_minus_half_x_cot_half_x_over_x2(Scalar x) {
  return one_minus_half_x_cot_half_x_over_x2_from_square(x * x);
}

// e'(x)/x for e(x) = (1 - (x/2) cot(x/2))/x^2 (the derivative of SE(3)'s
// J_r^{-1} along the rotation angle). Directly,
//   e'(x)/x = -2/x^4 + cot(x/2)/(2 x^3) + 1/(4 x^2 sin^2(x/2)),
// whose terms cancel like 720/x^4 relative to the result (1/360 at 0): a
// factor 9 at x = 3, where the direct form takes over. Below 3 the series
// converges with ratio (x/(2 pi))^2 <= 0.23; 32 terms leave < 1e-20.
template <class Scalar>
Scalar one_minus_half_x_cot_half_x_over_x2_derivative_over_x(Scalar x) {
  using std::abs;
  using std::cos;
  using std::sin;
  static constexpr auto kSeries =
      in_precision<Scalar>(detail::one_minus_half_cot_derivative_series<32>());
  if (abs(x) < Scalar(3)) return polynomial(kSeries, x * x);
  const Scalar x2 = x * x;
  const Scalar sin_half = sin(x / Scalar(2)), cos_half = cos(x / Scalar(2));
  return -Scalar(2) / (x2 * x2) + cos_half / (Scalar(2) * x2 * x * sin_half) +
         Scalar(1) / (Scalar(4) * x2 * sin_half * sin_half);
}

// atan(y)/y for y >= 0: a quotient of correctly rounded numbers, with the
// series 1 - y^2/3 where y^2 would lose the quotient's meaning.
template <class Scalar>
Scalar atan_over_y(Scalar y) {
  using std::abs;
  using std::atan;
  if (abs(y) < tiny_angle<Scalar>()) return Scalar(1) - y * y / Scalar(3);
  return atan(y) / y;
}

}  // namespace small_angle
}  // namespace bireg
