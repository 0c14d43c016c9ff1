// bireg: scatter matrices of left-trivialised tangent vectors and the ratio
// of their determinants (Wilks' Lambda), DESIGN.md section 5.
//
// Under left translation of the data every left-trivialised vector is
// unchanged; under right translation by h all of them are mapped by the one
// matrix Ad_{h^{-1}} (Hanik & von Tycowicz, Theorem 2.4, applied to the
// residuals), so a scatter S = sum w v v^T becomes Ad S Ad^T and the ratio
// det(S_res)/det(S_tot) is unchanged: left and right invariant on every
// group, SE(3) included, where no bi-invariant metric exists.
//
// Where S_tot is singular (planar motion in SE(3), fewer observations than
// d) the determinants are taken on S_tot's numerical range: with U an
// orthonormal basis of the eigenvectors of S_tot whose eigenvalues exceed
// kRangeTolerance times the largest, Lambda = det(U^T S_res U) /
// det(U^T S_tot U) (a pseudo-determinant ratio). Any basis of the same
// subspace gives the same ratio, and Ad maps the range of S_tot onto the
// range of Ad S_tot Ad^T, so the ratio stays invariant as long as the rank
// decision does (it is a threshold on eigenvalues, which Ad changes on
// SE(3): data exactly at the threshold could flip it; planar data sit at
// rounding level, far below it).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "bireg/math/small_lu.hpp"
#include "bireg/math/symmetric_eigen.hpp"

namespace bireg {

// Eigenvalues of S_tot below this, relative to its largest, count as zero.
inline constexpr double kRangeTolerance = 1e-10;

// sum_i w_i v_i v_i^T (weights empty: all 1).
template <class Scalar, int D>
Eigen::Matrix<Scalar, D, D> scatter_matrix(const std::vector<Eigen::Matrix<Scalar, D, 1>>& v,
                                           const std::vector<Scalar>& weights) {
  Eigen::Matrix<Scalar, D, D> s = Eigen::Matrix<Scalar, D, D>::Zero();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Scalar w = weights.empty() ? Scalar(1) : weights[i];
    s.noalias() += w * v[i] * v[i].transpose();
  }
  return s;
}

// The numerical range of a reference scatter matrix, for determinant ratios
// against it.
template <class Scalar, int D>
class ScatterRange {
 public:
  using Matrix = Eigen::Matrix<Scalar, D, D>;
  using Basis = Eigen::Matrix<Scalar, D, Eigen::Dynamic, 0, D, D>;  // fixed capacity: no heap

  explicit ScatterRange(const Matrix& reference) {
    const SymmetricEigen<Scalar, D> eigen = symmetric_eigen(reference);
    const auto& values = eigen.values;  // ascending
    const Scalar largest = values[D - 1];
    int rank = 0;
    for (int k = 0; k < D; ++k)
      if (largest > 0 && values[k] > Scalar(kRangeTolerance) * largest) ++rank;
    rank_ = rank;
    basis_ = eigen.vectors.rightCols(rank);
    reference_log_determinant_ = 0;
    for (int k = D - rank; k < D; ++k)
      reference_log_determinant_ += std::log(values[k]);
  }

  int rank() const { return rank_; }
  bool full() const { return rank_ == D; }

  // det(U^T s U) / det(U^T reference U); 0 when the range is empty.
  Scalar ratio(const Matrix& s) const {
    if (rank_ == 0) return Scalar(0);
    using Projected = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, 0, D, D>;
    // Lazy products and SmallLU: Eigen's dynamic-size kernels would cost
    // seconds of compile time in every user of this header.
    const Projected projected = basis_.transpose().lazyProduct(s.lazyProduct(basis_));
    const Scalar determinant = SmallLU<Projected>(projected).determinant();
    if (!(determinant > 0)) return Scalar(0);
    return std::exp(std::log(determinant) - reference_log_determinant_);
  }

 private:
  int rank_ = 0;
  Basis basis_;
  Scalar reference_log_determinant_ = 0;
};

}  // namespace bireg
