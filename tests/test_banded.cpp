// The spline's block-banded solve (regression/spline/banded.hpp): its two
// sides and interface against a dense solve of the same matrix, for every
// row count across the split's threshold (5k rows), bands 1-3 and blocks of
// 1, 3 and 6; the same bits with and without a pool; singular pivots found
// on either side and in the interface.
//
// Tolerance: LU without pivoting between blocks is backward stable when
// the growth of its blocks is O(1), as it is for the strongly shifted
// diagonal blocks here (and for K near -H kron I, H positive definite):
// the computed x satisfies ||K x - b|| <= c n eps (||K|| ||x|| + ||b||)
// with n = M d unknowns and c a small constant (Higham, Accuracy and
// Stability of Numerical Algorithms, 2nd ed., Theorem 9.4 for the solve
// and chapter 13 for block LU); c = 4, with infinity norms.
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/regression/spline/banded.hpp"
#include "catch.hpp"

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

template <int D>
struct Banded {
  using Block = Eigen::Matrix<double, D, D>;
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = bireg::BlockBandedMatrix<Block, Vector>;
};

// A random block-banded K with M block rows, band k: Gaussian blocks,
// each diagonal block shifted by -(2k + 1) d (well conditioned for these
// seeds; the sign of K near -H kron I); also returned dense.
template <int D>
typename Banded<D>::Matrix random_banded(std::mt19937& rng, std::size_t m, std::size_t k,
                                         Eigen::MatrixXd& dense) {
  using Block = typename Banded<D>::Block;
  std::normal_distribution<double> normal(0.0, 1.0);
  typename Banded<D>::Matrix matrix(m, k);
  dense = Eigen::MatrixXd::Zero(Eigen::Index(m) * D, Eigen::Index(m) * D);
  for (std::size_t c = 0; c < m; ++c) {
    for (std::size_t l = c > k ? c - k : 0; l <= std::min(m - 1, c + k); ++l) {
      Block block;
      for (int e = 0; e < D * D; ++e)
        block(e) = normal(rng);
      if (c == l) block -= double((2 * k + 1) * D) * Block::Identity();
      matrix(c, l) = block;
      dense.block<D, D>(Eigen::Index(c) * D, Eigen::Index(l) * D) = block;
    }
  }
  return matrix;
}

template <int D>
std::vector<typename Banded<D>::Vector> random_rhs(std::mt19937& rng, std::size_t m) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<typename Banded<D>::Vector> rhs(m);
  for (auto& v : rhs)
    for (int e = 0; e < D; ++e)
      v(e) = normal(rng);
  return rhs;
}

template <int D>
Eigen::VectorXd stacked(const std::vector<typename Banded<D>::Vector>& parts) {
  Eigen::VectorXd out(Eigen::Index(parts.size()) * D);
  for (std::size_t c = 0; c < parts.size(); ++c)
    out.segment<D>(Eigen::Index(c) * D) = parts[c];
  return out;
}

template <int D>
void check_against_dense(std::mt19937& rng) {
  for (std::size_t k = 1; k <= 3; ++k) {
    for (std::size_t m = 1; m <= 8 * k + 3; ++m) {
      CAPTURE(D, k, m);
      Eigen::MatrixXd dense;
      auto matrix = random_banded<D>(rng, m, k, dense);
      const auto b = random_rhs<D>(rng, m);
      auto x = b;
      REQUIRE(matrix.solve(x));
      const Eigen::VectorXd bx = stacked<D>(b), xx = stacked<D>(x);
      const double n = double(m * D);
      const double residual = (dense * xx - bx).lpNorm<Eigen::Infinity>();
      const double scale =
          dense.cwiseAbs().rowwise().sum().maxCoeff() * xx.lpNorm<Eigen::Infinity>() +
          bx.lpNorm<Eigen::Infinity>();
      CHECK(residual <= 4 * n * kEps * scale);
      // The dense solve agrees to the condition number's share.
      const Eigen::VectorXd reference = dense.partialPivLu().solve(bx);
      CHECK((reference - xx).lpNorm<Eigen::Infinity>() <=
            1e3 * n * kEps * reference.lpNorm<Eigen::Infinity>());
      // A second right-hand side on the same factors.
      const auto b2 = random_rhs<D>(rng, m);
      auto x2 = b2;
      REQUIRE(matrix.substitute(x2));
      const Eigen::VectorXd b2x = stacked<D>(b2), x2x = stacked<D>(x2);
      CHECK((dense * x2x - b2x).lpNorm<Eigen::Infinity>() <=
            4 * n * kEps *
                (dense.cwiseAbs().rowwise().sum().maxCoeff() * x2x.lpNorm<Eigen::Infinity>() +
                 b2x.lpNorm<Eigen::Infinity>()));
    }
  }
}

}  // namespace

TEST_CASE("BlockBandedMatrix solves as a dense LU does, split or not", "[spline][banded]") {
  std::mt19937 rng(20261129);
  check_against_dense<1>(rng);
  check_against_dense<3>(rng);
  check_against_dense<6>(rng);
}

TEST_CASE("BlockBandedMatrix: the same bits with a pool of two threads",
          "[spline][banded][threads]") {
  std::mt19937 rng(7);
  bireg::ChunkPool pool(2, 2);
  for (const std::size_t m : {std::size_t(15), std::size_t(16), std::size_t(1001)}) {
    CAPTURE(m);
    Eigen::MatrixXd dense;
    auto serial = random_banded<3>(rng, m, 3, dense);
    auto parallel = serial;
    const auto b = random_rhs<3>(rng, m);
    auto x_serial = b, x_parallel = b;
    REQUIRE(serial.solve(x_serial));
    REQUIRE(parallel.solve(x_parallel, &pool));
    for (std::size_t c = 0; c < m; ++c)
      CHECK(x_serial[c] == x_parallel[c]);
  }
}

TEST_CASE("BlockBandedMatrix refuses a singular pivot on either side and in the interface",
          "[spline][banded][hostile]") {
  // M = 20, k = 3: T = [0, 8), I = [8, 11), B = [11, 20).
  constexpr std::size_t kRows = 20, kBand = 3;
  for (const std::size_t zero_row :
       {std::size_t(0), std::size_t(5), std::size_t(9), std::size_t(12), std::size_t(19)}) {
    CAPTURE(zero_row);
    std::mt19937 rng(11);
    Eigen::MatrixXd dense;
    auto matrix = random_banded<3>(rng, kRows, kBand, dense);
    // A pivot block that is zero after the elimination reaches it: the
    // whole block row and column zero (K singular).
    for (std::size_t l = zero_row > kBand ? zero_row - kBand : 0;
         l <= std::min(kRows - 1, zero_row + kBand); ++l) {
      matrix(zero_row, l).setZero();
      matrix(l, zero_row).setZero();
    }
    auto x = random_rhs<3>(rng, kRows);
    CHECK_FALSE(matrix.solve(x));
    CHECK_FALSE(matrix.substitute(x));  // no factors to substitute with
  }
  std::mt19937 rng(12);
  Eigen::MatrixXd dense;
  auto matrix = random_banded<3>(rng, kRows, kBand, dense);
  matrix(15, 15)(1, 1) = std::numeric_limits<double>::quiet_NaN();
  auto x = random_rhs<3>(rng, kRows);
  CHECK_FALSE(matrix.solve(x));
}
