// bireg: a block-banded matrix and its solve, for the spline's
// Gauss-Newton step (docs/splines.md §9). K_cl = 0 for |c - l| > k, with
// d x d blocks: M (2k + 1) blocks stored, the solve block LU without
// pivoting between blocks (K -> -H kron I near the identity, H = B^T W B
// positive definite under Schoenberg-Whitney, where block elimination
// needs no pivoting) and partial pivoting within each d x d pivot.
// O(M k^2 d^3) to factor, O(M k d^2) per solve after that; no
// allocation after construction.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "bireg/math/small_lu.hpp"

namespace bireg {

template <class Block, class Vector>
class BlockBandedMatrix {
 public:
  using Scalar = typename Block::Scalar;

  BlockBandedMatrix(std::size_t rows, std::size_t band)
      : rows_(rows),
        band_(band),
        blocks_(rows * (2 * band + 1), Block::Zero()),
        work_(blocks_),
        pivot_inverse_(rows, Block::Zero()) {}

  std::size_t rows() const { return rows_; }
  std::size_t band() const { return band_; }

  void set_zero() {
    std::fill(blocks_.begin(), blocks_.end(), Block::Zero());
    factored_ = false;
  }

  // Block (c, l); precondition |c - l| <= band.
  Block& operator()(std::size_t c, std::size_t l) { return blocks_[index(c, l)]; }
  const Block& operator()(std::size_t c, std::size_t l) const { return blocks_[index(c, l)]; }

  // Solves K x = rhs in place. False (rhs then unspecified) when a pivot
  // is singular to working precision or the solution is not finite.
  bool solve(std::vector<Vector>& rhs) { return factorize() && substitute(rhs); }

  // The block LU of K, kept for substitute(): false when a pivot is
  // singular to working precision (U's diagonal within a pivot spans more
  // than 1/(d eps), a cheap stand-in for the condition number).
  bool factorize() {
    work_ = blocks_;
    factored_ = false;
    for (std::size_t c = 0; c < rows_; ++c) {
      const SmallLU<Block> pivot(at(c, c));
      if (!pivot.invertible()) return false;
      pivot_inverse_[c] = pivot.inverse();
      const std::size_t last = std::min(rows_ - 1, c + band_);
      for (std::size_t r = c + 1; r <= last; ++r) {
        at(r, c) = at(r, c) * pivot_inverse_[c];  // the multiplier, L's block
        for (std::size_t q = c + 1; q <= last; ++q)
          at(r, q).noalias() -= at(r, c) * at(c, q);
      }
    }
    factored_ = true;
    return true;
  }

  // Solves K x = rhs in place with the last factorize()'s LU (a
  // precondition: it returned true since K last changed). False when the
  // solution is not finite.
  bool substitute(std::vector<Vector>& rhs) const {
    if (!factored_) return false;
    for (std::size_t c = 0; c < rows_; ++c) {
      const std::size_t last = std::min(rows_ - 1, c + band_);
      for (std::size_t r = c + 1; r <= last; ++r)
        rhs[r].noalias() -= at(r, c) * rhs[c];
    }
    for (std::size_t c = rows_; c-- > 0;) {
      Vector sum = rhs[c];
      const std::size_t last = std::min(rows_ - 1, c + band_);
      for (std::size_t q = c + 1; q <= last; ++q)
        sum.noalias() -= at(c, q) * rhs[q];
      rhs[c] = pivot_inverse_[c] * sum;
      if (!rhs[c].allFinite()) return false;
    }
    return true;
  }

 private:
  std::size_t index(std::size_t c, std::size_t l) const {
    return c * (2 * band_ + 1) + (l + band_ - c);
  }
  Block& at(std::size_t c, std::size_t l) { return work_[index(c, l)]; }
  const Block& at(std::size_t c, std::size_t l) const { return work_[index(c, l)]; }

  std::size_t rows_, band_;
  std::vector<Block> blocks_, work_, pivot_inverse_;
  bool factored_ = false;
};

}  // namespace bireg
