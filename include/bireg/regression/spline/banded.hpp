// bireg: a block-banded matrix and its solve, for the spline's
// Gauss-Newton step (docs/splines.md §9). K_cl = 0 for |c - l| > k, with
// d x d blocks: M (2k + 1) blocks stored, the solve block LU without
// pivoting between blocks (K -> -H kron I near the identity, H = B^T W B
// positive definite under Schoenberg-Whitney, where block elimination
// needs no pivoting, in any order) and partial pivoting within each d x d
// pivot. O(M k^2 d^3) to factor, O(M k d^2) per solve after that; no
// allocation after construction. The factors overwrite K (a fit solves
// with each K once, and a copy of M (2k + 1) blocks, 5 MB for 1e4 SO(3)
// control points, cost a page-faulting allocation and a copy per step).
//
// Two sides and an interface (docs/splines.md §9, "the solve on two
// threads"). From 5k rows on, the k rows I = [s, s + k), s = (M - k) / 2,
// separate a top T = [0, s) from a bottom B = [s + k, M): no row of T
// couples to a column of B or back (|c - l| > k). Ordered T, B, I, K is
// an arrow: T's block rows are eliminated downward (LU), B's upward from
// row M - 1 (so that the rows they leave to I are B's last, as T's are),
// each touching I only in I's rows, and I, holding both sides' Schur
// updates, is eliminated last. The two sides are independent and run on
// two threads when solve() is given a pool. The split depends on M and k
// alone, so the factors, and every solution, are the same bits for any
// thread count; below 5k rows the whole matrix is one downward sweep.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "bireg/math/small_lu.hpp"
#include "bireg/regression/parallel.hpp"

namespace bireg {

template <class Block, class Vector>
class BlockBandedMatrix {
 public:
  using Scalar = typename Block::Scalar;

  BlockBandedMatrix(std::size_t rows, std::size_t band)
      : rows_(rows),
        band_(band),
        split_(band > 0 && rows >= 5 * band ? (rows - band) / 2 : rows),
        interface_end_(std::min(rows, split_ + band)),
        blocks_(rows * (2 * band + 1), Block::Zero()),
        pivot_inverse_(rows, Block::Zero()) {}

  std::size_t rows() const { return rows_; }
  std::size_t band() const { return band_; }

  // Block (c, l) of K, or of its factors after factorize() (a change of K
  // calls for factorize() before the next substitute()); precondition
  // |c - l| <= band.
  Block& operator()(std::size_t c, std::size_t l) { return blocks_[index(c, l)]; }
  const Block& operator()(std::size_t c, std::size_t l) const { return blocks_[index(c, l)]; }

  // Solves K x = rhs in place, the two sides on `pool`'s threads when
  // given. False (rhs then unspecified) when a pivot is singular to
  // working precision or the solution is not finite.
  bool solve(std::vector<Vector>& rhs, ChunkPool* pool = nullptr) {
    return factorize(pool) && substitute(rhs, pool);
  }

  // The block LU of K, in K's place, for substitute(): false (K then
  // partly overwritten) when a pivot is singular to working precision
  // (U's diagonal within a pivot spans more than 1/(d eps), a cheap
  // stand-in for the condition number).
  bool factorize(ChunkPool* pool = nullptr) {
    factored_ = false;
    bool side_invertible[2] = {true, true};
    on_both_sides(pool, [&](std::size_t side) {
      side_invertible[side] = side == 0 ? eliminate_top() : eliminate_bottom();
    });
    if (!side_invertible[0] || !side_invertible[1]) return false;
    // B's Schur updates of I x I, left out of eliminate_bottom() because
    // T writes the same blocks: from the last k pivots of B's upward
    // sweep (rows s + k .. s + 2k - 1), in that sweep's order.
    for (std::size_t c = bottom_interface_end(); c-- > interface_end_;) {
      for (std::size_t r = c - band_; r < interface_end_; ++r)
        for (std::size_t q = c - band_; q < interface_end_; ++q)
          at(r, q).noalias() -= at(r, c) * at(c, q);
    }
    // I, downward, within its own rows and columns.
    for (std::size_t c = split_; c < interface_end_; ++c) {
      if (!invert_pivot(c)) return false;
      for (std::size_t r = c + 1; r < interface_end_; ++r) {
        at(r, c) = at(r, c) * pivot_inverse_[c];
        for (std::size_t q = c + 1; q < interface_end_; ++q)
          at(r, q).noalias() -= at(r, c) * at(c, q);
      }
    }
    factored_ = true;
    return true;
  }

