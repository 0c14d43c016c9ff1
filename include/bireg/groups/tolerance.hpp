// bireg: the default tolerance with which is_element accepts a matrix.
#pragma once

#include <algorithm>
#include <limits>

namespace bireg {

// Real data is rarely exactly on the group: rotation matrices printed with 7
// decimals or renormalised in float are off by ~1e-7. The default accepts
// orthonormality and determinant errors up to 1e-6 (or 64 epsilon, whichever
// is larger, so that float data rounded from double passes); anything further
// off is rejected, since exp/log would silently project it.
template <class Scalar>
Scalar default_element_tolerance() {
  return std::max(Scalar(1e-6), Scalar(64) * std::numeric_limits<Scalar>::epsilon());
}

}  // namespace bireg
