// bireg: the product of homogeneous affine matrices [A t; 0 1], shared by
// SE2, SE3 and Sim3.
#pragma once

#include <Eigen/Core>

namespace bireg {
namespace affine {

// [A1 t1; 0 1] [A2 t2; 0 1] = [A1 A2, A1 t2 + t1; 0 1], block by block: a
// third of the flops of the full product, and the last row stays exactly
// (0 ... 0 1).
template <class Matrix>
Matrix compose(const Matrix& a, const Matrix& b) {
  constexpr int d = Matrix::RowsAtCompileTime - 1;
  Matrix g = Matrix::Identity();
  g.template topLeftCorner<d, d>() =
      a.template topLeftCorner<d, d>() * b.template topLeftCorner<d, d>();
  g.template topRightCorner<d, 1>() =
      a.template topLeftCorner<d, d>() * b.template topRightCorner<d, 1>() +
      a.template topRightCorner<d, 1>();
  return g;
}

}  // namespace affine
}  // namespace bireg
