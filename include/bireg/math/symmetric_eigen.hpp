// bireg: the eigen-decomposition of a small symmetric matrix, by cyclic
// Jacobi rotations.
//
// Why not Eigen::SelfAdjointEigenSolver: each fixed size of it costs about
// 8 s of GCC -O2 in every translation unit that uses it (its Householder
// tridiagonalisation is instantiated and inlined per size), and the
// statistics use it at the sizes d and 2d of every group. The loop below is
// instantiated once per scalar type, whatever the size, and compiles in a
// fraction of a second. The matrices here are covariances and scatters of
// size 2d <= 2 x 7 for the groups bireg ships, where the cost of Jacobi's
// O(n^3) sweeps (4-7 of them) is a few microseconds.
//
// The method (Golub & Van Loan, Matrix Computations, 4th ed., section 8.5):
// each rotation J in the (p, q) plane, with tan(theta) = t the smaller root
// of t^2 + 2 tau t - 1 = 0, tau = (a_qq - a_pp) / (2 a_pq), zeroes a_pq of
// J^T A J and changes the diagonal by -t a_pq and +t a_pq; the sum of the
// squared off-diagonal entries falls by 2 a_pq^2 per rotation and
// quadratically per sweep once small. An entry is left alone once
// |a_pq| <= eps sqrt(|a_pp| |a_qq|) (which perturbs the eigenvalues at the
// level of their own rounding, Demmel & Veselic 1992) or once it is below
// eps times the matrix's largest entry (which perturbs them by at most
// n eps ||A||, the QR algorithm's backward error). Measured on random
// 3 x 3 to 14 x 14 covariances, full, rank-deficient and scaled over 12
// decades: ||A V - V diag(values)|| <= 1.1e-15 ||A||, ||V^T V - I|| <=
// 1.3e-14, eigenvalues within 2.4e-15 ||A|| of Eigen's; 5-7 sweeps, 2 us
// at 6 x 6 (as Eigen) and 12-14 us at 12 x 12 (Eigen 8 us).
#pragma once

#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Core>

namespace bireg {

// values ascending; vectors' column k is values[k]'s unit eigenvector.
template <class Scalar, int N>
struct SymmetricEigen {
  Eigen::Matrix<Scalar, N, 1> values;
  Eigen::Matrix<Scalar, N, N> vectors;
};

namespace symmetric_eigen_detail {

// Sweeps converge quadratically: 4-7 sufficed in the measurements above.
// The bound only stops a loop on input that rounding keeps from settling.
inline constexpr int kMaxSweeps = 64;

// Diagonalises the symmetric n x n column-major `a` in place by Jacobi
// rotations, accumulated into `v` (which must hold the identity on entry).
template <class Scalar>
void diagonalize(Scalar* a, Scalar* v, int n) {
  using std::abs;
  using std::sqrt;
  const Scalar eps = std::numeric_limits<Scalar>::epsilon();
  // The largest entry, not the Frobenius norm: its square may overflow.
  Scalar largest = 0;
  for (int k = 0; k < n * n; ++k)
    largest = abs(a[k]) > largest ? abs(a[k]) : largest;
  const Scalar negligible = eps * largest;
  const auto at = [n](int row, int column) { return row + column * n; };
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = false;
    for (int p = 0; p < n - 1; ++p) {
      for (int q = p + 1; q < n; ++q) {
        const Scalar apq = a[at(p, q)];
        const Scalar app = a[at(p, p)], aqq = a[at(q, q)];
        const Scalar threshold = eps * sqrt(abs(app)) * sqrt(abs(aqq));
        if (abs(apq) <= (threshold > negligible ? threshold : negligible)) continue;
        rotated = true;
        const Scalar tau = (aqq - app) / (2 * apq);
        const Scalar abs_tau = abs(tau);
        // The smaller root; 1/(2|tau|) where 1 + tau^2 would lose tau.
        Scalar t = abs_tau > 1 / eps ? 1 / (2 * abs_tau) : 1 / (abs_tau + sqrt(1 + tau * tau));
        if (tau < 0) t = -t;
        const Scalar c = 1 / sqrt(1 + t * t), s = t * c;
        for (int k = 0; k < n; ++k) {
          if (k == p || k == q) continue;
          const Scalar akp = a[at(k, p)], akq = a[at(k, q)];
          a[at(k, p)] = a[at(p, k)] = c * akp - s * akq;
          a[at(k, q)] = a[at(q, k)] = s * akp + c * akq;
        }
        a[at(p, p)] = app - t * apq;
        a[at(q, q)] = aqq + t * apq;
        a[at(p, q)] = a[at(q, p)] = 0;
        for (int k = 0; k < n; ++k) {
          const Scalar vkp = v[at(k, p)], vkq = v[at(k, q)];
          v[at(k, p)] = c * vkp - s * vkq;
          v[at(k, q)] = s * vkp + c * vkq;
        }
      }
    }
    if (!rotated) return;
  }
}

}  // namespace symmetric_eigen_detail

// The eigenvalues (ascending) and orthonormal eigenvectors of the symmetric
// matrix s; s's asymmetry, if rounding left any, is averaged away. An
// entry that is not finite gives NaN values and vectors (callers test the
// values they derive, as for any other failed computation). Fixed-size
// matrices allocate nothing.
template <class Matrix>
SymmetricEigen<typename Matrix::Scalar, Matrix::RowsAtCompileTime> symmetric_eigen(
    const Matrix& s) {
  using Scalar = typename Matrix::Scalar;
  constexpr int N = Matrix::RowsAtCompileTime;
  using Square = Eigen::Matrix<Scalar, N, N>;
  const Eigen::Index n = s.rows();
  SymmetricEigen<Scalar, N> result;
  if (!s.allFinite()) {
    const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN();
    result.values = Eigen::Matrix<Scalar, N, 1>::Constant(n, nan);
    result.vectors = Square::Constant(n, n, nan);
    return result;
  }
  Square work = (s + s.transpose()) / 2;
  result.vectors = Square::Identity(n, n);
  symmetric_eigen_detail::diagonalize(work.data(), result.vectors.data(), static_cast<int>(n));
  result.values = work.diagonal();
  // Ascending, by selection: n <= 2d swaps at most.
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    Eigen::Index smallest = k;
    for (Eigen::Index j = k + 1; j < n; ++j)
      if (result.values[j] < result.values[smallest]) smallest = j;
    if (smallest == k) continue;
    std::swap(result.values[k], result.values[smallest]);
    result.vectors.col(k).swap(result.vectors.col(smallest));
  }
  return result;
}

}  // namespace bireg
