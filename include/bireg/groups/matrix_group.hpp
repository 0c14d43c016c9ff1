// bireg: any matrix Lie group, given a basis of its Lie algebra.
//
//   MatrixGroup<N, Basis, Scalar>: elements are N x N matrices, tangent
//   coordinates are the coefficients in Basis; exp and log are the matrix
//   exponential and principal matrix logarithm of bireg/math/
//   matrix_functions.hpp (Pade scaling and squaring; inverse scaling and
//   squaring), ad comes from commutators of the basis and Ad from
//   conjugation.
//
// A Basis is a struct with
//   static constexpr int dof;                       // dimension of the algebra
//   static constexpr const char* name;
//   template <class S> static Eigen::Matrix<S, N, N> generator(int k);   // k < dof
//   template <class S> static bool is_element(const Eigen::Matrix<S, N, N>&, S tol);
// and optionally
//   static constexpr int nilpotency_order;          // p with X^p = 0 on the algebra
//   static constexpr bool ad_spectrum_from_matrix;  // see ad_spectral_radius_from_matrix
// (see HeisenbergBasis, SL3Basis, GLBasis below: a dozen lines each).
//
// Nilpotent algebras (unipotent groups such as Heisenberg): when every X in
// the algebra has X^p = 0, and so every group element has (g - I)^p = 0, exp
// and log are the terminating series
//   exp(X) = sum_{k<p} X^k / k!,   log(g) = sum_{1<=k<p} (-1)^(k+1) (g - I)^k / k,
// exact polynomials, defined everywhere, evaluated by Horner's rule in a few
// matrix products. A Basis declares this with `nilpotency_order = p`; it is
// the only way to opt out of the general matrix functions.
//
// Domain of log (general path): the principal matrix logarithm exists for
// matrices with no eigenvalue on the closed negative real axis; there it is
// the unique logarithm whose eigenvalues have imaginary parts in (-pi, pi).
// Outside it (a rotation by pi inside SL(3), a negative eigenvalue pair) the
// square-root iteration of matrix_log cannot converge (proof beside
// math::matrix_sqrt), so log returns a tangent of NaN; so it does for inputs
// that are not finite or whose logarithm is beyond ~2^63 in norm. Unlike a
// Schur-based logarithm, no result is returned that is not a logarithm, so no
// exp(log g) = g check is made. GeodesicRegression turns NaN into a status:
// data that leave the domain as seen from their middle observation are
// invalid_input (naming the observation); an iterate that leaves it stops
// the fit with diverged and the last finite endpoints. Prefer the
// closed-form groups (SO3, SE3, Sim3, ...) where they exist: they are exact
// to rounding and faster.
//
// Everything is fixed-size: fits on a MatrixGroup do not allocate in their
// iterations, like the closed-form groups.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/eigenvalue_spread.hpp"
#include "bireg/math/matrix_functions.hpp"

namespace bireg {

namespace detail {
// Basis::nilpotency_order if declared, else 0 (general matrix functions).
template <class Basis, class = void>
struct nilpotency_order_of : std::integral_constant<int, 0> {};
template <class Basis>
struct nilpotency_order_of<Basis, std::void_t<decltype(Basis::nilpotency_order)>>
    : std::integral_constant<int, Basis::nilpotency_order> {};

// Basis::ad_spectrum_from_matrix if declared, else false.
template <class Basis, class = void>
struct ad_spectrum_from_matrix_of : std::false_type {};
template <class Basis>
struct ad_spectrum_from_matrix_of<Basis, std::void_t<decltype(Basis::ad_spectrum_from_matrix)>>
    : std::integral_constant<bool, Basis::ad_spectrum_from_matrix> {};

// {0, 1, 1/2, ..., 1/(Count-1)} at compile time: the nilpotent series
// multiply by these instead of dividing at run time.
template <class Scalar, int Count>
constexpr std::array<Scalar, Count> inverse_integers() {
  std::array<Scalar, Count> inverse{};
  for (int k = 1; k < Count; ++k)
    inverse[k] = Scalar(1) / Scalar(k);
  return inverse;
}
}  // namespace detail

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

  // exp(hat x); not finite when it overflows.
  static Element exp(const Tangent& x) {
    const Algebra h = hat(x);
    if constexpr (nilpotency_order() > 0) {
      // sum_{k<p} h^k / k! = I + T_1 by Horner's rule,
      //   T_{p-1} = h / (p-1),   T_k = (h + h T_{k+1}) / k:
      // p - 2 matrix products (one for Heisenberg). The last step is
      // written into the sum: exp = I + h + h T_2 (materialising T_1 first
      // costs a store-forwarding stall, doubling Heisenberg's exp).
      if constexpr (nilpotency_order() == 2) {
        return Element::Identity() + h;
      } else {
        const Algebra product = h * exp_horner<2>(h);
        return Element::Identity() + h + product;
      }
    } else {
      return math::matrix_exp(h);
    }
  }

  // The principal logarithm, or NaN outside its domain (see above).
  static Tangent log(const Element& g) {
    if constexpr (nilpotency_order() > 0) {
      // With n = g - I, sum_{1<=k<p} (-1)^(k+1) n^k / k = T_1 by Horner's rule,
      //   T_{p-1} = (-1)^p n / (p-1),   T_k = (-1)^(k+1) n / k + n T_{k+1}:
      // p - 2 matrix products (one for Heisenberg: n - n^2/2).
      return vee(log_horner<1>(Algebra(g - Element::Identity())));
    } else {
      const Algebra logarithm = math::matrix_log(g);
      if (!logarithm.allFinite())
        return Tangent::Constant(std::numeric_limits<Scalar>::quiet_NaN());
      return vee(logarithm);
    }
  }

