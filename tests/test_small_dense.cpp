// The small dense kernels that replace Eigen's decompositions in the
// statistics (math/symmetric_eigen.hpp, math/small_lu.hpp): each against
// matrices whose answer is known by construction.
//
// Tolerances are the methods' backward-error bounds. A Jacobi sweep is a
// product of about n^2/2 plane rotations, each exact to a few eps, and
// 4-7 sweeps are needed: an entry of V^T V - I or of A V - V diag(values)
// (relative to ||A||) accumulates at most ~n such errors per sweep, so n^2
// eps bounds both for n <= 14 with room for the constant. Eigenvalues then
// move by at most as much (Weyl's inequality). LU with partial pivoting
// has a residual ||A x - b|| <= c n eps ||A|| ||x|| times the growth
// factor, which is O(1) for the random and diagonally dominant matrices
// here; n^2 eps bounds it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>

#include "bireg/math/small_lu.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "catch.hpp"

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

using Dynamic = Eigen::MatrixXd;

Dynamic random_matrix(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Dynamic m(rows, cols);
  for (int k = 0; k < rows * cols; ++k)
    m(k) = normal(rng);
  return m;
}

// A random orthogonal matrix: Gram-Schmidt, twice, on a Gaussian matrix.
Dynamic random_orthogonal(std::mt19937& rng, int n) {
  Dynamic q = random_matrix(rng, n, n);
  for (int pass = 0; pass < 2; ++pass) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < j; ++k)
        q.col(j) -= q.col(k).dot(q.col(j)) * q.col(k);
      q.col(j).normalize();
    }
  }
  return q;
}

// Eigenvalues of a known spectrum: full rank, rank-deficient (zeros and a
// repeated value), and spread over 12 decades.
Eigen::VectorXd spectrum(std::mt19937& rng, int n, int kind) {
  std::uniform_real_distribution<double> uniform(0.5, 2.0);
  Eigen::VectorXd values(n);
  for (int k = 0; k < n; ++k) {
    switch (kind) {
      case 0:
        values[k] = uniform(rng) * (k % 2 == 0 ? 1 : -1);
        break;
      case 1:
        values[k] = k < n / 2 ? 0.0 : 3.0;
        break;
      default:
        values[k] = std::pow(10.0, -12.0 * k / std::max(n - 1, 1)) * uniform(rng);
        break;
    }
  }
  return values;
}

}  // namespace

TEST_CASE("symmetric_eigen diagonalises known spectra to n^2 eps", "[math][symmetric_eigen]") {
  std::mt19937 rng(7);
  for (int n = 1; n <= 14; ++n) {
    for (int kind = 0; kind < 3; ++kind) {
      for (int trial = 0; trial < 5; ++trial) {
        const Eigen::VectorXd lambda = spectrum(rng, n, kind);
        const Dynamic q = random_orthogonal(rng, n);
        const Dynamic a = q * lambda.asDiagonal() * q.transpose();
        const auto eigen = bireg::symmetric_eigen(a);
        const double norm = lambda.cwiseAbs().maxCoeff();
        const double bound = n * n * kEps;
        CAPTURE(n, kind, trial);
        // Ascending, and each the known eigenvalue of its rank.
        Eigen::VectorXd sorted = lambda;
        std::sort(sorted.data(), sorted.data() + n);
        for (int k = 0; k + 1 < n; ++k)
          CHECK(eigen.values[k] <= eigen.values[k + 1]);
        CHECK((eigen.values - sorted).cwiseAbs().maxCoeff() <= bound * norm);
        CHECK(
            (a * eigen.vectors - eigen.vectors * eigen.values.asDiagonal()).cwiseAbs().maxCoeff() <=
            bound * norm);
        CHECK((eigen.vectors.transpose() * eigen.vectors - Dynamic::Identity(n, n))
                  .cwiseAbs()
                  .maxCoeff() <= bound);
      }
    }
  }
}

