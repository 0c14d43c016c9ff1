// bireg: any matrix Lie group, given a basis of its Lie algebra.
//
//   MatrixGroup<N, Basis, Scalar>: elements are N x N matrices, tangent
//   coordinates are the coefficients in Basis; exp and log are Eigen's matrix
//   exponential and principal matrix logarithm (unsupported/MatrixFunctions,
//   shipped with libeigen3-dev), ad comes from commutators of the basis and
//   Ad from conjugation.
//
// A Basis is a struct with
//   static constexpr int dof;                       // dimension of the algebra
//   static constexpr const char* name;
//   template <class S> static Eigen::Matrix<S, N, N> generator(int k);   // k < dof
//   template <class S> static bool is_element(const Eigen::Matrix<S, N, N>&, S tol);
// and optionally `static constexpr bool log_everywhere` (below)
// (see HeisenbergBasis, SL3Basis, GLBasis below: a dozen lines each).
//
// Domain of log: the principal matrix logarithm exists for matrices with no
// eigenvalue on the closed negative real axis; there it is the unique
// logarithm whose eigenvalues have imaginary parts in (-pi, pi). Outside it
// (a rotation by pi inside SL(3), a negative eigenvalue) Eigen returns the
// real part of a complex logarithm, which is no logarithm of the input at
// all. MatrixGroup::log therefore checks exp(log g) = g (to sqrt(epsilon)
// relative; outside the domain the mismatch is O(1)) and returns a tangent
// of NaN when it fails. GeodesicRegression turns that into a status: data
// that leave the domain as seen from their middle observation are
// invalid_input (naming the observation); an iterate that leaves it stops
// the fit with diverged and the last finite endpoints. A basis whose group
// has a logarithm everywhere (unipotent groups such as Heisenberg) may
// declare `static constexpr bool log_everywhere = true;` to skip the check.
// Prefer the closed-form groups (SO3, SE3, Sim3, ...) where they exist: they
// are exact to rounding and much faster.
//
// The matrix functions allocate internally (dynamic Schur decompositions),
// so fits on a MatrixGroup are not allocation-free, unlike the closed-form
// groups.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

#include "bireg/groups/tolerance.hpp"

namespace bireg {

template <int N, class Basis, class Scalar_ = double>
struct MatrixGroup {
  using Scalar = Scalar_;
  static constexpr int dof = Basis::dof;
  static constexpr int matrix_size = N;
  static constexpr const char* name = Basis::name;
  using Element = Eigen::Matrix<Scalar, N, N>;
  using Tangent = Eigen::Matrix<Scalar, dof, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, dof, dof>;
  using Algebra = Eigen::Matrix<Scalar, N, N>;

  static Algebra generator(int k) { return Basis::template generator<Scalar>(k); }

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return a * b; }
  static Element inverse(const Element& g) { return g.inverse(); }

  static Element exp(const Tangent& x) { return Element(hat(x).exp()); }

  // The principal logarithm, or NaN outside its domain (see above).
  static Tangent log(const Element& g) {
    using std::sqrt;
    const Algebra logarithm = g.log();
    if constexpr (!log_everywhere()) {
      const Scalar mismatch = (Element(logarithm.exp()) - g).cwiseAbs().maxCoeff();
      const Scalar size = g.cwiseAbs().maxCoeff();
      if (!(mismatch <= sqrt(std::numeric_limits<Scalar>::epsilon()) * size)) {
        return Tangent::Constant(std::numeric_limits<Scalar>::quiet_NaN());
      }
    }
    return vee(logarithm);
  }

  static Algebra hat(const Tangent& x) {
    Algebra m = Algebra::Zero();
    for (int k = 0; k < dof; ++k)
      m += x[k] * generator(k);
    return m;
  }

  // The coefficients of the basis combination nearest to m (Frobenius
  // norm): exact for m in the algebra, a projection otherwise.
  static Tangent vee(const Algebra& m) {
    const Eigen::Matrix<Scalar, N * N, 1> flat =
        Eigen::Map<const Eigen::Matrix<Scalar, N * N, 1>>(m.data());
    return projector() * flat;
  }

  // ad_x e_k = vee([hat x, E_k]).
  static AdMatrix ad(const Tangent& x) {
    const Algebra h = hat(x);
    AdMatrix a;
    for (int k = 0; k < dof; ++k) {
      const Algebra e = generator(k);
      a.col(k) = vee(Algebra(h * e - e * h));
    }
    return a;
  }

  // Ad_g e_k = vee(g E_k g^{-1}).
  static AdMatrix Ad(const Element& g) {
    const Element g_inverse = g.inverse();
    AdMatrix a;
    for (int k = 0; k < dof; ++k)
      a.col(k) = vee(Algebra(g * generator(k) * g_inverse));
    return a;
  }

