// bireg: the spread of a small real matrix's eigenvalues,
//
//   spread(X) = max_{i,j} |lambda_i(X) - lambda_j(X)|,
//
// for 2 x 2 and 3 x 3 X, in closed form. On gl(N) the operator ad_X has
// the eigenvalues lambda_i - lambda_j (in vec form ad_X = I (x) X - X^T (x) I),
// so spread(X) is the spectral radius of ad_X; MatrixGroup uses this for
// GL(N), SL(N) and Heisenberg (matrix_group.hpp says why the radius on
// those algebras is the same) instead of a general eigensolver on the
// dof x dof matrix ad_X. Each fixed size of Eigen::EigenSolver costs about
// 10 s of GCC -O2 in every translation unit that fits such a group (a
// GL+(3) fit: 23 s with it, 10 s without); the formulas below cost nothing.
//
// Both sizes work on the traceless part Y = X - tr(X)/N I, whose eigenvalues
// have the same differences, scaled to max |Y_ij| = 1 (X too, before its
// trace), and the cubic's roots are scaled to order 1 (kappa, below), so
// that no square or cube overflows or underflows.
//
// 2 x 2: Y = [a b; c -a] has the eigenvalues +-sqrt(a^2 + b c) (real or
// imaginary), so spread = 2 sqrt(|a^2 + b c|).
//
// 3 x 3: the eigenvalues of Y are the roots of the depressed cubic
// t^3 + p t + q with p = -tr(Y^2)/2 and q = -det(Y), and
// D = (q/2)^2 + (p/3)^3 decides their kind (e.g. Press et al., Numerical
// Recipes, 3rd ed., section 5.6).
//   * D <= 0, three real roots: with rho = sqrt(-p/3) and
//     cos(phi) = -(q/2) / rho^3, phi in [0, pi], they are
//     2 rho cos((phi - 2 pi k)/3), k = 0, 1, 2; the largest is k = 0 and
//     the smallest k = 2, so
//       spread = 2 rho (cos(phi/3) - cos(phi/3 + 2 pi/3))
//              = 2 sqrt(3) rho sin((phi + pi)/3).
//   * D > 0, one real root r and a pair m +- i b with r + 2m = 0
//     (Y is traceless): r by Cardano's formula written without
//     cancellation, u = cbrt(-q/2 - sign(q) sqrt(D)), r = u - p/(3u) (the
//     two cube roots multiply to -p/3); then the sum of the roots' pairwise
//     products, 2 r m + m^2 + b^2 = p, gives b^2 = p + 3 r^2/4. The
//     differences are 2 i b and r - m -+ i b, so
//       spread = max(2 |b|, sqrt(9 r^2/4 + b^2)).
//
// Accuracy: for separated eigenvalues within a few ulps of max |Y_ij| times
// the conditioning of the eigenvalues; where two eigenvalues (nearly)
// coincide, to about sqrt(epsilon) relative (acos near +-1: a double root
// of the cubic, even where the matrix is diagonalisable and an eigensolver
// would do better), and near a triple one to about cbrt(epsilon). The
// spectral radius serves as a threshold (2 pi: the series and the
// exponential's injectivity) and a reported angle, where that is far below
// what is resolved. A matrix that is not finite has a NaN spread.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace bireg {
namespace math {

template <class Scalar, int N>
Scalar eigenvalue_spread(const Eigen::Matrix<Scalar, N, N>& x) {
  static_assert(N == 2 || N == 3, "eigenvalue_spread: 2 x 2 and 3 x 3 matrices only");
  using std::abs;
  using std::acos;
  using std::cbrt;
  using std::sin;
  using std::sqrt;
  if (!x.allFinite()) return std::numeric_limits<Scalar>::quiet_NaN();
  using Matrix = Eigen::Matrix<Scalar, N, N>;
  // X / max|X_ij| first, so that the trace of entries near the largest
  // double does not overflow.
  const Scalar x_scale = x.cwiseAbs().maxCoeff();
  if (!(x_scale > 0)) return Scalar(0);
  const Matrix unit_x = x / x_scale;
  const Scalar mean_eigenvalue = unit_x.trace() / Scalar(N);
  const Matrix traceless = unit_x - mean_eigenvalue * Matrix::Identity();
  const Scalar y_scale = traceless.cwiseAbs().maxCoeff();
  if (!(y_scale > 0)) return Scalar(0);  // a multiple of the identity
  const Matrix y = traceless / y_scale;
  const Scalar scale = y_scale * x_scale;

  if constexpr (N == 2) {
    const Scalar a = y(0, 0), b = y(0, 1), c = y(1, 0);
    return Scalar(2) * sqrt(abs(a * a + b * c)) * scale;
  } else {
    const Scalar p = -(y * y).trace() / Scalar(2);
    // det(Y) by cofactors along the first row (Eigen's determinant() lives
    // in Eigen/LU, which this header does not need).
    const Scalar determinant = y(0, 0) * (y(1, 1) * y(2, 2) - y(1, 2) * y(2, 1)) -
                               y(0, 1) * (y(1, 0) * y(2, 2) - y(1, 2) * y(2, 0)) +
                               y(0, 2) * (y(1, 0) * y(2, 1) - y(1, 1) * y(2, 0));
    const Scalar q = -determinant;
    // The roots scale as kappa = max(sqrt(|p|/3), cbrt(|q|/2)): with
    // t = kappa s the cubic is s^3 + (p/kappa^2) s + q/kappa^3, whose
    // coefficients are at most 3 and 2 and one of them is that large, so
    // that neither D nor rho underflows when the eigenvalues are tiny
    // beside Y's largest entry (+-1e-150 beside a 1, a pair or real).
    const Scalar kappa = std::max(sqrt(abs(p) / Scalar(3)), cbrt(abs(q) / Scalar(2)));
    if (!(kappa > 0)) return Scalar(0);  // p = q = 0: a triple eigenvalue
    const Scalar third_p = p / kappa / kappa / Scalar(3);
    const Scalar half_q = q / kappa / kappa / kappa / Scalar(2);
    const Scalar d = half_q * half_q + third_p * third_p * third_p;
    const Scalar pi = Scalar(3.14159265358979323846264338327950288L);
    Scalar unit_spread;
    if (d > 0) {
      const Scalar u = cbrt(-half_q - std::copysign(sqrt(d), half_q));
      const Scalar real_root = u - third_p / u;
      const Scalar b_squared =
          std::max(Scalar(0), Scalar(3) * third_p + Scalar(0.75) * real_root * real_root);
      const Scalar pair_gap = Scalar(2) * sqrt(b_squared);
      const Scalar cross_gap = sqrt(Scalar(2.25) * real_root * real_root + b_squared);
      unit_spread = std::max(pair_gap, cross_gap);
    } else {
      // d <= 0 needs -third_p^3 >= half_q^2, and one of the two is 1: rho = 1 up to rounding.
      const Scalar rho = sqrt(-third_p);
      const Scalar cos_phi = std::clamp(-half_q / (rho * rho * rho), Scalar(-1), Scalar(1));
      const Scalar phi = acos(cos_phi);
      unit_spread = Scalar(2) * sqrt(Scalar(3)) * rho * sin((phi + pi) / Scalar(3));
    }
    return unit_spread * kappa * scale;
  }
}

}  // namespace math
}  // namespace bireg