TEST_CASE("symmetric_eigen on fixed sizes, diagonal and non-finite input",
          "[math][symmetric_eigen]") {
  SECTION("a diagonal matrix is returned sorted, with permuted unit vectors") {
    Eigen::Matrix3d d = Eigen::Vector3d(2.0, -1.0, 0.5).asDiagonal();
    const bireg::SymmetricEigen<double, 3> eigen = bireg::symmetric_eigen(d);
    CHECK(eigen.values == Eigen::Vector3d(-1.0, 0.5, 2.0));
    CHECK(eigen.vectors.cwiseAbs() == (Eigen::Matrix3d() << 0, 0, 1, 1, 0, 0, 0, 1, 0).finished());
  }
  SECTION("asymmetry from rounding is averaged") {
    Eigen::Matrix2d a;
    a << 2.0, 1.0 + 1e-15, 1.0 - 1e-15, 2.0;
    const auto eigen = bireg::symmetric_eigen(a);
    CHECK(std::abs(eigen.values[0] - 1.0) <= 4 * kEps);
    CHECK(std::abs(eigen.values[1] - 3.0) <= 4 * kEps);
  }
  SECTION("entries near overflow and underflow") {
    for (const double scale : {1e300, 1e-300}) {
      Eigen::Matrix2d a;
      a << 2.0, 1.0, 1.0, 2.0;
      const auto eigen = bireg::symmetric_eigen(Eigen::Matrix2d(scale * a));
      CAPTURE(scale);
      CHECK(std::abs(eigen.values[0] / scale - 1.0) <= 8 * kEps);
      CHECK(std::abs(eigen.values[1] / scale - 3.0) <= 8 * kEps);
    }
  }
  SECTION("a matrix with a NaN or an infinity gives NaN, never a number") {
    for (const double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Identity();
      a(2, 4) = a(4, 2) = bad;
      const auto eigen = bireg::symmetric_eigen(a);
      CHECK(eigen.values.array().isNaN().all());
      CHECK(eigen.vectors.array().isNaN().all());
    }
  }
}

TEST_CASE("SmallLU solves, inverts and takes determinants to n^2 eps", "[math][small_lu]") {
  std::mt19937 rng(11);
  for (int n = 1; n <= 14; ++n) {
    for (int trial = 0; trial < 10; ++trial) {
      CAPTURE(n, trial);
      const Dynamic a =
          random_matrix(rng, n, n) + (trial % 2 == 0 ? 0.0 : n) * Dynamic::Identity(n, n);
      const bireg::SmallLU<Dynamic> lu(a);
      REQUIRE(lu.invertible());
      const Dynamic b = random_matrix(rng, n, 3);
      const Dynamic x = lu.solve(b);
      const double scale = a.cwiseAbs().maxCoeff() * x.cwiseAbs().maxCoeff();
      CHECK((a * x - b).cwiseAbs().maxCoeff() <= n * n * kEps * scale);
      const Eigen::VectorXd v = lu.solve(b.col(0));
      CHECK(v == x.col(0));
    }
  }
  SECTION("determinants, signed by the row swaps") {
    for (int n = 1; n <= 12; ++n) {
      const Eigen::VectorXd lambda = spectrum(rng, n, 0);
      const Dynamic q = random_orthogonal(rng, n);
      const double expected = lambda.prod();
      const double determinant =
          bireg::SmallLU<Dynamic>(q * lambda.asDiagonal() * q.transpose()).determinant();
      CAPTURE(n);
      CHECK(std::abs(determinant - expected) <= n * n * kEps * std::abs(expected) * 10);
    }
    Eigen::Matrix3d swap;  // one transposition: det -1, found by pivoting
    swap << 0, 1, 0, 1, 0, 0, 0, 0, 1;
    CHECK(bireg::SmallLU<Eigen::Matrix3d>(swap).determinant() == -1.0);
    CHECK(bireg::SmallLU<Eigen::Matrix3d>(swap).solve(Eigen::Vector3d(1, 2, 3)) ==
          Eigen::Vector3d(2, 1, 3));
  }
  SECTION("singular, nearly singular and non-finite matrices are not invertible") {
    Eigen::Matrix<double, 12, 12> a = Eigen::Matrix<double, 12, 12>::Identity();
    CHECK(bireg::SmallLU<Eigen::Matrix<double, 12, 12>>(a).invertible());
    a.row(7) = a.row(3) * 2;  // rank 11
    CHECK_FALSE(bireg::SmallLU<Eigen::Matrix<double, 12, 12>>(a).invertible());
    a.row(7) = a.row(3) * 2 + 1e-18 * Eigen::Matrix<double, 1, 12>::Ones();
    CHECK_FALSE(bireg::SmallLU<Eigen::Matrix<double, 12, 12>>(a).invertible());
    a = Eigen::Matrix<double, 12, 12>::Identity();
    a(5, 5) = std::numeric_limits<double>::quiet_NaN();
    CHECK_FALSE(bireg::SmallLU<Eigen::Matrix<double, 12, 12>>(a).invertible());
  }
}

