// bireg: matrix exponential, principal square root and principal logarithm
// of small fixed-size real matrices, without heap allocation and with every
// loop bounded.
//
// Depends only on Eigen/Core and the standard library. Matrices are
// Eigen::Matrix<Scalar, N, N> with N fixed at compile time (MatrixGroup uses
// N = 3 and 4; nothing here depends on N being small except cost); Scalar is
// float, double or long double (x87 80-bit or IEEE quad).
//
// Failure is reported, never looped on and never asserted: exp and log return
// a matrix of NaN, sqrt returns false, when
//   * the input has a NaN or infinite entry;
//   * an intermediate overflows (exp of a huge matrix, log of a matrix whose
//     inverse does not fit in the floating-point range);
//   * a linear solve meets a zero or non-finite pivot;
//   * (sqrt, log) the input has an eigenvalue on the closed negative real
//     axis, where no principal square root or logarithm exists: the
//     Denman-Beavers iteration below provably does not converge there and
//     stops after a fixed number of steps;
//   * (log) more than max_square_roots() square roots would be needed, i.e. the
//     logarithm's norm (or its nilpotent part) exceeds ~2^63: far outside any
//     use of a tangent vector, and such inputs are refused rather than
//     computed from ever more square roots.
// The only linear algebra used is Gaussian elimination with partial pivoting
// on fixed-size matrices (no Schur or eigenvalue decomposition, nothing that
// asserts), whose pivots are checked.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace bireg {
namespace math {

template <class Scalar, int N>
using SquareMatrix = Eigen::Matrix<Scalar, N, N>;

namespace detail {

template <class Scalar, int N>
SquareMatrix<Scalar, N> not_a_matrix() {
  return SquareMatrix<Scalar, N>::Constant(std::numeric_limits<Scalar>::quiet_NaN());
}

// Induced 1-norm (largest column sum): the norm in which the Pade
// thresholds below are stated.
template <class Scalar, int N>
Scalar norm1(const SquareMatrix<Scalar, N>& a) {
  return a.cwiseAbs().colwise().sum().maxCoeff();
}

// x = a^{-1} b by Gaussian elimination with partial pivoting (row
// interchanges choosing the largest remaining entry of the column), written
// out for fixed N: Eigen's PartialPivLU takes its general blocked path even
// for 3x3 and costs several times more. Returns false, leaving x undefined,
// when a pivot is zero or not finite (a singular to working precision, or
// overflow) or the solution is not finite. If log_abs_determinant is given
// it receives log|det a| = sum log|pivot|, which cannot overflow.
template <class Scalar, int N>
bool solve(SquareMatrix<Scalar, N> a, const SquareMatrix<Scalar, N>& b, SquareMatrix<Scalar, N>& x,
           Scalar* log_abs_determinant = nullptr) {
  using std::abs;
  using std::log;
  x = b;
  Scalar log_determinant = 0;
  for (int k = 0; k < N; ++k) {
    int pivot_row = k;
    for (int i = k + 1; i < N; ++i) {
      if (abs(a(i, k)) > abs(a(pivot_row, k))) pivot_row = i;
    }
    const Scalar pivot_size = abs(a(pivot_row, k));
    if (!(pivot_size > 0) || !std::isfinite(pivot_size)) return false;
    if (pivot_row != k) {
      a.row(k).swap(a.row(pivot_row));
      x.row(k).swap(x.row(pivot_row));
    }
    if (log_abs_determinant) log_determinant += log(pivot_size);
    for (int i = k + 1; i < N; ++i) {
      const Scalar multiplier = a(i, k) / a(k, k);
      for (int j = k + 1; j < N; ++j)
        a(i, j) -= multiplier * a(k, j);
      x.row(i) -= multiplier * x.row(k);
    }
  }
  for (int i = N - 1; i >= 0; --i) {
    for (int j = i + 1; j < N; ++j)
      x.row(i) -= a(i, j) * x.row(j);
    x.row(i) /= a(i, i);
  }
  if (log_abs_determinant) *log_abs_determinant = log_determinant;
  return x.allFinite();
}

// ---- exponential -----------------------------------------------------------
//
// Scaling and squaring with the diagonal [m/m] Pade approximant r_m of e^x,
// after Higham, "The scaling and squaring method for the matrix exponential
// revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005:
//   exp(A) = r_m(2^-s A)^(2^s),
// with m the smallest degree whose threshold theta_m bounds ||A||_1 (s = 0),
// and otherwise the largest degree and the least s with ||2^-s A||_1 <=
// theta_m. theta_m is the largest theta for which the backward error bound
// of the paper's Section 2 holds at the unit roundoff u: writing
// log(e^{-x} r_m(x)) = sum_{k >= 2m+1} c_k x^k, r_m(2^-s A)^(2^s) =
// exp(A + dA) with ||dA|| / ||A|| <= sum_k |c_k| theta^(k-1) <= u.
//
// The thetas were computed by us from that definition (mpmath, 120 digits,
// 200 series terms, bisection): for u = 2^-53 they reproduce the paper's
// Table 2.3 to all 16 digits, and for u = 2^-24 the single-precision values
// the paper quotes; 2^-64 (x87 long double) and 2^-113 (IEEE quad) are the
// same computation at those unit roundoffs. Degrees follow the paper: 13 is
// the degree that minimises matrix products per unit of norm in double (and
// we keep it for the wider types, where it remains the cheapest per unit of
// norm among 3..13), and 7 is its choice for single precision.

// Coefficients of the numerator p_m(x) = sum_j c_j x^j of r_m = p_m(x) /
// p_m(-x), normalised to c_0 = 1:
//   c_j = (2m - j)! m! / ((2m)! j! (m - j)!),
// built by the ratio c_{j+1} / c_j = (m - j) / ((2m - j)(j + 1)) so that no
// factorial is formed. Kept in long double; rounded once to Scalar.
template <int M>
constexpr std::array<long double, M + 1> pade_exp_coefficients() {
  std::array<long double, M + 1> c{};
  c[0] = 1.0L;
  for (int j = 0; j < M; ++j) {
    c[j + 1] = c[j] * static_cast<long double>(M - j) /
               (static_cast<long double>(2 * M - j) * static_cast<long double>(j + 1));
  }
  return c;
}

// The degrees tried in increasing order and their thetas, chosen by the
// precision of Scalar (its mantissa digits).
struct ExpPadeTable {
  int count;
  std::array<int, 5> degree;
  std::array<long double, 5> theta;
};

template <class Scalar>
constexpr ExpPadeTable exp_pade_table() {
  constexpr int digits = std::numeric_limits<Scalar>::digits;
  static_assert(digits <= 113, "matrix_exp: thresholds known up to IEEE quad precision");
  if constexpr (digits <= 24) {  // u = 2^-24
    return {3,
            {3, 5, 7, 0, 0},
            {4.2587300348979311586e-1L, 1.8801526985337688303L, 3.9257248464332841912L, 0, 0}};
  } else if constexpr (digits <= 53) {  // u = 2^-53
    return {5,
            {3, 5, 7, 9, 13},
            {1.4955852179582915173e-2L, 2.5393983300632320786e-1L, 9.5041789961629318679e-1L,
             2.0978479612570674568L, 5.3719203511481522594L}};
  } else if constexpr (digits <= 64) {  // u = 2^-64
    return {5,
            {3, 5, 7, 9, 13},
            {4.1968497232266989671e-3L, 1.1848116734693823091e-1L, 5.5170388480686700274e-1L,
             1.3759868875587845383L, 4.0246098906697353063L}};
  } else {  // u = 2^-113
    return {5,
            {3, 5, 7, 9, 13},
            {1.4605345568331036402e-5L, 3.9684111281412623102e-3L, 4.8782043467113475785e-2L,
             2.0880318491357325894e-1L, 1.0957790341272287509L}};
  }
}

// r_m(A) = (V - U)^{-1} (V + U) with U the odd part A sum_k c_{2k+1} A^{2k}
// and V the even part sum_k c_{2k} A^{2k} (p_m(-A) = V - U), for m <= 9:
// the even powers A^2 .. A^{m-1} are formed once.
template <int M, class Scalar, int N>
bool pade_exp_low_degree(const SquareMatrix<Scalar, N>& a, SquareMatrix<Scalar, N>& result) {
  static_assert(M % 2 == 1 && M <= 9, "odd degree up to 9");
  constexpr auto c = pade_exp_coefficients<M>();
  using Matrix = SquareMatrix<Scalar, N>;
  const Matrix a2 = a * a;
  Matrix even_power = Matrix::Identity();
  Matrix odd_sum = Scalar(c[1]) * even_power;
  Matrix even = Scalar(c[0]) * even_power;
  for (int k = 1; 2 * k < M; ++k) {
    even_power = even_power * a2;
    odd_sum += Scalar(c[2 * k + 1]) * even_power;
    even += Scalar(c[2 * k]) * even_power;
  }
  const Matrix odd = a * odd_sum;
  return solve<Scalar, N>(even - odd, even + odd, result);
}

// Degree 13 with the paper's evaluation scheme (its eq. (2.8)), six matrix
// products instead of twelve:
//   U = A [A6 (c13 A6 + c11 A4 + c9 A2) + c7 A6 + c5 A4 + c3 A2 + c1 I],
//   V =    A6 (c12 A6 + c10 A4 + c8 A2) + c6 A6 + c4 A4 + c2 A2 + c0 I.
template <class Scalar, int N>
bool pade_exp_degree13(const SquareMatrix<Scalar, N>& a, SquareMatrix<Scalar, N>& result) {
  constexpr auto c = pade_exp_coefficients<13>();
  using Matrix = SquareMatrix<Scalar, N>;
  const Matrix identity = Matrix::Identity();
  const Matrix a2 = a * a;
  const Matrix a4 = a2 * a2;
  const Matrix a6 = a4 * a2;
  const Matrix odd_high = Scalar(c[13]) * a6 + Scalar(c[11]) * a4 + Scalar(c[9]) * a2;
  const Matrix odd_sum = a6 * odd_high + Scalar(c[7]) * a6 + Scalar(c[5]) * a4 + Scalar(c[3]) * a2 +
                         Scalar(c[1]) * identity;
  const Matrix odd = a * odd_sum;
  const Matrix even_high = Scalar(c[12]) * a6 + Scalar(c[10]) * a4 + Scalar(c[8]) * a2;
  const Matrix even = a6 * even_high + Scalar(c[6]) * a6 + Scalar(c[4]) * a4 + Scalar(c[2]) * a2 +
                      Scalar(c[0]) * identity;
  return solve<Scalar, N>(even - odd, even + odd, result);
}

template <class Scalar, int N>
bool pade_exp(int degree, const SquareMatrix<Scalar, N>& a, SquareMatrix<Scalar, N>& result) {
  switch (degree) {
    case 3:
      return pade_exp_low_degree<3>(a, result);
    case 5:
      return pade_exp_low_degree<5>(a, result);
    case 7:
      return pade_exp_low_degree<7>(a, result);
    case 9:
      return pade_exp_low_degree<9>(a, result);
    default:
      return pade_exp_degree13(a, result);
  }
}

}  // namespace detail

// exp(A); a matrix of NaN when A is not finite or the result overflows.
template <class Scalar, int N>
SquareMatrix<Scalar, N> matrix_exp(const SquareMatrix<Scalar, N>& a) {
  using Matrix = SquareMatrix<Scalar, N>;
  constexpr detail::ExpPadeTable table = detail::exp_pade_table<Scalar>();
  const Scalar norm = detail::norm1(a);
  if (!std::isfinite(norm)) return detail::not_a_matrix<Scalar, N>();
  Matrix result;
  for (int i = 0; i + 1 < table.count; ++i) {
    if (norm <= Scalar(table.theta[i])) {
      if (!detail::pade_exp(table.degree[i], a, result)) return detail::not_a_matrix<Scalar, N>();
      return result;
    }
  }
  // ||A||_1 / theta < 2^exponent: 2^-exponent A is within the threshold.
  // exponent is bounded by the exponent range of Scalar (~1030 for double),
  // and the squaring stops at the first overflow.
  const Scalar theta = Scalar(table.theta[table.count - 1]);
  int exponent = 0;
  if (norm > theta) std::frexp(norm / theta, &exponent);
  const Matrix scaled = a * std::ldexp(Scalar(1), -exponent);
  if (!detail::pade_exp(table.degree[table.count - 1], scaled, result)) {
    return detail::not_a_matrix<Scalar, N>();
  }
  for (int i = 0; i < exponent; ++i) {
    result = (result * result).eval();
    if (!result.allFinite()) return detail::not_a_matrix<Scalar, N>();
  }
  return result;
}

// ---- square root -------------------------------------------------------------
//
// Principal square root (the one whose eigenvalues have positive real part)
// by the product form of the Denman-Beavers iteration with determinant
// scaling: Cheng, Higham, Kenney & Laub, "Approximating the logarithm of a
// matrix to specified accuracy", SIAM J. Matrix Anal. Appl. 22(4), 2001
// (product form, their eq. (2.5)); scaling as in Higham, "Functions of
// Matrices: Theory and Computation", SIAM 2008, Section 6.5:
//   M_0 = Y_0 = A,  mu_k = |det M_k|^(-1/(2N))  (from the LU's pivots, in
//                                               logarithms: no overflow),
//   Y_{k+1} = (mu_k / 2) Y_k (I + mu_k^-2 M_k^-1)    = Y_k M_k^-1 S_k / 2,
//   M_{k+1} = (I + (mu_k^2 M_k + mu_k^-2 M_k^-1) / 2) / 2 = S_k M_k^-1 S_k / 4,
// with S_k = mu_k M_k + mu_k^-1 I. The factored right-hand forms are the ones
// evaluated: near the branch cut the sum form cancels catastrophically. For
// a rotation by pi - e, M_1 = (2I + A + A^-1)/4 = cos^2(theta/2) I ~ e^2/4
// would be formed from O(1) terms with absolute error u, i.e. relative error
// u / e^2 (all digits lost at e = 1e-8), while S_0 = A + I is exact
// (Sterbenz) and S_0 A^-1 S_0 keeps relative accuracy.
// Throughout M_k = Y_k^2 A^{-1} (all iterates are rational functions of A and
// commute), so ||M_k - I|| small certifies Y_k^2 = A to that relative
// accuracy; Y_k -> A^{1/2} and M_k -> I quadratically (on each eigenvalue
// M_{k+1} - 1 = (M_k - 1)^2 / (4 M_k) once mu ~ 1). Scaling makes the early,
// linearly convergent phase short for large or small ||A||.
//
// Why a real input with an eigenvalue on the closed negative real axis never
// converges: on such an eigenvalue lambda < 0 (or 0) of M_k, the update maps
// lambda to (1 + (x + 1/x)/2)/2 with x = mu^2 lambda < 0, and x + 1/x <= -2,
// so the eigenvalue stays <= 0 and ||M_k - I|| >= 1 for ever; a zero
// eigenvalue is a zero pivot. The iteration therefore stops after
// max_sqrt_iterations() steps and reports failure: no check of the result
// is needed.
//
// Eigenvalues near the cut converge slowly: the Newton iteration for
// sqrt(lambda) contracts the Cayley ratio rho = (y - sqrt(lambda)) / (y +
// sqrt(lambda)) as rho_{k+1} = rho_k^2, and for lambda = e^{i(pi - e)},
// |rho_0| = tan(pi/4 - e/4) ~ 1 - e/2, so ~log2(1/e) + 6 steps are needed.
// digits + 16 steps cover every e down to the unit roundoff.
template <class Scalar>
constexpr int max_sqrt_iterations() {
  return std::numeric_limits<Scalar>::digits + 16;
}

// root = A^{1/2}, or false (see above).
template <class Scalar, int N>
bool matrix_sqrt(const SquareMatrix<Scalar, N>& a, SquareMatrix<Scalar, N>& root) {
  using std::exp;
  using std::sqrt;
  using Matrix = SquareMatrix<Scalar, N>;
  if (!a.allFinite()) return false;
  const Matrix identity = Matrix::Identity();
  // Once ||M - I|| <= sqrt(u), one more step brings it to ~u^2 / 4, below
  // rounding: stop after that step. An exactly converged M stops at once.
  const Scalar quadratic_regime = sqrt(std::numeric_limits<Scalar>::epsilon());
  Matrix m = a;
  Matrix y = a;
  bool last_step = false;
  for (int iteration = 0; iteration < max_sqrt_iterations<Scalar>(); ++iteration) {
    Matrix m_inverse;
    Scalar log_determinant = 0;
    if (!detail::solve<Scalar, N>(m, identity, m_inverse, &log_determinant)) return false;
    const Scalar mu = exp(-log_determinant / Scalar(2 * N));
    if (!std::isfinite(mu) || !(mu > 0)) return false;
    // The updates in factored form (see above): S = mu M + I / mu.
    const Matrix shifted = mu * m + identity / mu;
    const Matrix factor = m_inverse * shifted;
    y = (y * factor / 2).eval();
    m = shifted * factor / 4;
    const Scalar distance = detail::norm1(Matrix(m - identity));
    if (!std::isfinite(distance) || !y.allFinite()) return false;
    if (last_step || distance == 0) {
      if (!(distance <= quadratic_regime)) return false;
      root = y;
      return true;
    }
    last_step = distance <= quadratic_regime;
  }
  return false;
}

// ---- logarithm ---------------------------------------------------------------
//
// Principal logarithm (eigenvalues with imaginary part in (-pi, pi)) by
// inverse scaling and squaring, after Al-Mohy & Higham, "Improved inverse
// scaling and squaring algorithms for the matrix logarithm", SIAM J. Sci.
// Comput. 34(4), 2012, without their Schur form:
//
//  1. Take square roots R_k = R_{k-1}^{1/2}, R_0 = A, until Z_s = R_s - I has
//     ||Z_s||_1 <= 1/2; log A = 2^s log(I + Z_s). Z_s is not formed as R_s - I
//     (which cancels as R_s -> I) but by the paper's recurrence
//     (its Section 2, computing A^{1/2^s} - I accurately):
//       Z_k = (R_k + I)^{-1} Z_{k-1},  Z_0 = A - I,
//     exact since (R_k - I)(R_k + I) = R_{k-1} - I and all R_k commute;
//     R_k + I is well conditioned because R_k's eigenvalues have positive
//     real part.
//  2. log(I + Z) = 2 atanh(W) = 2 sum_{k>=0} W^{2k+1} / (2k+1), with
//     W = (2I + Z)^{-1} Z (Gregory's series; I + Z = (I + W)(I - W)^{-1}).
//     ||W|| <= ||Z|| / (2 - ||Z||) <= 1/3, and the tail after K terms is at
//     most 2 ||W||^(2K+1) / ((2K+1)(1 - ||W||^2)): the number of terms is the
//     least K that puts it below u ||W|| (at most ~12 for double, ~37 for
//     quad), evaluated by Horner's rule in W^2.
//
// The threshold 1/2 balances the two costs: one more square root (4-5
// Denman-Beavers steps, each an LU inverse) buys ~7 fewer series terms (one
// matrix product each).
constexpr int max_square_roots() {
  return 64;
}

// log(A), or a matrix of NaN (see the top of this file).
template <class Scalar, int N>
SquareMatrix<Scalar, N> matrix_log(const SquareMatrix<Scalar, N>& a) {
  using Matrix = SquareMatrix<Scalar, N>;
  const Matrix identity = Matrix::Identity();
  if (!a.allFinite()) return detail::not_a_matrix<Scalar, N>();
  const Scalar near_identity = Scalar(0.5);
  Matrix root = a;
  Matrix z = a - identity;
  int square_roots = 0;
  while (!(detail::norm1(z) <= near_identity)) {
    Matrix next_root;
    if (square_roots == max_square_roots() || !matrix_sqrt(root, next_root)) {
      return detail::not_a_matrix<Scalar, N>();
    }
    Matrix next_z;
    if (!detail::solve<Scalar, N>(Matrix(next_root + identity), z, next_z)) {
      return detail::not_a_matrix<Scalar, N>();
    }
    root = next_root;
    z = next_z;
    ++square_roots;
  }

  Matrix w;
  if (!detail::solve<Scalar, N>(Matrix(2 * identity + z), z, w)) {
    return detail::not_a_matrix<Scalar, N>();
  }
  // Terms: the least K with ||W||^(2K) / ((2K+1)(1 - ||W||^2)) <= u / 2
  // (the tail bound relative to the leading term 2 ||W||).
  const Scalar omega = detail::norm1(w);
  const Scalar omega2 = omega * omega;
  const Scalar target = std::numeric_limits<Scalar>::epsilon() / 2 * (1 - omega2);
  constexpr int max_terms = 64;  // omega <= 1/3: 3^-128 is below any unit roundoff
  int terms = 1;
  for (Scalar power = omega2; terms < max_terms && power / Scalar(2 * terms + 1) > target;
       ++terms) {
    power *= omega2;
  }
  const Matrix w2 = w * w;
  Matrix sum = identity / Scalar(2 * terms - 1);
  for (int k = terms - 2; k >= 0; --k)
    sum = (w2 * sum + identity / Scalar(2 * k + 1)).eval();
  const Matrix logarithm = std::ldexp(Scalar(2), square_roots) * (w * sum);
  if (!logarithm.allFinite()) return detail::not_a_matrix<Scalar, N>();
  return logarithm;
}

}  // namespace math
}  // namespace bireg
