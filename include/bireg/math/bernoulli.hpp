// bireg: Bernoulli numbers scaled by factorials, b_k = B_k / k!.
//
// They are the Taylor coefficients of z / (e^z - 1) = sum_k b_k z^k, which
// enter both the differential of the group logarithm (paper, eq.
// "derivative_log") and the inverse differentials of a geodesic (paper, Lemma
// "diff_2_gam"). The table is built at compile time from the paper's
// recursion, rewritten for b_k so that no large factorials appear:
//
//   z/(e^z - 1) * (e^z - 1)/z = 1   =>   sum_{k=0}^{n} b_k / (n + 1 - k)! = 0, n >= 1.
//
// In long double the recursion keeps b_k to about 1e-17 relative up to k = 70
// (checked against exact rationals), i.e. to full double precision. B_k = 0
// for odd k >= 3; those entries are set to zero exactly, not left as rounding
// residue.
#pragma once

#include <array>
#include <cstddef>

namespace bireg {

// Table of b_k = B_k / k! for k = 0 .. Count-1 (B_1 = -1/2 convention).
template <std::size_t Count>
constexpr std::array<long double, Count> bernoulli_over_factorial_table() {
  std::array<long double, Count + 2> inverse_factorial{};
  inverse_factorial[0] = 1.0L;
  for (std::size_t n = 1; n < Count + 2; ++n) {
    inverse_factorial[n] = inverse_factorial[n - 1] / static_cast<long double>(n);
  }
  std::array<long double, Count> b{};
  b[0] = 1.0L;
  for (std::size_t n = 1; n < Count; ++n) {
    if (n >= 3 && n % 2 == 1) {
      b[n] = 0.0L;
      continue;
    }
    long double sum = 0.0L;
    for (std::size_t k = 0; k < n; ++k)
      sum += b[k] * inverse_factorial[n + 1 - k];
    b[n] = -sum;  // the k = n term of the identity has weight 1/1! = 1
  }
  return b;
}

// Enough entries for every series in bireg (inverse-differential order caps
// and the small-angle expansions).
inline constexpr std::size_t kBernoulliTableSize = 96;
inline constexpr std::array<long double, kBernoulliTableSize> kBernoulliOverFactorial =
    bernoulli_over_factorial_table<kBernoulliTableSize>();

}  // namespace bireg