// inverse_3x3: by the adjugate where ||A||^3 <= 4 |det A| (residual
// ||A X - I|| <= 48 eps ||A||^3 / |det A| <= 192 eps, max-norms, derived
// beside it), else by SmallLU (n^2 eps ||A|| ||X|| as above); the test's
// own product A X adds 3 eps ||A|| ||X||. A = Q diag(lambda) P^T with two
// random orthogonal Q, P is not symmetric, so a transposed adjugate fails.
TEST_CASE("inverse_3x3 inverts 3 x 3 matrices to the bound of the branch it takes",
          "[math][small_lu]") {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> spread(0.0, 1.0);
  int adjugate_branch = 0;
  for (int trial = 0; trial < 300; ++trial) {
    CAPTURE(trial);
    // Singular values 1, 10^-a, 10^-b, a and b uniform in [0, 1]: about a
    // third of the matrices pass the adjugate's test.
    const Eigen::Vector3d lambda(1.0, std::pow(10.0, -spread(rng)),
                                 (trial % 2 ? -1 : 1) * std::pow(10.0, -spread(rng)));
    const Eigen::Matrix3d a =
        random_orthogonal(rng, 3) * lambda.asDiagonal() * random_orthogonal(rng, 3).transpose();
    const Eigen::Matrix3d x = bireg::inverse_3x3(a);
    const double norm = a.cwiseAbs().maxCoeff();
    const double ratio = norm * norm * norm / std::abs(lambda.prod());  // |det Q| = |det P| = 1
    const bool adjugate = ratio <= 4;
    adjugate_branch += adjugate;
    const double product = 3 * kEps * norm * x.cwiseAbs().maxCoeff();
    const double bound =
        (adjugate ? 48 * kEps * ratio : 9 * kEps * norm * x.cwiseAbs().maxCoeff()) + product;
    CHECK((a * x - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= bound);
  }
  CHECK(adjugate_branch > 30);  // both branches are exercised
  CHECK(adjugate_branch < 270);
  // A rotation (its entries rounded to binary): the adjugate's branch, and
  // the transpose to 48 eps (the residual bound at ratio 1, ||R^{-1}|| = 1)
  // plus R^T R - I from the rounding of R's entries (3 eps an entry, times 3).
  Eigen::Matrix3d rotation;
  rotation << 0.36, 0.48, -0.8, -0.8, 0.6, 0.0, 0.48, 0.64, 0.6;
  CHECK((bireg::inverse_3x3(rotation) - rotation.transpose()).cwiseAbs().maxCoeff() <= 57 * kEps);
  Eigen::Matrix3d singular;  // rows 0 and 1 parallel: the determinant is exactly 0
  singular << 1, 2, 3, 2, 4, 6, 0, 0, 1;
  CHECK_FALSE(bireg::inverse_3x3(singular).allFinite());
}
