// The trajectory bench_local_regression and bench_spline time: a smooth
// SO(3) curve exp(0.5 (sin w t, cos w t - 1, sin 2 w t)) with
// w = 2 pi / 10 s, sampled at 1 kHz, noise 0.01 rad per axis, seed 7.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "bireg/groups/so3.hpp"
#include "bireg/testing/random.hpp"

namespace bench {

struct SmoothCurve {
  std::vector<bireg::SO3d::Element> f;
  std::vector<double> t;
};

constexpr double kSpacing = 1e-3;  // s: 1 kHz

inline SmoothCurve smooth_curve(int n) {
  using G = bireg::SO3d;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.01);
  const double w = 2 * M_PI / 10;
  SmoothCurve data;
  for (int i = 0; i < n; ++i) {
    const double t = i * kSpacing;
    const G::Tangent c =
        0.5 * G::Tangent(std::sin(w * t), std::cos(w * t) - 1, std::sin(2 * w * t));
    const G::Tangent e = bireg::testing::draw_vector<G::Tangent>(rng, normal);
    data.t.push_back(t);
    data.f.push_back(G::compose(G::exp(c), G::exp(e)));
  }
  return data;
}

}  // namespace bench
