// bireg: SO(3), 3D rotations, as 3x3 rotation matrices.
//
// Tangent coordinates: the rotation vector omega (axis times angle), with
// hat(omega) the skew matrix such that hat(omega) v = omega x v.
//
// exp is Rodrigues' formula with half-angle coefficients (no cancellation at
// any angle). log goes through a unit quaternion obtained by Shepperd's
// method (the largest of the four candidate components is computed from the
// diagonal, the other three from off-diagonal sums or differences), and the
// angle is 2 atan2(|v|, w). Unlike acos((tr R - 1)/2) or formulas that divide
// by sin(theta), this keeps full relative precision at every angle, including
// theta -> 0 and theta -> pi, and tolerates inputs slightly off the group.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/membership.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/ad_algebra.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/small_angle.hpp"

namespace bireg {

template <class Scalar_ = double>
struct SO3 {
  using Scalar = Scalar_;
  static constexpr int dof = 3;
  static constexpr int matrix_size = 3;
  static constexpr const char* name = "SO3";
  using Element = Eigen::Matrix<Scalar, 3, 3>;
  using Tangent = Eigen::Matrix<Scalar, 3, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, 3, 3>;
  using Algebra = Eigen::Matrix<Scalar, 3, 3>;
  using Quaternion = Eigen::Quaternion<Scalar>;

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return a * b; }
  static Element inverse(const Element& g) { return g.transpose(); }

  // R = I + (sin t / t) W + ((1 - cos t)/t^2) W^2, W = hat(omega), t = |omega|.
  static Element exp(const Tangent& omega) {
    using std::sqrt;
    const Scalar squared_angle = omega.squaredNorm();
    if (!(squared_angle <= std::numeric_limits<Scalar>::max())) return exp_of_huge(omega);
    const RodriguesCoefficients c = rodrigues_coefficients(sqrt(squared_angle));
    return rodrigues(omega, c.sin_over_angle, c.one_minus_cos_over_angle2);
  }

  // An angle whose square overflows (a geodesic evaluated ~1e154 ranges
  // away from its data): the same rotation about the unit axis u, R = I +
  // sin t hat(u) + (1 - cos t) hat(u)^2, which stays a rotation; NaN only
  // for a tangent that is not finite.
  static Element exp_of_huge(const Tangent& omega) {
    using std::cos;
    using std::sin;
    if (!omega.allFinite()) return Element::Constant(std::numeric_limits<Scalar>::quiet_NaN());
    const Scalar angle = omega.stableNorm();
    const Tangent axis = omega / angle;
    return rodrigues(axis, sin(angle), Scalar(1) - cos(angle));
  }

  // With h = t/2: sin t / t = sinc(h) cos(h) and (1 - cos t)/t^2 = sinc(h)^2/2,
  // so one sin/cos pair of the half angle gives both, without cancellation
  // (sin and cos side by side, so that the compiler makes one sincos call).
  struct RodriguesCoefficients {
    Scalar sin_over_angle, one_minus_cos_over_angle2;
  };
  static RodriguesCoefficients rodrigues_coefficients(Scalar angle) {
    using std::cos;
    using std::sin;
    const Scalar half_angle = angle / Scalar(2);
    const Scalar sin_half = sin(half_angle), cos_half = cos(half_angle);
    const Scalar sinc_half = half_angle < small_angle::tiny_angle<Scalar>()
                                 ? small_angle::sin_over_x(half_angle)
                                 : sin_half / half_angle;
    return {sinc_half * cos_half, sinc_half * sinc_half / Scalar(2)};
  }

  // I + a W + b W^2, W = hat(omega), entry by entry: W^2 = omega omega^T -
  // |omega|^2 I, whose diagonal is -(the other two squares), so no entry is
  // formed by cancellation and no 3 x 3 product is needed. exp's matrix for
  // a = sin t / t, b = (1 - cos t)/t^2; SE(3)'s exp calls it with the
  // coefficients it shares with its translation part.
  static Element rodrigues(const Tangent& omega, Scalar a, Scalar b) {
    const Tangent square = omega.cwiseAbs2();
    const Scalar b01 = b * omega[0] * omega[1], b02 = b * omega[0] * omega[2],
                 b12 = b * omega[1] * omega[2];
    const Tangent a_omega = a * omega;
    Element r;
    r << Scalar(1) - b * (square[1] + square[2]), b01 - a_omega[2], b02 + a_omega[1],
        b01 + a_omega[2], Scalar(1) - b * (square[0] + square[2]), b12 - a_omega[0],
        b02 - a_omega[1], b12 + a_omega[0], Scalar(1) - b * (square[0] + square[1]);
    return r;
  }

