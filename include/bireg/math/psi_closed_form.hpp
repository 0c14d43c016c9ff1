// bireg: the scalar coefficients of the weighted inverse differentials
// psi_s(ad_X) in closed form (DESIGN.md section 2, "Exact form"). The groups
// whose ad_X has eigenvalues 0 and +-i theta only (SO(2), SO(3), SE(2),
// SE(3)) assemble psi_s(ad_X) r from them in their own headers
// (ClosedFormPsi); this header holds the part they share. Sim(3), whose
// ad_X also has the eigenvalues sigma and sigma +- i theta, has its own
// closed form in groups/sim3.hpp.
//
// On these groups ad_X has eigenvalues 0 and +-i theta (theta the rotation
// angle), so any analytic F(ad_X) is fixed by F and F' at 0 and i theta. For
// F = psi_s, with 1 - e^{-i phi} = 2i sin(phi/2) e^{-i phi/2},
//
//   psi_s(i theta)  = s^2 sin(theta/2) / sin(s theta/2) e^{-i (1-s) theta/2},
//   psi_s'/psi_s    = (s - 1)/2 - (i/2) (cot(theta/2) - s cot(s theta/2)),
//
// both free of cancellation for s theta in (0, 2 pi). Domain: the rotation
// angle theta in (0, 2 pi); the principal logarithm of SO(3), SE(3) and
// SE(2) keeps it at or below pi, where sin(s theta/2) >= sin(s pi/2) > 0
// for s > 0 (s = 0 returns psi_0 = 0 exactly). At theta -> 2 pi psi itself
// has its pole (sin(theta/2) -> 0 in the denominator of cot(theta/2)), the
// same edge where the series stops converging. With F(i theta) =
// alpha + i beta and F'(i theta) = alpha' + i beta', the scalar coefficients
//
//   f1 = beta / theta,                     f2 = (s - alpha) / theta^2,
//   g1 = f1'(theta)/theta = (theta alpha' - beta) / theta^3,
//   g2 = f2'(theta)/theta = (theta beta' - 2 (s - alpha)) / theta^4
//
// give, on SO(3) (W = hat(omega)),  F(W) v = s v + f1 W v + f2 W^2 v; on SE(3)
// (ad = [W P; 0 W], P = hat(rho)) the upper-right block is the derivative of
// F(W) along P, D v = f1 P v + f2 (W P + P W) v + (omega . rho)(g1 W + g2 W^2) v;
// on SE(2) (ad = [theta J, c; 0 0]) the block is (F(theta J) - s)(theta J)^{-1}
// c = (f1 I + theta f2 J) c.
//
// The quotients by theta^3 and theta^4 cancel as theta -> 0 (like
// (theta - sin theta)/theta^3). Below kExactMinAngle the regression
// therefore uses the power series instead, which there converges to
// rounding in a dozen terms: "exact" means exact to rounding at every
// angle, by closed form where it is accurate and by the series where the
// series is.
#pragma once

#include <array>
#include <cmath>

namespace bireg {

// Rotation angle from which the closed forms are used. Their cancellation
// grows like 1/theta^2 relative to the result: against a long double series
// the SE(3) form is off by 1.4e-15 at theta = 0.1 and 2.2e-14 at 0.01, but
// stays below 6e-16 from 0.3 to pi (tests/test_exact_inverse_differential
// checks 1e-14 densely). Below 0.25 the series needs only ~12 terms
// ((0.25 / 2 pi)^12 < 1e-16).
inline constexpr double kExactMinAngle = 0.25;

namespace psi_closed_form {

// sin and cos of one angle.
template <class Scalar>
struct SinCos {
  Scalar sin, cos;
  static SinCos of(Scalar angle) {
    using std::cos;
    using std::sin;
    return {sin(angle), cos(angle)};
  }
};

// What psi_s at angle theta needs of theta alone, computed once per X: the
// half angle's sin and cos, cot(theta/2) and the powers 1/theta^k, so that
// the coefficients of one observation divide once (by sin(s theta/2)).
template <class Scalar>
struct Angle {
  Scalar theta;
  SinCos<Scalar> half;                           // theta/2
  Scalar cot_half;                               // cot(theta/2)
  Scalar inverse, inverse2, inverse3, inverse4;  // 1/theta .. 1/theta^4