  static bool is_element(const Element& g, Scalar tol = default_element_tolerance<Scalar>()) {
    return g.allFinite() && Basis::template is_element<Scalar>(g, tol);
  }

 private:
  template <class B, class = void>
  struct declares_log_everywhere : std::false_type {};
  template <class B>
  struct declares_log_everywhere<B, std::void_t<decltype(B::log_everywhere)>>
      : std::bool_constant<B::log_everywhere> {};
  static constexpr bool log_everywhere() { return declares_log_everywhere<Basis>::value; }

  // (B^T B)^{-1} B^T with B = [vec E_1 ... vec E_dof], computed once.
  static const Eigen::Matrix<Scalar, dof, N * N>& projector() {
    static const Eigen::Matrix<Scalar, dof, N* N> p = [] {
      Eigen::Matrix<Scalar, N * N, dof> b;
      for (int k = 0; k < dof; ++k) {
        const Algebra e = generator(k);
        b.col(k) = Eigen::Map<const Eigen::Matrix<Scalar, N * N, 1>>(e.data());
      }
      const Eigen::Matrix<Scalar, dof, dof> gram = b.transpose() * b;
      return Eigen::Matrix<Scalar, dof, N * N>(gram.inverse() * b.transpose());
    }();
    return p;
  }
};

// The Heisenberg group: unit upper-triangular 3x3 matrices. Its algebra is
// nilpotent ([X, Y] = Z central), so ad_x^2 = 0 and the inverse-differential
// series terminates after its linear term.
struct HeisenbergBasis {
  static constexpr int dof = 3;
  static constexpr const char* name = "Heisenberg";
  static constexpr bool log_everywhere = true;  // unipotent: log is a polynomial
  template <class S>
  static Eigen::Matrix<S, 3, 3> generator(int k) {
    Eigen::Matrix<S, 3, 3> e = Eigen::Matrix<S, 3, 3>::Zero();
    const int rows[] = {0, 1, 0}, cols[] = {1, 2, 2};  // X = E01, Y = E12, Z = E02
    e(rows[k], cols[k]) = S(1);
    return e;
  }
  template <class S>
  static bool is_element(const Eigen::Matrix<S, 3, 3>& g, S tol) {
    using std::abs;
    S off = 0;
    for (int r = 0; r < 3; ++r) {
      off = std::max(off, abs(g(r, r) - S(1)));
      for (int c = 0; c < r; ++c)
        off = std::max(off, abs(g(r, c)));
    }
    return off <= tol;
  }
};
template <class Scalar = double>
using Heisenberg = MatrixGroup<3, HeisenbergBasis, Scalar>;

// SL(3): determinant one (homographies normalised to det 1). Basis: the six
// off-diagonal elementary matrices and diag(1, -1, 0), diag(0, 1, -1).
struct SL3Basis {
  static constexpr int dof = 8;
  static constexpr const char* name = "SL3";
  template <class S>
  static Eigen::Matrix<S, 3, 3> generator(int k) {
    Eigen::Matrix<S, 3, 3> e = Eigen::Matrix<S, 3, 3>::Zero();
    const int rows[] = {0, 0, 1, 1, 2, 2}, cols[] = {1, 2, 0, 2, 0, 1};
    if (k < 6) {
      e(rows[k], cols[k]) = S(1);
    } else {
      e(k - 6, k - 6) = S(1);
      e(k - 5, k - 5) = S(-1);
    }
    return e;
  }
  template <class S>
  static bool is_element(const Eigen::Matrix<S, 3, 3>& g, S tol) {
    using std::abs;
    return abs(g.determinant() - S(1)) <= tol;
  }
};
template <class Scalar = double>
using SL3 = MatrixGroup<3, SL3Basis, Scalar>;

// GL+(N): invertible N x N matrices with positive determinant (a deforming
// shape). Basis: all N^2 elementary matrices, row-major.
template <int N>
struct GLBasis {
  static constexpr int dof = N * N;
  static constexpr const char* name = "GLp";
  template <class S>
  static Eigen::Matrix<S, N, N> generator(int k) {
    Eigen::Matrix<S, N, N> e = Eigen::Matrix<S, N, N>::Zero();
    e(k / N, k % N) = S(1);
    return e;
  }
  template <class S>
  static bool is_element(const Eigen::Matrix<S, N, N>& g, S tol) {
    return g.determinant() > tol;
  }
};
template <int N, class Scalar = double>
using GLp = MatrixGroup<N, GLBasis<N>, Scalar>;

}  // namespace bireg
