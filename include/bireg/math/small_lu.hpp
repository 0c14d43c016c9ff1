// bireg: LU with partial pivoting for the small square systems of the
// fit's step, the mean's Newton step, the covariance's K, the local fits'
// normal equations and the spline's pivot blocks (sizes 2 to 2d).
//
// Why not Eigen::PartialPivLU, FullPivLU or inverse() (which is PartialPivLU
// above 4 x 4): each fixed size of either
// instantiates Eigen's blocked LU and its matrix-product kernels, about
// 2 s of GCC -O2 per size in every translation unit that solves one. The
// loops below are a few lines per size and scalar type, with the size a
// constant the compiler can unroll for fixed-size matrices (a 3 x 3 LU
// and inverse, 10003 of them for the spline's pivots: 0.62 ms with the
// size read at run time, 0.34 ms with it fixed; 2026-11-29); at n <= 14
// the blocked kernels win nothing at run time.
//
// P A = L U with |L_ij| <= 1 (Golub & Van Loan, Matrix Computations, 4th
// ed., algorithm 3.4.1): backward stable in practice, the growth factor
// being modest for every matrix met here (K is block diagonally
// dominant near the solution; the mean's Jacobian is near the identity).
#pragma once

#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Core>

namespace bireg {

namespace small_lu_detail {

// Factors the n x n column-major `lu` in place (unit L below the diagonal,
// U on and above it); `pivot[k]` is the row swapped with row k at step k.
// A zero pivot is left in place: solving then divides by it, and the
// caller sees a solution that is not finite (as with Eigen's).
template <int N, class Scalar>
void factor(Scalar* lu, int* pivot, int runtime_n) {
  using std::abs;
  const int n = N == Eigen::Dynamic ? runtime_n : N;
  const auto at = [=](int row, int column) { return row + column * n; };
  for (int k = 0; k < n; ++k) {
    int largest = k;
    for (int i = k + 1; i < n; ++i)
      if (abs(lu[at(i, k)]) > abs(lu[at(largest, k)])) largest = i;
    pivot[k] = largest;
    if (largest != k) {
      for (int j = 0; j < n; ++j)
        std::swap(lu[at(k, j)], lu[at(largest, j)]);
    }
    const Scalar diagonal = lu[at(k, k)];
    if (diagonal == Scalar(0)) continue;
    for (int i = k + 1; i < n; ++i)
      lu[at(i, k)] /= diagonal;
    for (int j = k + 1; j < n; ++j) {
      const Scalar u_kj = lu[at(k, j)];
      if (u_kj == Scalar(0)) continue;
      for (int i = k + 1; i < n; ++i)
        lu[at(i, j)] -= lu[at(i, k)] * u_kj;
    }
  }
}

// Overwrites the n x m column-major b with A^{-1} b.
template <int N, class Scalar>
void solve(const Scalar* lu, const int* pivot, int runtime_n, Scalar* b, int m) {
  const int n = N == Eigen::Dynamic ? runtime_n : N;
  const auto at = [=](int row, int column) { return row + column * n; };
  for (int c = 0; c < m; ++c) {
    Scalar* x = b + c * n;
    for (int k = 0; k < n; ++k)
      if (pivot[k] != k) std::swap(x[k], x[pivot[k]]);
    for (int k = 0; k < n; ++k) {  // L y = P b, L unit lower
      for (int i = k + 1; i < n; ++i)
        x[i] -= lu[at(i, k)] * x[k];
    }
    for (int k = n - 1; k >= 0; --k) {  // U x = y
      x[k] /= lu[at(k, k)];
      for (int i = 0; i < k; ++i)
        x[i] -= lu[at(i, k)] * x[k];
    }
  }
}

}  // namespace small_lu_detail

// The factorisation of a square matrix, fixed-size or dynamic. Fixed-size
// matrices allocate nothing.
template <class Matrix>
class SmallLU {
 public:
  using Scalar = typename Matrix::Scalar;
  static constexpr int N = Matrix::RowsAtCompileTime;
  using Square = Eigen::Matrix<Scalar, N, N>;

  explicit SmallLU(const Matrix& a) : lu_(a) {
    pivot_.resize(a.rows());
    small_lu_detail::factor<N>(lu_.data(), pivot_.data(), static_cast<int>(lu_.rows()));
  }

