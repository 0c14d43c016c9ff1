// bireg: SO(2), planar rotations, as 2x2 rotation matrices.
//
// Tangent coordinate: the angle theta; hat(theta) = [0 -theta; theta 0].
// The group is commutative, so ad = 0 and Ad = 1: bi-invariant regression on
// SO(2) is least squares on the unwrapped angle.
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/psi_closed_form.hpp"

namespace bireg {

template <class Scalar_ = double>
struct SO2 {
  using Scalar = Scalar_;
  static constexpr int dof = 1;
  static constexpr int matrix_size = 2;
  static constexpr const char* name = "SO2";
  using Element = Eigen::Matrix<Scalar, 2, 2>;
  using Tangent = Eigen::Matrix<Scalar, 1, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, 1, 1>;
  using Algebra = Eigen::Matrix<Scalar, 2, 2>;

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return a * b; }
  static Element inverse(const Element& g) { return g.transpose(); }

  static Element exp(const Tangent& x) {
    using std::cos;
    using std::sin;
    const Scalar c = cos(x[0]);
    const Scalar s = sin(x[0]);
    Element g;
    g << c, -s, s, c;
    return g;
  }

  // Principal logarithm, theta in (-pi, pi]. atan2 of the two entries is
  // accurate to an ulp at every angle, including near 0 and pi.
  static Tangent log(const Element& g) {
    using std::atan2;
    return Tangent(atan2(g(1, 0), g(0, 0)));
  }

  // |theta| of the principal logarithm, in [0, pi] (capabilities.hpp,
  // turn_angle): SO(2) is abelian, so every conjugate has the same angle.
  static Scalar turn_angle(const Element& g) {
    using std::abs;
    using std::atan2;
    return abs(atan2(g(1, 0), g(0, 0)));
  }

  static Algebra hat(const Tangent& x) {
    Algebra m;
    m << Scalar(0), -x[0], x[0], Scalar(0);
    return m;
  }
  static Tangent vee(const Algebra& m) { return Tangent(m(1, 0)); }

  static AdMatrix ad(const Tangent& /*x*/) { return AdMatrix::Zero(); }
  static AdMatrix Ad(const Element& /*g*/) { return AdMatrix::Identity(); }
  static Scalar ad_spectral_radius(const Tangent& /*x*/) { return Scalar(0); }

  // Orthonormal with determinant +1, to within tol (max-norm), and finite.
  static bool is_element(const Element& g, Scalar tol = default_element_tolerance<Scalar>()) {
    using std::abs;
    if (!g.allFinite()) return false;
    const Scalar orthonormality = (g.transpose() * g - Element::Identity()).cwiseAbs().maxCoeff();
    return orthonormality <= tol && abs(g.determinant() - Scalar(1)) <= tol;
  }
  // psi_s(ad_x) r in closed form (math/psi_closed_form.hpp; DESIGN.md section 2,
  // "Exact form"): SO(2) is commutative, ad = 0, so psi_s(0) = s, one term.
  struct ClosedFormPsi {
    using SinCos = psi_closed_form::SinCos<Scalar>;
    struct Prepared {
      Scalar theta = 0;
    };
    static constexpr int kTerms = 1;
    static Scalar angle(const Tangent&) { return Scalar(kExactMinAngle); }  // ad = 0: always exact
    static Prepared prepare(const Tangent&) { return {}; }
    static std::array<Scalar, kTerms> coefficients(const Prepared&, Scalar s, const SinCos&,
                                                   const SinCos&) {
      return {s};
    }
    static Tangent combine(const Prepared&, const std::array<Tangent, kTerms>& sums) {
      return sums[0];
    }
    static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos& u_half,
                         const Tangent& r) {
      return psi_closed_form::apply_by_coefficients<ClosedFormPsi>(p, s, s_half, u_half, r);
    }
  };
};

using SO2d = SO2<double>;
using SO2f = SO2<float>;

}  // namespace bireg
