// bireg: random vectors whose draws happen in a fixed order, so that a
// fixed seed gives the same data under every compiler.
//
// `Vector3d(normal(rng), normal(rng), normal(rng))` leaves the order of the
// three draws to the compiler: the order in which function arguments are
// evaluated is unspecified ([expr.call]), and GCC evaluates them right to
// left where Clang goes left to right. The same seed then gives a vector
// with its coordinates permuted, a test's simulated data differ between the
// two builds, and a statistical check that holds on one build's sample can
// fail on the other's. The same holds for the two operands of `*` or `+`.
// Draw through these helpers, or into named variables one statement each.
#pragma once

#include <Eigen/Core>

namespace bireg::testing {

// A fixed-size vector whose coordinates are drawn from `distribution` in
// index order: coordinate 0 first.
template <class Vector, class Distribution, class Engine>
Vector draw_vector(Engine& engine, Distribution& distribution) {
  Vector x;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    x[i] = static_cast<typename Vector::Scalar>(distribution(engine));
  return x;
}

}  // namespace bireg::testing
