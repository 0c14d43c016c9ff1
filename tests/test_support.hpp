// Helpers shared by bireg's tests: random samples and long double references
// that do not reuse the library's closed forms.
#pragma once

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Core>

namespace bireg_test {

template <class Scalar>
constexpr Scalar eps() {
  return std::numeric_limits<Scalar>::epsilon();
}

// A random unit vector of dimension D.
template <int D>
Eigen::Matrix<long double, D, 1> random_unit(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Matrix<long double, D, 1> v;
  do {
    for (int i = 0; i < D; ++i)
      v[i] = normal(rng);
  } while (v.norm() < 1e-3L);
  return v / v.norm();
}

// A random tangent vector with every entry uniform in [-scale, scale].
template <class Tangent>
Tangent random_tangent(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Tangent x;
  for (int i = 0; i < x.size(); ++i)
    x[i] = static_cast<typename Tangent::Scalar>(uniform(rng));
  return x;
}

// Matrix exponential in long double by scaling and squaring a Taylor series:
// the reference for exp and Ad(exp) in the tests. It uses none of the
// library's closed forms. Scaling to norm <= 1/2 and summing until the terms
// vanish gives ~1e-18 relative accuracy for the moderate norms tested.
template <int N>
Eigen::Matrix<long double, N, N> reference_expm(const Eigen::Matrix<long double, N, N>& a) {
  using Matrix = Eigen::Matrix<long double, N, N>;
  const long double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  while (std::ldexp(norm, -squarings) > 0.5L)
    ++squarings;
  const Matrix scaled = a * std::ldexp(1.0L, -squarings);
  Matrix sum = Matrix::Identity();
  Matrix term = Matrix::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * scaled / static_cast<long double>(k);
    sum += term;
  }
  for (int i = 0; i < squarings; ++i)
    sum = sum * sum;
  return sum;
}

// Rotation matrix of the rotation vector theta * axis (unit axis), built in
// long double from the unit quaternion (cos(theta/2), sin(theta/2) axis):
// an independent path from SO3::exp's Rodrigues form.
inline Eigen::Matrix<long double, 3, 3> reference_rotation(
    long double theta, const Eigen::Matrix<long double, 3, 1>& axis) {
  const long double w = std::cos(theta / 2);
  const Eigen::Matrix<long double, 3, 1> v = std::sin(theta / 2) * axis;
  const long double x = v[0], y = v[1], z = v[2];
  Eigen::Matrix<long double, 3, 3> r;
  r << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return r;
}

// Largest absolute entry of a - b, divided by the largest absolute entry of b
// (or 1 if b vanishes): "relative error" of a matrix or vector result.
template <class A, class B>
long double relative_error(const A& a, const B& b) {
  const long double diff =
      (a.template cast<long double>() - b.template cast<long double>()).cwiseAbs().maxCoeff();
  const long double scale = b.template cast<long double>().cwiseAbs().maxCoeff();
  return scale > 0 ? diff / scale : diff;
}

}  // namespace bireg_test