  // Unit quaternion (w >= 0) of a rotation matrix by Shepperd's method: the
  // largest of |w|, |x|, |y|, |z| is computed from the diagonal, the other
  // three from sums or differences of off-diagonal pairs (4 q_a q_b is
  // linear in r for every pair), so no component is formed by cancellation.
  // For a matrix slightly off SO(3) the result is not exactly unit; log()
  // only uses ratios of its components, so that does not matter there.
  static Quaternion to_quaternion(const Element& r) {
    using std::sqrt;
    const Scalar trace = r(0, 0) + r(1, 1) + r(2, 2);
    Scalar w, x, y, z;
    if (trace >= r(0, 0) && trace >= r(1, 1) && trace >= r(2, 2)) {
      const Scalar four_w = Scalar(2) * sqrt(Scalar(1) + trace);
      w = four_w / Scalar(4);
      x = (r(2, 1) - r(1, 2)) / four_w;
      y = (r(0, 2) - r(2, 0)) / four_w;
      z = (r(1, 0) - r(0, 1)) / four_w;
    } else if (r(0, 0) >= r(1, 1) && r(0, 0) >= r(2, 2)) {
      const Scalar four_x = Scalar(2) * sqrt(Scalar(1) + r(0, 0) - r(1, 1) - r(2, 2));
      w = (r(2, 1) - r(1, 2)) / four_x;
      x = four_x / Scalar(4);
      y = (r(0, 1) + r(1, 0)) / four_x;
      z = (r(0, 2) + r(2, 0)) / four_x;
    } else if (r(1, 1) >= r(2, 2)) {
      const Scalar four_y = Scalar(2) * sqrt(Scalar(1) - r(0, 0) + r(1, 1) - r(2, 2));
      w = (r(0, 2) - r(2, 0)) / four_y;
      x = (r(0, 1) + r(1, 0)) / four_y;
      y = four_y / Scalar(4);
      z = (r(1, 2) + r(2, 1)) / four_y;
    } else {
      const Scalar four_z = Scalar(2) * sqrt(Scalar(1) - r(0, 0) - r(1, 1) + r(2, 2));
      w = (r(1, 0) - r(0, 1)) / four_z;
      x = (r(0, 2) + r(2, 0)) / four_z;
      y = (r(1, 2) + r(2, 1)) / four_z;
      z = four_z / Scalar(4);
    }
    return w < Scalar(0) ? Quaternion(-w, -x, -y, -z) : Quaternion(w, x, y, z);
  }

  // The rotation of a quaternion, normalised first (q must not be zero).
  static Element from_quaternion(const Quaternion& q) { return q.normalized().toRotationMatrix(); }