  // Solves K x = rhs in place with the last factorize()'s LU (a
  // precondition: it returned true since K last changed), the two sides
  // on `pool`'s threads when given. False when the solution is not
  // finite.
  bool substitute(std::vector<Vector>& rhs, ChunkPool* pool = nullptr) const {
    if (!factored_) return false;
    // L y = rhs: T downward, B upward, then B's share of I's rows and I.
    on_both_sides(pool, [&](std::size_t side) {
      if (side == 0) {
        for (std::size_t c = 0; c < split_; ++c) {
          for (std::size_t r = c + 1; r <= last_coupled(c); ++r)
            rhs[r].noalias() -= at(r, c) * rhs[c];
        }
      } else {
        for (std::size_t c = rows_; c-- > interface_end_;) {
          for (std::size_t r = std::max(c - band_, interface_end_); r < c; ++r)
            rhs[r].noalias() -= at(r, c) * rhs[c];
        }
      }
    });
    for (std::size_t c = bottom_interface_end(); c-- > interface_end_;) {
      for (std::size_t r = c - band_; r < interface_end_; ++r)
        rhs[r].noalias() -= at(r, c) * rhs[c];
    }
    for (std::size_t c = split_; c < interface_end_; ++c) {
      for (std::size_t r = c + 1; r < interface_end_; ++r)
        rhs[r].noalias() -= at(r, c) * rhs[c];
    }
    // U x = y: I upward, then T upward and B downward from it.
    bool finite[2] = {true, true};
    for (std::size_t c = interface_end_; c-- > split_;) {
      Vector sum = rhs[c];
      for (std::size_t q = c + 1; q < interface_end_; ++q)
        sum.noalias() -= at(c, q) * rhs[q];
      rhs[c] = pivot_inverse_[c] * sum;
      finite[0] = finite[0] && rhs[c].allFinite();
    }
    on_both_sides(pool, [&](std::size_t side) {
      bool all_finite = true;
      if (side == 0) {
        for (std::size_t c = split_; c-- > 0;) {
          Vector sum = rhs[c];
          for (std::size_t q = c + 1; q <= last_coupled(c); ++q)
            sum.noalias() -= at(c, q) * rhs[q];
          rhs[c] = pivot_inverse_[c] * sum;
          all_finite = all_finite && rhs[c].allFinite();
        }
      } else {
        for (std::size_t c = interface_end_; c < rows_; ++c) {
          Vector sum = rhs[c];
          for (std::size_t q = c - band_; q < c; ++q)
            sum.noalias() -= at(c, q) * rhs[q];
          rhs[c] = pivot_inverse_[c] * sum;
          all_finite = all_finite && rhs[c].allFinite();
        }
      }
      finite[side] = finite[side] && all_finite;
    });
    return finite[0] && finite[1];
  }

 private:
  std::size_t index(std::size_t c, std::size_t l) const {
    return c * (2 * band_ + 1) + (l + band_ - c);
  }
  Block& at(std::size_t c, std::size_t l) { return blocks_[index(c, l)]; }
  const Block& at(std::size_t c, std::size_t l) const { return blocks_[index(c, l)]; }

  // The last row (column) coupled to column (row) c below (right of) the
  // diagonal.
  std::size_t last_coupled(std::size_t c) const { return std::min(rows_ - 1, c + band_); }

  // One past B's last pivot that updates I: B's first k rows.
  std::size_t bottom_interface_end() const { return std::min(rows_, interface_end_ + band_); }

  // body(0) for T and body(1) for B, on two threads when there is a pool
  // and a split.
  template <class Body>
  void on_both_sides(ChunkPool* pool, const Body& body) const {
    run_pieces(split_ < rows_ ? pool : nullptr, 2, body);
  }

  bool invert_pivot(std::size_t c) {
    const SmallLU<Block> pivot(at(c, c));
    if (!pivot.invertible()) return false;
    pivot_inverse_[c] = pivot.inverse();
    return true;
  }

  // T's columns, downward: the multipliers L_rc and the Schur updates of
  // every row below within the band (I's rows among them).
  bool eliminate_top() {
    for (std::size_t c = 0; c < split_; ++c) {
      if (!invert_pivot(c)) return false;
      const std::size_t last = last_coupled(c);
      for (std::size_t r = c + 1; r <= last; ++r) {
        at(r, c) = at(r, c) * pivot_inverse_[c];  // the multiplier, L's block
        for (std::size_t q = c + 1; q <= last; ++q)
          at(r, q).noalias() -= at(r, c) * at(c, q);
      }
    }
    return true;
  }

  // B's columns, upward from M - 1: the multipliers and the Schur updates
  // of every row above within the band, except I x I (factorize() adds
  // those once T is done).
  bool eliminate_bottom() {
    for (std::size_t c = rows_; c-- > interface_end_;) {
      if (!invert_pivot(c)) return false;
      const std::size_t first = c - band_;
      for (std::size_t r = first; r < c; ++r) {
        at(r, c) = at(r, c) * pivot_inverse_[c];
        for (std::size_t q = first; q < c; ++q) {
          if (r < interface_end_ && q < interface_end_) continue;
          at(r, q).noalias() -= at(r, c) * at(c, q);
        }
      }
    }
    return true;
  }

  std::size_t rows_, band_;
  std::size_t split_;          // s: T = [0, s); rows_ when there is no split
  std::size_t interface_end_;  // s + k: I = [s, s + k), B = [s + k, M)
  std::vector<Block> blocks_, pivot_inverse_;
  bool factored_ = false;
};

}  // namespace bireg