  // Whether every pivot is finite and above n eps times the largest, the
  // rank test of a pivoted elimination (a matrix this close to singular
  // has no solve worth reporting).
  bool invertible() const {
    using std::abs;
    const Eigen::Index n = lu_.rows();
    if (!lu_.allFinite()) return false;
    const Scalar largest = lu_.diagonal().cwiseAbs().maxCoeff();
    const Scalar floor = Scalar(n) * std::numeric_limits<Scalar>::epsilon() * largest;
    for (Eigen::Index k = 0; k < n; ++k)
      if (!(abs(lu_(k, k)) > floor)) return false;
    return true;
  }

  // det A: the product of U's diagonal, signed by the row swaps.
  Scalar determinant() const {
    Scalar product = 1;
    for (Eigen::Index k = 0; k < lu_.rows(); ++k)
      product *= pivot_[k] == k ? lu_(k, k) : -lu_(k, k);
    return product;
  }

  // A^{-1}.
  Square inverse() const { return solve(Square::Identity(lu_.rows(), lu_.cols())); }

  // A^{-1} b for a vector or a matrix b with A's number of rows.
  template <class Rhs>
  typename Rhs::PlainObject solve(const Eigen::MatrixBase<Rhs>& b) const {
    typename Rhs::PlainObject x = b;
    static_assert(!(Rhs::PlainObject::IsRowMajor && Rhs::ColsAtCompileTime != 1),
                  "SmallLU::solve writes column-major right-hand sides");
    small_lu_detail::solve<N>(lu_.data(), pivot_.data(), static_cast<int>(lu_.rows()), x.data(),
                              static_cast<int>(x.cols()));
    return x;
  }

 private:
  Square lu_;
  Eigen::Matrix<int, N, 1> pivot_;
};

// The inverse of a fixed-size 3 x 3 matrix: by its adjugate, adj(A) /
// det A (about 40 operations and one division, where the pivoted
// elimination's data-dependent branches cost ~50 ns: SmallLU, 2026-11-29)
// where that is accurate, else by SmallLU. With max-norms and to first
// order, the adjugate's residual is ||A X - I|| <= 48 eps ||A||^3 /
// |det A|: a cofactor (two rounded products and a rounded difference) is
// off by at most 4 eps ||A||^2, so A times the adjugate's errors by 12 eps
// ||A||^3; the determinant carries those through its first row (12) and
// rounds its three products and two sums (18); the division adds 3 eps
// ||A|| ||X|| <= 6 eps ||A||^3 / |det A|. Where ||A||^3 <= 4 |det A| that
// is at most 192 eps: the near-orthogonal
// matrices it is meant for (the spline's interior D_j on SO(3), B_j times
// a matrix near I; splines.md §5). A matrix whose entries differ in scale
// (SE(2)'s translations in small units) fails the test and gets the
// pivoted LU, whose error grows like cond(A) eps rather than cond^2. A
// singular A gives a result that is not finite, as SmallLU's.
template <class Matrix>
Eigen::Matrix<typename Matrix::Scalar, 3, 3> inverse_3x3(const Matrix& a) {
  static_assert(Matrix::RowsAtCompileTime == 3 && Matrix::ColsAtCompileTime == 3);
  using Scalar = typename Matrix::Scalar;
  using std::abs;
  Eigen::Matrix<Scalar, 3, 3> adjugate;
  // Row j of the adjugate is column j of A's cofactors.
  adjugate(0, 0) = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1);
  adjugate(0, 1) = a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2);
  adjugate(0, 2) = a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1);
  adjugate(1, 0) = a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2);
  adjugate(1, 1) = a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0);
  adjugate(1, 2) = a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2);
  adjugate(2, 0) = a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0);
  adjugate(2, 1) = a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1);
  adjugate(2, 2) = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
  const Scalar determinant =
      a(0, 0) * adjugate(0, 0) + a(0, 1) * adjugate(1, 0) + a(0, 2) * adjugate(2, 0);
  const Scalar norm = a.cwiseAbs().maxCoeff();
  if (Scalar(4) * abs(determinant) >= norm * norm * norm) return adjugate / determinant;
  return SmallLU<Eigen::Matrix<Scalar, 3, 3>>(a).inverse();
}

}  // namespace bireg
