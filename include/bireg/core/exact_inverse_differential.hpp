// bireg: the weighted inverse differentials psi_s(ad_X) in closed form for
// SO(2), SO(3), SE(2) and SE(3) (DESIGN.md section 2, "Exact form").
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
#include <limits>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "bireg/core/inverse_differential.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"

namespace bireg {

// Rotation angle from which the closed forms are used. Their cancellation
// grows like 1/theta^2 relative to the result: against a long double series
// the SE(3) form is off by 1.4e-15 at theta = 0.1 and 2.2e-14 at 0.01, but
// stays below 6e-16 from 0.3 to pi (tests/test_exact_inverse_differential
// checks 1e-14 densely). Below 0.25 the series needs only ~12 terms
// ((0.25 / 2 pi)^12 < 1e-16).
inline constexpr double kExactMinAngle = 0.25;

namespace exact_detail {

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

}  // namespace exact_detail

// ExactPsi<G>::available tells whether G has a closed form. prepare(x)
// caches what depends on X only; apply(prepared, s, s_half, u_half, r)
// returns psi_s(ad_X) r given sin/cos of s theta/2 and (1 - s) theta/2
// (angles(prepared, s) computes them), and requires the rotation angle of
// X to be at least kExactMinAngle (SO(2) needs none).
template <class G, class = void>
struct ExactPsi {
  static constexpr bool available = false;
};

template <class Scalar>
struct ExactPsi<SO2<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SO2<Scalar>::Tangent;
  using SinCos = exact_detail::SinCos<Scalar>;
  struct Prepared {
    Scalar theta = 0;
    SinCos half{0, 1};
  };
  static Scalar angle(const Tangent&) { return Scalar(kExactMinAngle); }  // ad = 0: always exact
  static Prepared prepare(const Tangent&) { return {}; }
  static Tangent apply(const Prepared&, Scalar s, const SinCos&, const SinCos&, const Tangent& r) {
    return s * r;
  }
};

template <class Scalar>
struct ExactPsi<SO3<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SO3<Scalar>::Tangent;
  using SinCos = exact_detail::SinCos<Scalar>;
  struct Prepared {
    Tangent omega;
    Scalar theta;
    SinCos half;
  };
  static Scalar angle(const Tangent& x) { return x.norm(); }
  static Prepared prepare(const Tangent& x) {
    const Scalar theta = x.norm();
    return {x, theta, SinCos::of(theta / 2)};
  }
  static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                       const Tangent& r) {
    if (s == 0) return Tangent::Zero();
    const auto c = exact_detail::psi_coefficients<Scalar>({p.theta, p.half, s_half, u_half}, s);
    const Tangent w_r = p.omega.cross(r);
    return s * r + c.f1 * w_r + c.f2 * p.omega.cross(w_r);
  }
};

template <class Scalar>
struct ExactPsi<SE2<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SE2<Scalar>::Tangent;
  using SinCos = exact_detail::SinCos<Scalar>;
  struct Prepared {
    Tangent x;
    Scalar theta;  // |theta|; the sign is carried by x[2]
    SinCos half;
  };
  static Scalar angle(const Tangent& x) {
    using std::abs;
    return abs(x[2]);
  }
  static Prepared prepare(const Tangent& x) {
    using std::abs;
    return {x, abs(x[2]), SinCos::of(abs(x[2]) / 2)};
  }
  static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                       const Tangent& r) {
    if (s == 0) return Tangent::Zero();
    // F(-i theta) = conj F(i theta): the coefficients at |theta|, the sign
    // carried by the signed angle.
    const auto c = exact_detail::psi_coefficients<Scalar>({p.theta, p.half, s_half, u_half}, s);
    const Scalar theta = p.x[2];
    const Scalar re = s - theta * theta * c.f2;  // Re F(i theta)
    const Scalar im = theta * c.f1;              // Im F(i theta), odd in theta
    // The angle's ad column is c = -J rho; the block maps it by f1 I + theta f2 J.
    const Scalar cx = p.x[1], cy = -p.x[0];
    const Scalar lx = c.f1 * cx - theta * c.f2 * cy, ly = c.f1 * cy + theta * c.f2 * cx;
    Tangent out;
    out[0] = re * r[0] - im * r[1] + lx * r[2];
    out[1] = im * r[0] + re * r[1] + ly * r[2];
    out[2] = s * r[2];
    return out;
  }
};

template <class Scalar>
struct ExactPsi<SE3<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SE3<Scalar>::Tangent;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using SinCos = exact_detail::SinCos<Scalar>;
  struct Prepared {
    Vector3 rho, omega;
    Scalar theta, omega_dot_rho;
    SinCos half;
  };
  static Scalar angle(const Tangent& x) { return x.template tail<3>().norm(); }
  static Prepared prepare(const Tangent& x) {
    const Vector3 rho = x.template head<3>(), omega = x.template tail<3>();
    const Scalar theta = omega.norm();
    return {rho, omega, theta, omega.dot(rho), SinCos::of(theta / 2)};
  }
  static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                       const Tangent& r) {
    if (s == 0) return Tangent::Zero();
    const auto c = exact_detail::psi_coefficients<Scalar>({p.theta, p.half, s_half, u_half}, s);
    const Vector3 r_rho = r.template head<3>(), r_omega = r.template tail<3>();
    const auto rotation_block = [&](const Vector3& v) {
      const Vector3 w_v = p.omega.cross(v);
      return Vector3(s * v + c.f1 * w_v + c.f2 * p.omega.cross(w_v));
    };
    const Vector3 w_v = p.omega.cross(r_omega);
    const Vector3 p_v = p.rho.cross(r_omega);
    const Vector3 derivative = c.f1 * p_v + c.f2 * (p.omega.cross(p_v) + p.rho.cross(w_v)) +
                               p.omega_dot_rho * (c.g1 * w_v + c.g2 * p.omega.cross(w_v));
    Tangent out;
    out.template head<3>() = rotation_block(r_rho) + derivative;
    out.template tail<3>() = rotation_block(r_omega);
    return out;
  }
};

// psi_s(ad_x) r as Method::exact evaluates it: the closed form from
// kExactMinAngle on, below it (and for groups without a closed form) the
// series truncated adaptively below epsilon.
template <class G>
typename G::Tangent apply_psi_exact(const typename G::Tangent& x, typename G::Scalar s,
                                    const typename G::Tangent& r) {
  using Scalar = typename G::Scalar;
  if constexpr (ExactPsi<G>::available) {
    if (ExactPsi<G>::angle(x) >= static_cast<Scalar>(kExactMinAngle)) {
      using SinCos = exact_detail::SinCos<Scalar>;
      const auto prepared = ExactPsi<G>::prepare(x);
      return ExactPsi<G>::apply(prepared, s, SinCos::of(s * prepared.theta / 2),
                                SinCos::of((1 - s) * prepared.theta / 2), r);
    }
  }
  const typename G::AdMatrix a = G::ad(x);
  const int order =
      adaptive_series_order(a, std::numeric_limits<Scalar>::epsilon(), kMaxSeriesOrder).first;
  return apply_psi_series<Scalar, G::dof>(a, s, r, order);
}

}  // namespace bireg
