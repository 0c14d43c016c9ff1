// Membership of many matrices at once, stored row-major one after another
// (numpy's (N, n, n) in C order): first_non_element<G>(data, count, tol)
// is the index of the first matrix that G::is_element(matrix, tol) refuses,
// or count when every one is an element.
//
// For SO(3) and SE(3) the tests of is_element (SO3::is_rotation's seven
// departures of R^T R from I and of det R from 1, SE(3)'s last row, a finite
// translation) are straight-line arithmetic on the entries
// (groups/membership.hpp), here evaluated for a block of matrices before any
// verdict is read: a loop without branches, which a compiler vectorizes across
// matrices where the target can gather (AVX2, AVX-512). Per matrix in cache, on
// the 2-core AMD EPYC VM (GCC 12, 2026-11-29, bench_groups built with no
// -march, -march=haswell and -march=skylake-avx512): SE(3), this loop 8.0, 5.6
// and 5.0 ns against is_element one by one 10.1, 10.3 and 10.6; SO(3), 6.1, 4.8
// and 5.0 against 4.5 to 5.7, so the loop gains on SE(3) only (is_element took
// 11.6 and 13.6 ns before it shared this arithmetic). A caller that wants the
// vector width of the CPU it runs on compiles its call once per target (the
// Python module does, with GCC's target_clones).
//
// The departures are those of is_element, computed by the same functions;
// only a compiler's contraction of them into fused multiply-adds may differ
// from one target (or one inlining) to another, so a matrix within a
// rounding error of the tolerance may be judged either way. An infinite
// tolerance takes is_element itself, which then checks finiteness apart.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "bireg/groups/membership.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"

namespace bireg {

// Matrices per block of first_non_element: 256 SE(3) matrices are 32 KiB.
// A caller that checks a long array block by block (the Python module's
// batched maps) may use the same number.
inline constexpr std::size_t kElementCheckBlock = 256;

namespace element_check_detail {

// SO(3): the rotation alone.
template <class Scalar>
inline std::int64_t within(const SO3<Scalar>&, const Scalar* m, Scalar tol) {
  return membership_detail::rotation_within(m, 3, tol);
}

// SE(3): the rotation block, the last row (0, 0, 0, 1) and a finite
// translation.
template <class Scalar>
inline std::int64_t within(const SE3<Scalar>&, const Scalar* m, Scalar tol) {
  return membership_detail::pose_within(m, tol);
}

template <class G>
inline constexpr bool kStraightLine = false;
template <class Scalar>
inline constexpr bool kStraightLine<SO3<Scalar>> = true;
template <class Scalar>
inline constexpr bool kStraightLine<SE3<Scalar>> = true;

}  // namespace element_check_detail

template <class G>
std::size_t first_non_element(
    const typename G::Scalar* data, std::size_t count,
    typename G::Scalar tol = default_element_tolerance<typename G::Scalar>()) {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  static_assert(
      Element::RowsAtCompileTime == Element::ColsAtCompileTime && Element::RowsAtCompileTime > 0,
      "first_non_element: G's elements must be square matrices of a fixed size");
  constexpr int kSide = int(Element::RowsAtCompileTime);
  constexpr std::size_t kEntries = std::size_t(kSide) * std::size_t(kSide);
  using RowMajor = Eigen::Matrix<Scalar, kSide, kSide, Eigen::RowMajor>;
  using std::abs;
  const bool finite_tolerance = abs(tol) <= std::numeric_limits<Scalar>::max();
  if constexpr (element_check_detail::kStraightLine<G>) {
    if (finite_tolerance) {
      std::int64_t verdicts[kElementCheckBlock];
      for (std::size_t begin = 0; begin < count; begin += kElementCheckBlock) {
        const std::size_t size = std::min(kElementCheckBlock, count - begin);
        const Scalar* block = data + begin * kEntries;
        for (std::size_t i = 0; i < size; ++i)
          verdicts[i] = element_check_detail::within(G{}, block + i * kEntries, tol);
        for (std::size_t i = 0; i < size; ++i)
          if (!verdicts[i]) return begin + i;
      }
      return count;
    }
  }
  for (std::size_t i = 0; i < count; ++i) {
    const Element element = Eigen::Map<const RowMajor>(data + i * kEntries);
    if (!G::is_element(element, tol)) return i;
  }
  return count;
}

}  // namespace bireg
