// bireg: the tests of membership in SO(3) and SE(3) as straight-line
// arithmetic on the matrix entries. One definition, evaluated by
// SO3::is_rotation (hence SO3::is_element), SE3::is_element and the block
// loop of first_non_element (groups/element_check.hpp).
//
// Each test is |departure| <= tol, as an integer 0 or 1 so that a loop over
// many matrices stays in one element width, and the tests are combined
// without branches. A NaN departure fails its comparison, and a NaN or an
// infinite entry makes some departure NaN or infinite, so with a finite tol
// finiteness needs no scan of its own. An infinite tol passes an infinite
// departure: callers then check finiteness apart.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace bireg {
namespace membership_detail {

// 1 when |x| <= tol, else 0 (also for NaN).
template <class Scalar>
inline std::int64_t small(Scalar x, Scalar tol) {
  using std::abs;
  return abs(x) <= tol;
}

// R = [a b c] (columns a, b, c) in SO(3) to within tol, max-norm: R^T R - I
// is symmetric, its six distinct entries the columns' dot products (less 1
// on the diagonal), and det R - 1 = a . (b x c) - 1.
template <class Scalar>
inline std::int64_t rotation_within(Scalar a0, Scalar a1, Scalar a2, Scalar b0, Scalar b1,
                                    Scalar b2, Scalar c0, Scalar c1, Scalar c2, Scalar tol) {
  const Scalar det = a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2) + a2 * (b0 * c1 - b1 * c0);
  return small(a0 * a0 + a1 * a1 + a2 * a2 - 1, tol) & small(b0 * b0 + b1 * b1 + b2 * b2 - 1, tol) &
         small(c0 * c0 + c1 * c1 + c2 * c2 - 1, tol) & small(a0 * b0 + a1 * b1 + a2 * b2, tol) &
         small(a0 * c0 + a1 * c1 + a2 * c2, tol) & small(b0 * c0 + b1 * c1 + b2 * c2, tol) &
         small(det - 1, tol);
}

// The same of the row-major 3 x 3 block whose first entry is at `r`, with
// `stride` numbers between rows.
template <class Scalar>
inline std::int64_t rotation_within(const Scalar* r, std::size_t stride, Scalar tol) {
  return rotation_within(r[0], r[stride], r[2 * stride], r[1], r[stride + 1], r[2 * stride + 1],
                         r[2], r[stride + 2], r[2 * stride + 2], tol);
}

// The rest of SE(3)'s [R t; l]: the last row l = (l0, l1, l2, l3) is
// (0, 0, 0, 1) to within tol, max-norm, and the translation t is finite
// (t_i - t_i is 0 for a finite t_i and NaN otherwise, which fails whatever
// tol is).
template <class Scalar>
inline std::int64_t pose_rest_within(Scalar t0, Scalar t1, Scalar t2, Scalar l0, Scalar l1,
                                     Scalar l2, Scalar l3, Scalar tol) {
  return small(l0, tol) & small(l1, tol) & small(l2, tol) & small(l3 - 1, tol) &
         small(t0 - t0, tol) & small(t1 - t1, tol) & small(t2 - t2, tol);
}

// A row-major 4 x 4 matrix at `m` in SE(3) to within tol (finite tol).
template <class Scalar>
inline std::int64_t pose_within(const Scalar* m, Scalar tol) {
  return rotation_within(m, 4, tol) &
         pose_rest_within(m[3], m[7], m[11], m[12], m[13], m[14], m[15], tol);
}

}  // namespace membership_detail
}  // namespace bireg
