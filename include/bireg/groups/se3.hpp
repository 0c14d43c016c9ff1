// bireg: SE(3), rigid motions, as 4x4 homogeneous matrices [R t; 0 1].
//
// Tangent coordinates, translation first: xi = (rho, omega), with
// hat(xi) = [hat(omega) rho; 0 0] (the order of Sophus and manif).
//
// exp: R = exp_SO3(omega), t = V rho,
//      V = I + ((1 - cos th)/th^2) W + ((th - sin th)/th^3) W^2;
// log: omega = log_SO3(R), rho = V^{-1} t,
//      V^{-1} = I - W/2 + ((1 - (th/2) cot(th/2))/th^2) W^2,
// with W = hat(omega), th = |omega|. All three coefficients are evaluated
// without cancellation (small_angle.hpp); V is applied with cross products.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include "bireg/groups/affine.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/membership.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/small_angle.hpp"

namespace bireg {

template <class Scalar_ = double>
struct SE3 {
  using Scalar = Scalar_;
  static constexpr int dof = 6;
  static constexpr int matrix_size = 4;
  static constexpr const char* name = "SE3";
  using Element = Eigen::Matrix<Scalar, 4, 4>;
  using Tangent = Eigen::Matrix<Scalar, 6, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, 6, 6>;
  using Algebra = Eigen::Matrix<Scalar, 4, 4>;
  using Rotation = SO3<Scalar>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return affine::compose(a, b); }
  static Element inverse(const Element& g) {
    Element inv = Element::Identity();
    const Matrix3 rt = g.template topLeftCorner<3, 3>().transpose();
    inv.template topLeftCorner<3, 3>() = rt;
    inv.template topRightCorner<3, 1>() = -rt * g.template topRightCorner<3, 1>();
    return inv;
  }

  static Element exp(const Tangent& xi) {
    using std::sqrt;
    const Vector3 rho = xi.template head<3>();
    const Vector3 omega = xi.template tail<3>();
    const Scalar theta = sqrt(omega.squaredNorm());
    // SO(3)'s coefficients, (1 - cos t)/t^2 shared with the translation.
    const typename Rotation::RodriguesCoefficients rotation =
        Rotation::rodrigues_coefficients(theta);
    const Scalar b = rotation.one_minus_cos_over_angle2;
    const Scalar c = small_angle::x_minus_sin_over_x3(theta);
    const Vector3 w_rho = omega.cross(rho);
    Element g = Element::Identity();
    g.template topLeftCorner<3, 3>() = Rotation::rodrigues(omega, rotation.sin_over_angle, b);
    g.template topRightCorner<3, 1>() = rho + b * w_rho + c * omega.cross(w_rho);
    return g;
  }

  // The angle of the rotation block, in [0, pi] (capabilities.hpp,
  // turn_angle): conjugation by (R, t) conjugates the block by R.
  static Scalar turn_angle(const Element& g) {
    return Rotation::turn_angle(g.template topLeftCorner<3, 3>());
  }

  // Principal logarithm: |omega| in [0, pi].
  static Tangent log(const Element& g) {
    const Vector3 omega = Rotation::log(g.template topLeftCorner<3, 3>());
    const Vector3 t = g.template topRightCorner<3, 1>();
    const Scalar e =
        small_angle::one_minus_half_x_cot_half_x_over_x2_from_square(omega.squaredNorm());
    const Vector3 w_t = omega.cross(t);
    Tangent xi;
    xi.template head<3>() = t - w_t / Scalar(2) + e * omega.cross(w_t);
    xi.template tail<3>() = omega;
    return xi;
  }

  static Algebra hat(const Tangent& xi) {
    Algebra m = Algebra::Zero();
    m.template topLeftCorner<3, 3>() = Rotation::hat(xi.template tail<3>());
    m.template topRightCorner<3, 1>() = xi.template head<3>();
    return m;
  }
  static Tangent vee(const Algebra& m) {
    Tangent xi;
    xi.template head<3>() = m.template topRightCorner<3, 1>();
    xi.template tail<3>() = Rotation::vee(m.template topLeftCorner<3, 3>());
    return xi;
  }

  // [xi_1, xi_2] = (w1 x rho2 - w2 x rho1, w1 x w2), so
  // ad_xi = [hat(omega) hat(rho); 0 hat(omega)].
  static AdMatrix ad(const Tangent& xi) {
    return block_triangular(Rotation::hat(xi.template tail<3>()),
                            Rotation::hat(xi.template head<3>()));
  }

  // ad_xi is block triangular with hat(omega) twice on the diagonal: its
  // eigenvalues are 0 and +-i|omega|, each twice.
  static Scalar ad_spectral_radius(const Tangent& xi) {
    return Rotation::ad_spectral_radius(xi.template tail<3>());
  }

  // g hat(xi) g^{-1} = hat(R rho + t x (R omega), R omega):
  // Ad_g = [R hat(t) R; 0 R].
  static AdMatrix Ad(const Element& g) {
    const Matrix3 r = g.template topLeftCorner<3, 3>();
    return block_triangular(r, Rotation::hat(g.template topRightCorner<3, 1>()) * r);
  }

