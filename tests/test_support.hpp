// Helpers shared by bireg's tests: random samples and long double references
// that do not reuse the library's closed forms.
#pragma once

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/so3.hpp"
#include "bireg/testing/group_laws.hpp"
#include "bireg/testing/random.hpp"

namespace bireg_test {

template <class Scalar>
constexpr Scalar eps() {
  return std::numeric_limits<Scalar>::epsilon();
}

// A tangent vector with independent N(0, sd^2) coordinates; sd = 0 gives
// zero (std::normal_distribution requires sd > 0: _GLIBCXX_ASSERTIONS
// aborts on 0). The same draws as normal_distribution(0, sd) for sd > 0.
template <class Tangent>
Tangent normal_tangent(std::mt19937& rng, double sd) {
  std::normal_distribution<double> standard(0.0, 1.0);
  Tangent x;
  for (int i = 0; i < x.size(); ++i)
    x[i] = sd * standard(rng);
  return x;
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

// Random tangent vectors (entries uniform in [-scale, scale]) and the long
// double matrix exponential (scaling and squaring a Taylor series; it uses
// none of the library's closed forms): the ones users get from
// bireg/testing/group_laws.hpp.
using bireg::testing::random_tangent;
using bireg::testing::reference_expm;

// A dense SO(3) trajectory, bench/bench_local_regression.cpp's: n samples
// at 1 kHz from t = 0 of exp(0.5 (sin wt, cos wt - 1, sin 2wt)),
// w = 2 pi / 10 s, each times exp(e), e Gaussian with standard deviation
// `noise` per axis (std::mt19937 seeded with `seed`).
struct So3Trajectory {
  std::vector<bireg::SO3d::Element> f;
  std::vector<double> t;
};

inline So3Trajectory dense_so3_trajectory(int n, double noise, unsigned seed) {
  using SO3 = bireg::SO3d;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, noise);
  const double omega = 2 * M_PI / 10;
  So3Trajectory data;
  for (int i = 0; i < n; ++i) {
    const double t = i * 1e-3;
    const SO3::Tangent curve =
        0.5 * SO3::Tangent(std::sin(omega * t), std::cos(omega * t) - 1, std::sin(2 * omega * t));
    const SO3::Tangent e = bireg::testing::draw_vector<SO3::Tangent>(rng, normal);
    data.f.push_back(SO3::compose(SO3::exp(curve), SO3::exp(e)));
    data.t.push_back(t);
  }
  return data;
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
  return bireg::testing::relative_difference(a, b);
}

}  // namespace bireg_test