  // Principal logarithm: |omega| in [0, pi]. At exactly pi both +-omega are
  // logarithms; the one with the sign of the chosen quaternion is returned.
  // Below pi/2 from the antisymmetric part of r (first branch); otherwise
  // omega = (theta / |v|) v with theta = 2 atan2(|v|, w). For w > |v|
  // (angles below pi/2) theta/|v| = (2/w) atan(y)/y with y = |v|/w, whose
  // series covers |v| -> 0 without forming |v| (no underflow at 1e-300).
  static Tangent log(const Element& r) {
    using std::atan2;
    using std::sqrt;
    const Scalar trace = r(0, 0) + r(1, 1) + r(2, 2);
    if (trace > Scalar(1)) {
      // Angle below pi/2 (trace = 1 + 2 cos theta): the antisymmetric part
      // d = 2 sin(theta) axis has no cancellation, 1 + trace = 4 cos^2(theta/2)
      // >= 2, y = |d| / (1 + trace) = tan(theta/2), and
      // omega = theta d / |d| = (2 / (1 + trace)) (atan(y) / y) d: the
      // quaternion route's w > |v| branch below in fewer dependent steps
      // (no square root of 1 + trace, no division by w).
      const Tangent d(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
      const Scalar one_plus_trace = Scalar(1) + trace;
      const Scalar y = sqrt(d.squaredNorm()) / one_plus_trace;
      return (Scalar(2) / one_plus_trace * small_angle::atan_over_y(y)) * d;
    }
    const Quaternion q = to_quaternion(r);
    const Scalar w = q.w();
    const Tangent v = q.vec();
    const Scalar v_norm2 = v.squaredNorm();
    if (w * w > v_norm2) {
      const Scalar y = sqrt(v_norm2) / w;
      return (Scalar(2) / w * small_angle::atan_over_y(y)) * v;
    }
    const Scalar v_norm = sqrt(v_norm2);
    return (Scalar(2) * atan2(v_norm, w) / v_norm) * v;
  }

  // The rotation angle of r, in [0, pi] (capabilities.hpp, turn_angle):
  // atan2(sin theta, cos theta) from the antisymmetric part
  // |vee(r - r^T)| = 2 sin theta and the trace 1 + 2 cos theta, accurate at
  // every angle. Invariant under conjugation, r -> q r q^T.
  static Scalar turn_angle(const Element& r) {
    using std::atan2;
    using std::sqrt;
    const Tangent d(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
    const Scalar trace = r(0, 0) + r(1, 1) + r(2, 2);
    return atan2(sqrt(d.squaredNorm()), trace - Scalar(1));
  }

  static Algebra hat(const Tangent& omega) {
    Algebra m;
    m << Scalar(0), -omega[2], omega[1], omega[2], Scalar(0), -omega[0], -omega[1], omega[0],
        Scalar(0);
    return m;
  }
  static Tangent vee(const Algebra& m) { return Tangent(m(2, 1), m(0, 2), m(1, 0)); }

  // [hat a, hat b] = hat(a x b), so ad_a = hat(a); Ad_R = R.
  static AdMatrix ad(const Tangent& omega) { return hat(omega); }
  static AdMatrix Ad(const Element& r) { return r; }

  // ad_omega has eigenvalues 0 and +-i|omega|.
  static Scalar ad_spectral_radius(const Tangent& omega) {
    using std::sqrt;
    return sqrt(omega.squaredNorm());
  }

  // Right Jacobian of exp (groups/capabilities.hpp):
  //   J_r(omega)      = I - ((1 - cos t)/t^2) W + ((t - sin t)/t^3) W^2,
  //   J_r(omega)^{-1} = I + W/2 + ((1 - (t/2) cot(t/2))/t^2) W^2,
  // W = hat(omega), t = |omega|; the inverse exists for t < 2 pi.
  // The coefficients are series in t^2 below t = 2 (small_angle.hpp), so
  // the usual short arguments take neither a square root nor a sine; W^2 is
  // formed entry by entry as in rodrigues().
  static AdMatrix right_jacobian(const Tangent& omega) {
    const Scalar squared_angle = omega.squaredNorm();
    return AdMatrix::Identity() -
           small_angle::one_minus_cos_over_x2_from_square(squared_angle) * hat(omega) +
           small_angle::x_minus_sin_over_x3_from_square(squared_angle) * hat_squared(omega);
  }
  static AdMatrix right_jacobian_inverse(const Tangent& omega) {
    return AdMatrix::Identity() + hat(omega) / Scalar(2) +
           small_angle::one_minus_half_x_cot_half_x_over_x2_from_square(omega.squaredNorm()) *
               hat_squared(omega);
  }
  // Both at once: W, W^2 and the squared angle are shared.
  static RightJacobianPair<AdMatrix> right_jacobian_pair(const Tangent& omega) {
    const Scalar squared_angle = omega.squaredNorm();
    const Algebra w = hat(omega);
    const Algebra w2 = hat_squared(omega);
    return {AdMatrix::Identity() -
                small_angle::one_minus_cos_over_x2_from_square(squared_angle) * w +
                small_angle::x_minus_sin_over_x3_from_square(squared_angle) * w2,
            AdMatrix::Identity() + w / Scalar(2) +
                small_angle::one_minus_half_x_cot_half_x_over_x2_from_square(squared_angle) * w2};
  }
  // hat(omega)^2 = omega omega^T - |omega|^2 I, whose diagonal is -(the
  // other two squares): no 3 x 3 product and no cancellation.
  static Algebra hat_squared(const Tangent& omega) {
    const Tangent square = omega.cwiseAbs2();
    const Scalar w01 = omega[0] * omega[1], w02 = omega[0] * omega[2], w12 = omega[1] * omega[2];
    Algebra w2;
    w2 << -(square[1] + square[2]), w01, w02, w01, -(square[0] + square[2]), w12, w02, w12,
        -(square[0] + square[1]);
    return w2;
  }

  // The algebra of functions of ad_omega = W (math/ad_algebra.hpp), with
  // W^2 = omega omega^T - theta^2 I; N1 = N2 = 0 and kappa = 0 here.
  static AdAlgebraBasis<AdMatrix> ad_algebra_basis(const Tangent& omega) {
    using std::sqrt;
    AdAlgebraBasis<AdMatrix> basis;
    basis.theta2 = omega.squaredNorm();
    basis.theta = sqrt(basis.theta2);
    basis.a = hat(omega);
    basis.a2 = hat_squared(omega);
    basis.n1 = basis.n2 = AdMatrix::Zero();
    return basis;
  }

  // Orthonormal with determinant +1, to within tol (max-norm), and finite.
  static bool is_element(const Element& r, Scalar tol = default_element_tolerance<Scalar>()) {
    return is_rotation(r, tol);
  }

  // The same for any 3 x 3 expression (SE(3)'s rotation block, read in
  // place): the nine entries go to membership_detail::rotation_within
  // (groups/membership.hpp), the straight-line arithmetic that
  // first_non_element's block loop also evaluates. Its seven tests, R^T R -
  // I by the columns' dot products and det R - 1 = c0 . (c1 x c2) - 1, are
  // combined without branches: a NaN or an infinity anywhere makes a
  // departure NaN or infinite and its test false, so finiteness needs no
  // scan of its own unless tol is infinite.
  template <class Derived>
  static bool is_rotation(const Eigen::MatrixBase<Derived>& r, Scalar tol) {
    EIGEN_STATIC_ASSERT_MATRIX_SPECIFIC_SIZE(Derived, 3, 3)
    using std::abs;
    const bool within = membership_detail::rotation_within<Scalar>(
        r(0, 0), r(1, 0), r(2, 0), r(0, 1), r(1, 1), r(2, 1), r(0, 2), r(1, 2), r(2, 2), tol);
    // An infinite tol passes an infinite departure: then finiteness is
    // checked apart.
    const bool finite_tolerance = abs(tol) <= std::numeric_limits<Scalar>::max();
    return within && (finite_tolerance || r.allFinite());
  }

  // psi_s(ad_x) r in closed form (math/psi_closed_form.hpp; DESIGN.md section 2,
  // "Exact form"): F(W) v = s v + f1 W v + f2 W^2 v, W = hat(omega), i.e. the
  // coefficients (s, f1, f2) of the maps (I, W, W^2). The angle must be at
  // least kExactMinAngle; the regression uses the series below.
  struct ClosedFormPsi {
    using SinCos = psi_closed_form::SinCos<Scalar>;
    struct Prepared {
      Tangent omega;
      Scalar theta;
      psi_closed_form::Angle<Scalar> angle;
    };
    static constexpr int kTerms = 3;
    static Scalar angle(const Tangent& x) { return x.norm(); }
    static Prepared prepare(const Tangent& x) {
      const Scalar theta = x.norm();
      return {x, theta, psi_closed_form::Angle<Scalar>::of(theta)};
    }
    static std::array<Scalar, kTerms> coefficients(const Prepared& p, Scalar s,
                                                   const SinCos& s_half, const SinCos& u_half) {
      return psi_closed_form::rotation_block_coefficients(p.angle, s, s_half, u_half);
    }
    static Tangent combine(const Prepared& p, const std::array<Tangent, kTerms>& sums) {
      return sums[0] + p.omega.cross(sums[1] + p.omega.cross(sums[2]));
    }
    // exp(t x), t >= 0, from sin and cos of t theta/2 (the force's half-angle
    // pair): on the unscaled omega, Rodrigues' coefficients are
    // sin(t theta)/theta = 2 sin cos / theta and (1 - cos(t theta))/theta^2 =
    // 2 sin^2 / theta^2, free of cancellation and exact at t = 0.
    static Element exp(const Prepared& p, Scalar, const SinCos& t_half) {
      return rodrigues(p.omega, 2 * t_half.sin * t_half.cos * p.angle.inverse,
                       2 * t_half.sin * t_half.sin * p.angle.inverse2);
    }
    static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                         const Tangent& r) {
      return psi_closed_form::apply_by_coefficients<ClosedFormPsi>(p, s, s_half, u_half, r);
    }
  };
};

using SO3d = SO3<double>;
using SO3f = SO3<float>;

}  // namespace bireg
