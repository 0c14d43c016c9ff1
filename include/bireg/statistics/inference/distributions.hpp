// bireg: the few distribution functions the statistics need, and their
// quantiles: chi-square, F, Hotelling's T^2 and the Lawley-Hotelling trace
// (McKeon's F approximation). Written here to keep bireg free of a
// statistics dependency; double precision throughout (quantiles are
// statistics, not geometry: 1e-12 relative is far beyond what they mean).
//
// The regularised incomplete gamma P(a, x) is summed by its power series
// below x = a + 1 and by its continued fraction above; the regularised
// incomplete beta I_x(a, b) by its continued fraction (modified Lentz), on
// the side x < (a + 1)/(a + b + 2) where it converges fast, using
// I_x(a, b) = 1 - I_{1-x}(b, a) on the other. Quantiles invert the
// distribution function by bisection: monotone, bracketed, and 200 halvings
// reach the resolution of double on any bracket, so no convergence
// question arises.
//
// Huge degrees of freedom. log B(a, b) is formed without the cancellation
// of lgamma(a + b) - lgamma(b) (both ~ b log b, their difference ~ a log b)
// when b is large. An F quantile whose denominator degrees of freedom d2
// reach kChiSquareLimit is the chi-square limit with its first correction,
//   d1 F_q = x (1 + (x - d1 + 2) / (2 d2)) + O(x^3 / d2^2),  x = chi2_{d1} quantile
// (F = (chi2_{d1} / d1) / Y, Y = chi2_{d2} / d2 of mean 1 and variance
// 2 / d2: P(chi2_{d1} <= x Y) moves by x^2 g'(x) / d2 for the chi2_{d1}
// density g, and x^2 g'/g = x (d1/2 - 1) - x^2/2). There the remainder is
// below 1e-12 relative, whereas the incomplete beta's continued fraction
// needs ~sqrt(d2) terms near the quantile (more than kMaxTerms: errors of
// 1e-10 at d2 = 1e8, 2e-6 at 1e12) and the bisection on u = d1 x / (d1 x +
// d2) in [0, 1] cannot resolve u ~ d1 / d2 below 2^-200 (d2 ~ 1e61 on).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace bireg {

namespace distribution_detail {

inline constexpr int kMaxTerms = 1000;
inline constexpr double kRelative = 1e-16;
inline constexpr double kTiny = 1e-300;
// From this argument on, lgamma differences use Stirling's series.
inline constexpr double kStirlingFrom = 1e6;

// log(Gamma(a + b) / (Gamma(a) Gamma(b))) = -log B(a, b), a, b > 0. With
// s = min(a, b), l = max(a, b) >= kStirlingFrom, Stirling's series
// lgamma(z) = (z - 1/2) log z - z + log(2 pi)/2 + 1/(12 z) - 1/(360 z^3)
// + O(z^-5) (the next term, 1/(1260 z^5), is below 1e-33 here) gives
//   lgamma(s + l) - lgamma(l) = (l - 1/2) log1p(s/l) + s log(s + l) - s
//                               + 1/(12 (s + l)) - 1/(12 l)
//                               - 1/(360 (s + l)^3) + 1/(360 l^3),
// whose terms are each of the size of the result (log1p keeps s/l).
inline double log_inverse_beta(double a, double b) {
  const double small = std::min(a, b), large = std::max(a, b);
  if (large < kStirlingFrom) return std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b);
  const double sum = small + large;
  const double leading = (large - 0.5) * std::log1p(small / large) + small * std::log(sum) - small;
  const double first_correction = 1 / (12 * sum) - 1 / (12 * large);
  const double second_correction = 1 / (360 * sum * sum * sum) - 1 / (360 * large * large * large);
  return leading + first_correction - second_correction - std::lgamma(small);
}

// P(a, x) by the series x^a e^{-x} / Gamma(a + 1) sum_n x^n / ((a+1)...(a+n)).
inline double gamma_series(double a, double x) {
  double term = 1 / a, sum = term;
  for (int n = 1; n < kMaxTerms; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kRelative) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) = 1 - P(a, x) by its continued fraction (modified Lentz).
inline double gamma_continued_fraction(double a, double x) {
  double b = x + 1 - a, c = 1 / kTiny, d = 1 / b, h = d;
  for (int n = 1; n < kMaxTerms; ++n) {
    const double an = -n * (n - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < kRelative) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// The continued fraction of I_x(a, b) without its prefactor.
inline double beta_continued_fraction(double a, double b, double x) {
  const double qab = a + b, qap = a + 1, qam = a - 1;
  double c = 1, d = 1 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1 / d;
  double h = d;
  for (int m = 1; m < kMaxTerms; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < kRelative) break;
  }
  return h;
}

// The x in [low, high] with cdf(x) = level, cdf increasing.
template <class Cdf>
double bisect(Cdf cdf, double level, double low, double high) {
  for (int i = 0; i < 200 && high - low > 0; ++i) {
    const double middle = low + (high - low) / 2;
    if (middle <= low || middle >= high) break;
    (cdf(middle) < level ? low : high) = middle;
  }
  return low + (high - low) / 2;
}

}  // namespace distribution_detail

// P(a, x) = gamma(a, x) / Gamma(a), a > 0, x >= 0.
inline double regularized_gamma_p(double a, double x) {
  if (!(x > 0)) return 0;
  if (x < a + 1) return distribution_detail::gamma_series(a, x);
  return 1 - distribution_detail::gamma_continued_fraction(a, x);
}

