// bireg: R^N under addition, the commutative sanity case.
//
// Elements and tangent vectors are both N-vectors; exp and log are the
// identity map and ad = 0, so bi-invariant geodesic regression on R^N is
// ordinary (weighted) least squares of a straight line.
#pragma once

#include <Eigen/Core>

#include "bireg/groups/capabilities.hpp"

namespace bireg {

template <int N, class Scalar_ = double>
struct Rn {
  static_assert(N >= 1, "Rn<N>: N must be at least 1");
  using Scalar = Scalar_;
  static constexpr int dof = N;
  static constexpr const char* name = "Rn";
  using Element = Eigen::Matrix<Scalar, N, 1>;
  using Tangent = Eigen::Matrix<Scalar, N, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, N, N>;
  // The Lie algebra of R^N represented as the translation part of the
  // (N+1)x(N+1) matrix [0 x; 0 0], so that [hat x, hat y] = 0 as it must.
  using Algebra = Eigen::Matrix<Scalar, N + 1, N + 1>;

  static Element identity() { return Element::Zero(); }
  static Element compose(const Element& a, const Element& b) { return a + b; }
  static Element inverse(const Element& g) { return -g; }
  static Element exp(const Tangent& x) { return x; }
  static Tangent log(const Element& g) { return g; }

  static Algebra hat(const Tangent& x) {
    Algebra m = Algebra::Zero();
    m.template topRightCorner<N, 1>() = x;
    return m;
  }
  static Tangent vee(const Algebra& m) { return m.template topRightCorner<N, 1>(); }

  static AdMatrix ad(const Tangent& /*x*/) { return AdMatrix::Zero(); }
  static AdMatrix Ad(const Element& /*g*/) { return AdMatrix::Identity(); }
  static Scalar ad_spectral_radius(const Tangent& /*x*/) { return Scalar(0); }

  static bool is_element(const Element& g, Scalar /*tol*/ = Scalar(0)) { return g.allFinite(); }
};

template <int N>
using Rnd = Rn<N, double>;
template <int N>
using Rnf = Rn<N, float>;

}  // namespace bireg