  // Right Jacobian of exp (groups/capabilities.hpp). ad_xi = [W P; 0 W] is
  // block triangular with equal diagonal blocks, so for any analytic F,
  // F(ad_xi) = [F(W) L; 0 F(W)] with L the derivative of F(W) along P. For
  // F(z) = z / (1 - e^{-z}) (J_r^{-1}), F(W) = I + W/2 + e(t) W^2 with
  // e(t) = (1 - (t/2) cot(t/2))/t^2, t = |omega|, and t changes by
  // (omega . rho)/t along P, so
  //   L = P/2 + e(t) (W P + P W) + (omega . rho) (e'(t)/t) W^2.
  // J_r itself is the block inverse [J, -J L J; 0, J], J = SO(3)'s J_r.
  static AdMatrix right_jacobian_inverse(const Tangent& xi) {
    return block_triangular(Rotation::right_jacobian_inverse(xi.template tail<3>()),
                            coupling_of_jacobian_inverse(xi));
  }
  static AdMatrix right_jacobian(const Tangent& xi) {
    const Matrix3 j = Rotation::right_jacobian(xi.template tail<3>());
    return block_triangular(j, -j * coupling_of_jacobian_inverse(xi) * j);
  }
  // Both at once: SO(3)'s pair and L are computed once.
  static RightJacobianPair<AdMatrix> right_jacobian_pair(const Tangent& xi) {
    const RightJacobianPair<Matrix3> rotation =
        Rotation::right_jacobian_pair(xi.template tail<3>());
    const Matrix3 coupling = coupling_of_jacobian_inverse(xi);
    return {block_triangular(rotation.jacobian, -rotation.jacobian * coupling * rotation.jacobian),
            block_triangular(rotation.inverse, coupling)};
  }

  // The algebra of functions of ad_xi = [W P; 0 W] (math/ad_algebra.hpp):
  // N1 = [0 W; 0 0], N2 = [0 W^2; 0 0], theta = |omega|, kappa = omega . rho.
  static AdAlgebraBasis<AdMatrix> ad_algebra_basis(const Tangent& xi) {
    using std::sqrt;
    const Vector3 rho = xi.template head<3>(), omega = xi.template tail<3>();
    AdAlgebraBasis<AdMatrix> basis;
    basis.theta2 = omega.squaredNorm();
    basis.theta = sqrt(basis.theta2);
    basis.kappa = omega.dot(rho);
    const Matrix3 w = Rotation::hat(omega), p = Rotation::hat(rho);
    const Matrix3 w2 = omega * omega.transpose() - basis.theta2 * Matrix3::Identity();
    basis.a = block_triangular(w, p);  // ad(xi)
    basis.a2 = block_triangular(w2, w * p + p * w);
    basis.n1 = block_triangular(Matrix3::Zero(), w);
    basis.n2 = block_triangular(Matrix3::Zero(), w2);
    return basis;
  }

  // Rotation block in SO(3) (SO3::is_rotation, read in place), last row
  // (0, 0, 0, 1) to within tol (max-norm) and finite translation
  // (membership_detail::pose_rest_within): the straight-line tests of
  // groups/membership.hpp that first_non_element's block loop evaluates,
  // combined without branches, so that a NaN fails every comparison.
  static bool is_element(const Element& g, Scalar tol = default_element_tolerance<Scalar>()) {
    using std::abs;
    const bool rotation = Rotation::is_rotation(g.template topLeftCorner<3, 3>(), tol);
    const bool rest = membership_detail::pose_rest_within<Scalar>(
        g(0, 3), g(1, 3), g(2, 3), g(3, 0), g(3, 1), g(3, 2), g(3, 3), tol);
    // An infinite tol passes an infinite entry of the last row.
    const bool finite_last_row =
        abs(tol) <= std::numeric_limits<Scalar>::max() || g.template bottomRows<1>().allFinite();
    return rotation & rest & finite_last_row;
  }

