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
// both free of cancellation for s theta in (0, 2 pi). With F(i theta) =
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

// The scalar coefficients of psi_s at the angle theta (theta > 0, s in (0, 1]).
template <class Scalar>
struct PsiCoefficients {
  Scalar f1, f2, g1, g2;
};

template <class Scalar>
PsiCoefficients<Scalar> psi_coefficients(Scalar theta, Scalar s) {
  using std::cos;
  using std::sin;
  const Scalar half = theta / 2, s_half = s * theta / 2;
  const Scalar modulus = s * s * sin(half) / sin(s_half);
  const Scalar phase = -(1 - s) * half;
  const Scalar alpha = modulus * cos(phase), beta = modulus * sin(phase);
  // F'/F = p + i q
  const Scalar p = (s - 1) / 2;
  const Scalar q = -(cos(half) / sin(half) - s * cos(s_half) / sin(s_half)) / 2;
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
// caches what depends on X only; apply(prepared, s, r) returns psi_s(ad_X) r
// and requires the rotation angle of X to be at least kExactMinAngle (SO(2)
// needs none).
template <class G, class = void>
struct ExactPsi {
  static constexpr bool available = false;
};

template <class Scalar>
struct ExactPsi<SO2<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SO2<Scalar>::Tangent;
  struct Prepared {};
  static Scalar angle(const Tangent&) { return Scalar(kExactMinAngle); }  // ad = 0: always exact
  static Prepared prepare(const Tangent&) { return {}; }
  static Tangent apply(const Prepared&, Scalar s, const Tangent& r) { return s * r; }
};

template <class Scalar>
struct ExactPsi<SO3<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SO3<Scalar>::Tangent;
  struct Prepared {
    Tangent omega;
    Scalar theta;
  };
  static Scalar angle(const Tangent& x) { return x.norm(); }
  static Prepared prepare(const Tangent& x) { return {x, x.norm()}; }
  static Tangent apply(const Prepared& p, Scalar s, const Tangent& r) {
    if (s == 0) return Tangent::Zero();
    const auto c = exact_detail::psi_coefficients(p.theta, s);
    const Tangent w_r = p.omega.cross(r);
    return s * r + c.f1 * w_r + c.f2 * p.omega.cross(w_r);
  }
};

template <class Scalar>
struct ExactPsi<SE2<Scalar>> {
  static constexpr bool available = true;
  using Tangent = typename SE2<Scalar>::Tangent;
  struct Prepared {
    Tangent x;
    Scalar theta;
  };
  static Scalar angle(const Tangent& x) {
    using std::abs;
    return abs(x[2]);
  }
  static Prepared prepare(const Tangent& x) { return {x, x[2]}; }
  static Tangent apply(const Prepared& p, Scalar s, const Tangent& r) {
    using std::abs;
    if (s == 0) return Tangent::Zero();
    // psi is even-odd symmetric: F(-i theta) = conj F(i theta), so the
    // coefficients at |theta| with the sign carried by J theta.
    const Scalar theta = p.theta;
    const auto c = exact_detail::psi_coefficients(abs(theta), s);
    const Scalar re = s - theta * theta * c.f2;  // Re F(i theta)
    const Scalar im = theta * c.f1;              // Im F(i theta), odd in theta
    // c = -J rho (the ad column of the angle), then (f1 I + theta f2 J) c.
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
  struct Prepared {
    Vector3 rho, omega;
    Scalar theta, omega_dot_rho;
  };
  static Scalar angle(const Tangent& x) { return x.template tail<3>().norm(); }
  static Prepared prepare(const Tangent& x) {
    const Vector3 rho = x.template head<3>(), omega = x.template tail<3>();
    return {rho, omega, omega.norm(), omega.dot(rho)};
  }
  static Tangent apply(const Prepared& p, Scalar s, const Tangent& r) {
    if (s == 0) return Tangent::Zero();
    const auto c = exact_detail::psi_coefficients(p.theta, s);
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
      return ExactPsi<G>::apply(ExactPsi<G>::prepare(x), s, r);
    }
  }
  const typename G::AdMatrix a = G::ad(x);
  const int order =
      adaptive_series_order(a, std::numeric_limits<Scalar>::epsilon(), kMaxSeriesOrder).first;
  return apply_psi_series<Scalar, G::dof>(a, s, r, order);
}

}  // namespace bireg