  // sum_k x_k E_k, as one product with the stacked basis (vec E_1 ... vec E_dof).
  static Algebra hat(const Tangent& x) {
    const FlatAlgebra flat = basis_matrix() * x;
    return Eigen::Map<const Algebra>(flat.data());
  }

  // The coefficients of the basis combination nearest to m (Frobenius
  // norm): exact for m in the algebra, a projection otherwise.
  static Tangent vee(const Algebra& m) {
    return projector() * Eigen::Map<const FlatAlgebra>(m.data());
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

  // Spectral radius of ad_x, for a 2 x 2 or 3 x 3 algebra whose Basis
  // declares ad_spectrum_from_matrix = true: the largest difference of the
  // eigenvalues of X = hat x, in closed form (math/eigenvalue_spread.hpp).
  // capabilities.hpp's ad_spectral_radius<G> uses it instead of its
  // fallback, a general eigensolver on the dof x dof matrix ad_x compiled
  // for each size. (Under the name ad_spectral_radius it would also turn
  // on the per-residual angle diagnostics of the fit and the spline for
  // these groups: a change of their output, not made here.)
  //
  // Why the two agree there. The algebra g is an ad_X-invariant subspace of
  // gl(N), so the eigenvalues of ad_X on g are some of its eigenvalues on
  // gl(N), the differences lambda_i - lambda_j of X's eigenvalues. On
  // gl(N) they are all of them. On sl(N), gl(N) = sl(N) + span(I) with
  // ad_X I = 0, so only a 0 is lost and the largest modulus is kept. On
  // strictly upper-triangular matrices (Heisenberg) X is nilpotent, so
  // every lambda_i is 0, and ad_X = L_X - R_X (left and right
  // multiplication by X, which commute and are nilpotent) is nilpotent:
  // both are 0. A basis of some other subalgebra leaves the flag unset:
  // there the largest difference may be missing from g and only bounds the
  // radius.
  template <
      class T = Tangent,
      std::enable_if_t<std::is_same_v<T, Tangent> &&
                           detail::ad_spectrum_from_matrix_of<Basis>::value && (N == 2 || N == 3),
                       int> = 0>
  static Scalar ad_spectral_radius_from_matrix(const T& x) {
    return math::eigenvalue_spread<Scalar, N>(hat(x));
  }

 private:
  // The Horner steps T_K of the nilpotent series (see exp and log),
  // unrolled at compile time.
  template <int K>
  static Algebra exp_horner(const Algebra& h) {
    constexpr auto inverse = detail::inverse_integers<Scalar, nilpotency_order()>();
    if constexpr (K == nilpotency_order() - 1) {
      return h * inverse[K];
    } else {
      const Algebra inner = exp_horner<K + 1>(h);
      const Algebra product = h * inner;
      return (h + product) * inverse[K];
    }
  }
  template <int K>
  static Algebra log_horner(const Algebra& n) {
    constexpr auto inverse = detail::inverse_integers<Scalar, nilpotency_order()>();
    constexpr Scalar coefficient = K % 2 == 1 ? inverse[K] : -inverse[K];
    if constexpr (K == nilpotency_order() - 1) {
      return coefficient * n;
    } else {
      const Algebra inner = log_horner<K + 1>(n);
      const Algebra product = n * inner;
      return coefficient * n + product;
    }
  }

  static constexpr int nilpotency_order() { return detail::nilpotency_order_of<Basis>::value; }
  static_assert(detail::nilpotency_order_of<Basis>::value == 0 ||
                    detail::nilpotency_order_of<Basis>::value >= 2,
                "nilpotency_order p means X^p = 0 on a nonzero algebra: p >= 2");

  using FlatAlgebra = Eigen::Matrix<Scalar, N * N, 1>;
  using BasisMatrix = Eigen::Matrix<Scalar, N * N, dof>;

  // B = [vec E_1 ... vec E_dof], computed once.
  static const BasisMatrix& basis_matrix() {
    static const BasisMatrix b = [] {
      BasisMatrix columns;
      for (int k = 0; k < dof; ++k) {
        const Algebra e = generator(k);
        columns.col(k) = Eigen::Map<const FlatAlgebra>(e.data());
      }
      return columns;
    }();
    return b;
  }

  // (B^T B)^{-1} B^T, computed once.
  static const Eigen::Matrix<Scalar, dof, N * N>& projector() {
    static const Eigen::Matrix<Scalar, dof, N* N> p = [] {
      const BasisMatrix& b = basis_matrix();
      const Eigen::Matrix<Scalar, dof, dof> gram = b.transpose() * b;
      return Eigen::Matrix<Scalar, dof, N * N>(gram.inverse() * b.transpose());
    }();
    return p;
  }
};

// The Heisenberg group: unit upper-triangular 3x3 matrices. Its algebra is
// nilpotent ([X, Y] = Z central), so ad_x^2 = 0 and the inverse-differential
// series terminates after its linear term; strictly upper-triangular 3x3
// matrices have X^3 = 0, so exp(X) = I + X + X^2/2 and log(g) = (g - I) -
// (g - I)^2/2 exactly.
struct HeisenbergBasis {
  static constexpr int dof = 3;
  static constexpr const char* name = "Heisenberg";
  static constexpr int nilpotency_order = 3;
  static constexpr bool ad_spectrum_from_matrix = true;
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
  static constexpr bool ad_spectrum_from_matrix = true;
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
  static constexpr bool ad_spectrum_from_matrix = true;
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