  // psi_s(ad_x) r in closed form (math/psi_closed_form.hpp; DESIGN.md section 2,
  // "Exact form"): the diagonal blocks as on SO(3), the upper-right block the
  // derivative of F(W) along P = hat(rho),
  //   F(ad_x) = s I + f1 ad_x + f2 [W^2, W P + P W; 0, W^2]
  //             + (omega . rho) (g1 [0, W; 0, 0] + g2 [0, W^2; 0, 0]),
  // i.e. five coefficients of five maps. Angle at least kExactMinAngle.
  struct ClosedFormPsi {
    using SinCos = psi_closed_form::SinCos<Scalar>;
    struct Prepared {
      Vector3 rho, omega;
      Scalar theta, omega_dot_rho;
      psi_closed_form::Angle<Scalar> angle;
      Vector3 w_rho, w_w_rho;  // W rho, W^2 rho (for exp)
    };
    static constexpr int kTerms = 5;
    static Scalar angle(const Tangent& x) { return x.template tail<3>().norm(); }
    static Prepared prepare(const Tangent& x) {
      const Vector3 rho = x.template head<3>(), omega = x.template tail<3>();
      const Scalar theta = omega.norm();
      const Vector3 w_rho = omega.cross(rho);
      return {rho,
              omega,
              theta,
              omega.dot(rho),
              psi_closed_form::Angle<Scalar>::of(theta),
              w_rho,
              omega.cross(w_rho)};
    }
    static std::array<Scalar, kTerms> coefficients(const Prepared& p, Scalar s,
                                                   const SinCos& s_half, const SinCos& u_half) {
      if (s == 0) return {0, 0, 0, 0, 0};
      const auto c = psi_closed_form::psi_coefficients<Scalar>(p.angle, s, s_half, u_half);
      return {s, c.f1, c.f2, p.omega_dot_rho * c.g1, p.omega_dot_rho * c.g2};
    }
    // sum_k B_k sums[k]: on (a_k, b_k) = (rho, omega) parts of sums[k],
    //   omega part: b0 + W (b1 + W b2),
    //   rho part:   a0 + P b1 + W (a1 + b3 + W (a2 + b4) + P b2) + P W b2.
    static Tangent combine(const Prepared& p, const std::array<Tangent, kTerms>& sums) {
      const auto rho_part = [&](int k) { return sums[k].template head<3>(); };
      const auto omega_part = [&](int k) { return sums[k].template tail<3>(); };
      const Vector3 w_b2 = p.omega.cross(omega_part(2));
      const Vector3 inner = rho_part(1) + omega_part(3) +
                            p.omega.cross(rho_part(2) + omega_part(4)) + p.rho.cross(omega_part(2));
      Tangent out;
      out.template head<3>() =
          rho_part(0) + p.rho.cross(omega_part(1)) + p.omega.cross(inner) + p.rho.cross(w_b2);
      out.template tail<3>() = omega_part(0) + p.omega.cross(omega_part(1) + w_b2);
      return out;
    }
    // exp(t x), t >= 0, from sin and cos of t theta/2 (the force's half-angle
    // pair), as SE3::exp with the angle t theta: on the unscaled omega and
    // rho the coefficients are a = sin(t theta)/theta, b = (1 - cos(t
    // theta))/theta^2 (from the half angle, see SO3::ClosedFormPsi::exp) and
    // c = t^3 (u - sin u)/u^3 at u = t theta, so that
    // exp(t x) = [I + a W + b W^2,  t rho + b W rho + c W^2 rho].
    static Element exp(const Prepared& p, Scalar t, const SinCos& t_half) {
      const Scalar a = 2 * t_half.sin * t_half.cos * p.angle.inverse;
      const Scalar b = 2 * t_half.sin * t_half.sin * p.angle.inverse2;
      const Scalar c = t * t * t * small_angle::x_minus_sin_over_x3(t * p.theta);
      Element g = Element::Identity();
      g.template topLeftCorner<3, 3>() = Rotation::rodrigues(p.omega, a, b);
      g.template topRightCorner<3, 1>() = t * p.rho + b * p.w_rho + c * p.w_w_rho;
      return g;
    }
    static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                         const Tangent& r) {
      return psi_closed_form::apply_by_coefficients<ClosedFormPsi>(p, s, s_half, u_half, r);
    }
  };

 private:
  // [diagonal upper; 0 diagonal]: the shape of ad, Ad and the Jacobians on
  // SE(3), whose 6 x 6 matrices act on (rho, omega).
  static AdMatrix block_triangular(const Matrix3& diagonal, const Matrix3& upper) {
    AdMatrix m = AdMatrix::Zero();
    m.template topLeftCorner<3, 3>() = diagonal;
    m.template bottomRightCorner<3, 3>() = diagonal;
    m.template topRightCorner<3, 3>() = upper;
    return m;
  }

  // L, the upper-right block of J_r^{-1} (see right_jacobian_inverse).
  static Matrix3 coupling_of_jacobian_inverse(const Tangent& xi) {
    using std::sqrt;
    const Vector3 rho = xi.template head<3>(), omega = xi.template tail<3>();
    const Scalar angle = sqrt(omega.squaredNorm());
    const Scalar omega_dot_rho = omega.dot(rho);
    const Scalar e = small_angle::one_minus_half_x_cot_half_x_over_x2(angle);
    const Scalar e_derivative_over_angle =
        small_angle::one_minus_half_x_cot_half_x_over_x2_derivative_over_x(angle);
    // hat(a) hat(b) = b a^T - (a . b) I gives W P + P W and W^2 as outer
    // products, without 3 x 3 matrix products.
    const Matrix3 identity = Matrix3::Identity();
    const Matrix3 w_p_plus_p_w =
        rho * omega.transpose() + omega * rho.transpose() - 2 * omega_dot_rho * identity;
    const Matrix3 w_squared = omega * omega.transpose() - (angle * angle) * identity;
    return Rotation::hat(rho) / Scalar(2) + e * w_p_plus_p_w +
           (omega_dot_rho * e_derivative_over_angle) * w_squared;
  }
};

using SE3d = SE3<double>;
using SE3f = SE3<float>;

}  // namespace bireg
