// bireg: SE(2), planar rigid motions, as 3x3 homogeneous matrices [R t; 0 1].
//
// Tangent coordinates, translation first: x = (rho_x, rho_y, theta), with
// hat(x) = [theta J  rho; 0 0], J = [0 -1; 1 0].
//
// exp: R = R(theta), t = V(theta) rho, V = (sin th/th) I + ((1 - cos th)/th) J.
// log: theta = atan2, rho = V^{-1} t with
//      V^{-1} = (th/2) cot(th/2) I - (th/2) J,
// both free of cancellation (small_angle.hpp).
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "bireg/groups/affine.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/small_angle.hpp"

namespace bireg {

template <class Scalar_ = double>
struct SE2 {
  using Scalar = Scalar_;
  static constexpr int dof = 3;
  static constexpr int matrix_size = 3;
  static constexpr const char* name = "SE2";
  using Element = Eigen::Matrix<Scalar, 3, 3>;
  using Tangent = Eigen::Matrix<Scalar, 3, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, 3, 3>;
  using Algebra = Eigen::Matrix<Scalar, 3, 3>;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using Matrix2 = Eigen::Matrix<Scalar, 2, 2>;

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return affine::compose(a, b); }
  static Element inverse(const Element& g) {
    Element inv = Element::Identity();
    const Matrix2 rt = g.template topLeftCorner<2, 2>().transpose();
    inv.template topLeftCorner<2, 2>() = rt;
    inv.template topRightCorner<2, 1>() = -rt * g.template topRightCorner<2, 1>();
    return inv;
  }

  static Element exp(const Tangent& x) {
    using std::cos;
    using std::sin;
    const Scalar theta = x[2];
    const Scalar c = cos(theta);
    const Scalar s = sin(theta);
    const Scalar a = small_angle::sin_over_x(theta);                     // sin th / th
    const Scalar b = theta * small_angle::one_minus_cos_over_x2(theta);  // (1 - cos th) / th
    Element g = Element::Identity();
    g(0, 0) = c;
    g(0, 1) = -s;
    g(1, 0) = s;
    g(1, 1) = c;
    g(0, 2) = a * x[0] - b * x[1];
    g(1, 2) = b * x[0] + a * x[1];
    return g;
  }

  // Principal logarithm, theta in (-pi, pi].
  static Tangent log(const Element& g) {
    using std::atan2;
    const Scalar theta = atan2(g(1, 0), g(0, 0));
    const Scalar diagonal = small_angle::half_x_cot_half_x(theta);
    const Scalar half_theta = theta / Scalar(2);
    const Scalar tx = g(0, 2);
    const Scalar ty = g(1, 2);
    return Tangent(diagonal * tx + half_theta * ty, -half_theta * tx + diagonal * ty, theta);
  }

  // The angle of the rotation block, in [0, pi] (capabilities.hpp,
  // turn_angle): conjugation by (R, t) leaves it unchanged.
  static Scalar turn_angle(const Element& g) {
    using std::abs;
    using std::atan2;
    return abs(atan2(g(1, 0), g(0, 0)));
  }

  static Algebra hat(const Tangent& x) {
    Algebra m = Algebra::Zero();
    m(0, 1) = -x[2];
    m(1, 0) = x[2];
    m(0, 2) = x[0];
    m(1, 2) = x[1];
    return m;
  }
  static Tangent vee(const Algebra& m) { return Tangent(m(0, 2), m(1, 2), m(1, 0)); }

  // [x, y] = (theta_x J rho_y - theta_y J rho_x, 0), so
  // ad_x = [theta J  -J rho; 0 0].
  static AdMatrix ad(const Tangent& x) {
    AdMatrix m = AdMatrix::Zero();
    m(0, 1) = -x[2];
    m(1, 0) = x[2];
    m(0, 2) = x[1];
    m(1, 2) = -x[0];
    return m;
  }

  // ad_x has eigenvalues 0 and +-i theta.
  static Scalar ad_spectral_radius(const Tangent& x) {
    using std::abs;
    return abs(x[2]);
  }

  // g hat(x) g^{-1} = hat(R rho - theta J t, theta): Ad_g = [R  -J t; 0 1].
  static AdMatrix Ad(const Element& g) {
    AdMatrix m = AdMatrix::Zero();
    m.template topLeftCorner<2, 2>() = g.template topLeftCorner<2, 2>();
    m(0, 2) = g(1, 2);
    m(1, 2) = -g(0, 2);
    m(2, 2) = Scalar(1);
    return m;
  }

  // Rotation block orthonormal with determinant +1 and last row (0, 0, 1),
  // to within tol (max-norm), all finite.
  static bool is_element(const Element& g, Scalar tol = default_element_tolerance<Scalar>()) {
    using std::abs;
    if (!g.allFinite()) return false;
    const Matrix2 r = g.template topLeftCorner<2, 2>();
    const Scalar orthonormality = (r.transpose() * r - Matrix2::Identity()).cwiseAbs().maxCoeff();
    const Scalar last_row =
        (g.template bottomRows<1>() - Eigen::Matrix<Scalar, 1, 3>(0, 0, 1)).cwiseAbs().maxCoeff();
    return orthonormality <= tol && abs(r.determinant() - Scalar(1)) <= tol && last_row <= tol;
  }
  // psi_s(ad_x) r in closed form (math/psi_closed_form.hpp; DESIGN.md section 2,
  // "Exact form"): the rotation part as on SO(2) rotated by F(i theta) =
  // (s - theta^2 f2) + i theta f1, the angle's column c = -J rho mapped by
  // f1 I + theta f2 J; i.e. the coefficients (s, f1, f2) of the maps
  //   I,   [theta J, c; 0, 0],   [-theta^2 I, theta J c; 0, 0]
  // (F(-i theta) = conj F(i theta): the coefficients at |theta|, the sign
  // carried by the signed angle). Angle at least kExactMinAngle.
  struct ClosedFormPsi {
    using SinCos = psi_closed_form::SinCos<Scalar>;
    struct Prepared {
      Tangent x;
      Scalar theta;  // |theta|; the sign is carried by x[2]
      psi_closed_form::Angle<Scalar> angle;
    };
    static constexpr int kTerms = 3;
    static Scalar angle(const Tangent& x) {
      using std::abs;
      return abs(x[2]);
    }
    static Prepared prepare(const Tangent& x) {
      using std::abs;
      return {x, abs(x[2]), psi_closed_form::Angle<Scalar>::of(abs(x[2]))};
    }
    static std::array<Scalar, kTerms> coefficients(const Prepared& p, Scalar s,
                                                   const SinCos& s_half, const SinCos& u_half) {
      return psi_closed_form::rotation_block_coefficients(p.angle, s, s_half, u_half);
    }
    static Tangent combine(const Prepared& p, const std::array<Tangent, kTerms>& sums) {
      const Scalar theta = p.x[2];
      const Scalar cx = p.x[1], cy = -p.x[0];  // c = -J rho
      const Tangent& a = sums[0];
      const Tangent& b = sums[1];
      const Tangent& d = sums[2];
      Tangent out;
      out[0] = a[0] - theta * b[1] + cx * b[2] - theta * theta * d[0] - theta * cy * d[2];
      out[1] = a[1] + theta * b[0] + cy * b[2] - theta * theta * d[1] + theta * cx * d[2];
      out[2] = a[2];
      return out;
    }
    static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                         const Tangent& r) {
      return psi_closed_form::apply_by_coefficients<ClosedFormPsi>(p, s, s_half, u_half, r);
    }
  };
};

using SE2d = SE2<double>;
using SE2f = SE2<float>;

}  // namespace bireg
