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

// What psi_s at angle theta needs: the half angle theta/2 (per X), and
// s theta/2 and (1 - s) theta/2 (per observation). The regression evaluates
// psi_t for v1 and psi_{1-t} for v0, which use the same two angles with
// their roles swapped, so each observation costs two sin/cos pairs.
template <class Scalar>
struct Angles {
  Scalar theta;
  SinCos<Scalar> half, s_half, u_half;  // theta/2, s theta/2, (1 - s) theta/2
};

// The scalar coefficients of psi_s at the angle theta (theta > 0, s in (0, 1]).
template <class Scalar>
struct PsiCoefficients {
  Scalar f1, f2, g1, g2;
};

template <class Scalar>
PsiCoefficients<Scalar> psi_coefficients(const Angles<Scalar>& a, Scalar s) {
  const Scalar theta = a.theta;
  const Scalar modulus = s * s * a.half.sin / a.s_half.sin;
  // F(i theta) = modulus e^{-i (1 - s) theta / 2}
  const Scalar alpha = modulus * a.u_half.cos, beta = -modulus * a.u_half.sin;
  // F'/F = p + i q
  const Scalar p = (s - 1) / 2;
  const Scalar q = -(a.half.cos / a.half.sin - s * a.s_half.cos / a.s_half.sin) / 2;
  const Scalar alpha_d = alpha * p - beta * q, beta_d = alpha * q + beta * p;
  const Scalar theta2 = theta * theta;
  PsiCoefficients<Scalar> c;
  c.f1 = beta / theta;
  c.f2 = (s - alpha) / theta2;
  c.g1 = (theta * alpha_d - beta) / (theta2 * theta);
  c.g2 = (theta * beta_d - 2 * (s - alpha)) / (theta2 * theta2);
  return c;
}

}  // namespace psi_closed_form

}  // namespace bireg