// I_x(a, b), a, b > 0, x in [0, 1].
inline double regularized_beta(double a, double b, double x) {
  if (!(x > 0)) return 0;
  if (!(x < 1)) return 1;
  const double log_prefactor =
      distribution_detail::log_inverse_beta(a, b) + a * std::log(x) + b * std::log1p(-x);
  const double prefactor = std::exp(log_prefactor);
  if (x < (a + 1) / (a + b + 2)) {
    return prefactor * distribution_detail::beta_continued_fraction(a, b, x) / a;
  }
  return 1 - prefactor * distribution_detail::beta_continued_fraction(b, a, 1 - x) / b;
}

// Chi-square distribution with k > 0 degrees of freedom.
inline double chi_square_cdf(double x, double k) {
  return regularized_gamma_p(k / 2, x / 2);
}

// F distribution with (d1, d2) > 0 degrees of freedom.
inline double f_cdf(double x, double d1, double d2) {
  if (!(x > 0)) return 0;
  return regularized_beta(d1 / 2, d2 / 2, d1 * x / (d1 * x + d2));
}

// Quantiles at `level` in (0, 1); nullopt for a level or degrees of freedom
// outside the domain.
inline std::optional<double> chi_square_quantile(double level, double k) {
  if (!(level > 0 && level < 1) || !(k > 0) || !std::isfinite(k)) return std::nullopt;
  double high = k + 10;
  while (chi_square_cdf(high, k) < level)
    high *= 2;
  return distribution_detail::bisect([k](double x) { return chi_square_cdf(x, k); }, level, 0,
                                     high);
}

// Denominator degrees of freedom from which f_quantile is the chi-square
// limit with its first correction (see the top of this file).
inline constexpr double kChiSquareLimit = 1e7;

// Bisection on u = d1 x / (d1 x + d2) in [0, 1], where I_u is bracketed;
// for d2 >= kChiSquareLimit the chi-square limit with its first correction.
inline std::optional<double> f_quantile(double level, double d1, double d2) {
  if (!(level > 0 && level < 1) || !(d1 > 0) || !(d2 > 0) || !std::isfinite(d1) ||
      !std::isfinite(d2)) {
    return std::nullopt;
  }
  if (d2 >= kChiSquareLimit) {
    const std::optional<double> chi_square = chi_square_quantile(level, d1);
    if (!chi_square) return std::nullopt;
    const double x = *chi_square;
    const double correction = (x - d1 + 2) / (2 * d2);
    return x / d1 * (1 + correction);
  }
  const double u = distribution_detail::bisect(
      [d1, d2](double v) { return regularized_beta(d1 / 2, d2 / 2, v); }, level, 0, 1);
  if (!(u < 1)) return std::nullopt;
  return d2 * u / (d1 * (1 - u));
}

// Hotelling's T^2 with dimension p and nu error degrees of freedom (the
// Mahalanobis distance of one normal p-vector with its covariance
// estimated from a Wishart(nu) scatter): T^2 = nu p / (nu - p + 1) F(p,
// nu - p + 1). Exact on R^n for a single vector (the velocity, the pose at
// one covariate, a prediction). Needs nu > p - 1. None where the quantile
// is not a number: p and nu both near the largest double with
// nu - p + 1 small make nu p / (nu - p + 1) overflow while F's quantile
// underflows to 0 (found by fuzz_statistics: p = nu = 1e300).
inline std::optional<double> hotelling_quantile(double level, double p, double nu) {
  const double denominator = nu - p + 1;
  if (!(denominator > 0)) return std::nullopt;
  const std::optional<double> f = f_quantile(level, p, denominator);
  if (!f) return std::nullopt;
  // nu / (nu - p + 1) first: nu p alone overflows for nu near the largest double.
  const double quantile = nu / denominator * p * *f;
  if (std::isnan(quantile)) return std::nullopt;
  return quantile;
}

// The Lawley-Hotelling trace U = nu tr(B E^{-1}), B ~ Wishart_p(q), E ~
// Wishart_p(nu), by McKeon's (1974) approximation U / nu ~ g F(a, b):
//   a = p q,  B = (nu + q - p - 1)(nu - 1) / ((nu - p - 3)(nu - p)),
//   b = 4 + (a + 2)/(B - 1),  g = a (b - 2) / (b (nu - p - 1)).
// B - 1 ~ (p + q + 1)/nu vanishes as nu grows; it is formed without that
// cancellation (expanding the products of B's numerator and denominator),
//   B - 1 = ((p + q + 1) nu + 1 - q - p^2 - 2p) / ((nu - p - 3)(nu - p)),
// and no product of two nu's is formed (nu up to the largest double).
// It is exact for q = 1 (where it reduces to Hotelling's T^2). This is the
// Mahalanobis distance of the two endpoints together (q = 2: a line's two
// values share one estimated d x d covariance). Needs nu > p + 3.
inline std::optional<double> lawley_hotelling_quantile(double level, double p, double q,
                                                       double nu) {
  if (q == 1) return hotelling_quantile(level, p, nu);
  if (!(nu - p - 3 > 0)) return std::nullopt;
  const double a = p * q;
  const double slope = p + q + 1, offset = 1 - q - p * p - 2 * p;
  const double big_b_minus_one =
      (slope + offset / nu) / (nu - p - 3) * (nu / (nu - p));  // B - 1, nu divided out
  const double b = 4 + (a + 2) / big_b_minus_one;
  // nu g = a ((b - 2)/b) (nu / (nu - p - 1)).
  const double nu_g = a * ((b - 2) / b) * (nu / (nu - p - 1));
  const std::optional<double> f = f_quantile(level, a, b);
  if (!f) return std::nullopt;
  return nu_g * *f;
}

}  // namespace bireg