  static Angle of(Scalar theta) {
    const SinCos<Scalar> half = SinCos<Scalar>::of(theta / 2);
    const Scalar inverse = 1 / theta, inverse2 = inverse * inverse;
    return {theta,
            half,
            half.cos / half.sin,
            inverse,
            inverse2,
            inverse2 * inverse,
            inverse2 * inverse2};
  }
};

// sin and cos of s theta/2 and of (1 - s) theta/2 from one sin/cos
// evaluation, given those of theta/2 (s in [0, 1]). The smaller of the two
// angles, a = min(s, 1 - s) theta/2, is evaluated directly, so it keeps its
// full relative accuracy however small it is; the other, theta/2 - a, by
//   sin(theta/2 - a) = sin(theta/2) cos a - cos(theta/2) sin a,
//   cos(theta/2 - a) = cos(theta/2) cos a + sin(theta/2) sin a.
// For theta in [0, pi] every product is >= 0, so the cosine is a sum of
// non-negative terms, and the sine's difference loses at most the factor
// sin(theta/2 + a) / sin(theta/2 - a) <= sin(3 theta/4) / sin(theta/4) <= 3
// (a <= theta/4): a few ulps. Beyond pi (not reached from a principal
// logarithm) both pairs are evaluated directly.
template <class Scalar>
struct HalfAnglePair {
  SinCos<Scalar> s_half, u_half;  // s theta/2, (1 - s) theta/2
};

template <class Scalar>
HalfAnglePair<Scalar> half_angle_pair(Scalar theta, const SinCos<Scalar>& half, Scalar s) {
  constexpr Scalar kPi = Scalar(3.141592653589793238462643383279502884L);
  const Scalar u = 1 - s;
  if (!(theta <= kPi)) {
    return {SinCos<Scalar>::of(s * theta / 2), SinCos<Scalar>::of(u * theta / 2)};
  }
  const bool s_is_smaller = s <= u;
  const SinCos<Scalar> smaller = SinCos<Scalar>::of((s_is_smaller ? s : u) * theta / 2);
  const SinCos<Scalar> larger{half.sin * smaller.cos - half.cos * smaller.sin,
                              half.cos * smaller.cos + half.sin * smaller.sin};
  if (s_is_smaller) return {smaller, larger};
  return {larger, smaller};
}

// The scalar coefficients of psi_s at the angle theta (theta > 0, s in (0, 1]),
// given sin and cos of s theta/2 and (1 - s) theta/2.
template <class Scalar>
struct PsiCoefficients {
  Scalar f1, f2, g1, g2;
};

template <class Scalar>
PsiCoefficients<Scalar> psi_coefficients(const Angle<Scalar>& a, Scalar s,
                                         const SinCos<Scalar>& s_half,
                                         const SinCos<Scalar>& u_half) {
  const Scalar theta = a.theta;
  const Scalar inverse_s_sin = 1 / s_half.sin;
  const Scalar modulus = s * s * a.half.sin * inverse_s_sin;
  // F(i theta) = modulus e^{-i (1 - s) theta / 2}
  const Scalar alpha = modulus * u_half.cos, beta = -modulus * u_half.sin;
  // F'/F = p + i q
  const Scalar p = (s - 1) / 2;
  const Scalar q = -(a.cot_half - s * s_half.cos * inverse_s_sin) / 2;
  const Scalar alpha_d = alpha * p - beta * q, beta_d = alpha * q + beta * p;
  PsiCoefficients<Scalar> c;
  c.f1 = beta * a.inverse;
  c.f2 = (s - alpha) * a.inverse2;
  c.g1 = (theta * alpha_d - beta) * a.inverse3;
  c.g2 = (theta * beta_d - 2 * (s - alpha)) * a.inverse4;
  return c;
}

// (s, f1, f2): the coefficients of I, W and W^2 in F(W) = psi_s(W) on a
// rotation block (all zero at s = 0, where psi_0 = 0).
template <class Scalar>
std::array<Scalar, 3> rotation_block_coefficients(const Angle<Scalar>& a, Scalar s,
                                                  const SinCos<Scalar>& s_half,
                                                  const SinCos<Scalar>& u_half) {
  if (s == 0) return {0, 0, 0};
  const PsiCoefficients<Scalar> c = psi_coefficients(a, s, s_half, u_half);
  return {s, c.f1, c.f2};
}

// The closed forms of SO(2), SO(3), SE(2) and SE(3) are linear in a few
// scalar coefficients of s: psi_s(ad_x) r = sum_k c_k(s) B_k r, with maps
// B_k fixed by x (their ClosedFormPsi::coefficients and ::combine). A sum
// over observations sum_i w_i psi_{s_i}(ad_x) r_i is then
// sum_k B_k (sum_i w_i c_k(s_i) r_i): per observation only the scalars
// c_k and kTerms vector updates, and the B_k applied once per sum. One
// psi_s(ad_x) r is the same with a single term.
template <class Psi, class Prepared, class Scalar, class Tangent>
Tangent apply_by_coefficients(const Prepared& p, Scalar s, const SinCos<Scalar>& s_half,
                              const SinCos<Scalar>& u_half, const Tangent& r) {
  const auto c = Psi::coefficients(p, s, s_half, u_half);
  std::array<Tangent, Psi::kTerms> sums;
  for (int k = 0; k < Psi::kTerms; ++k)
    sums[k] = c[k] * r;
  return Psi::combine(p, sums);
}

}  // namespace psi_closed_form

}  // namespace bireg
