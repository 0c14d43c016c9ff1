// Helpers shared by the spline tests (test_spline.cpp,
// test_spline_inference.cpp): random control points, the distance the
// tests compare elements by, and noisy samples of a spline.
#pragma once

#include <cstddef>
#include <random>
#include <vector>

#include "bireg/spline.hpp"
#include "test_support.hpp"

namespace bireg_test {

// m control points, each a step of N(0, step^2) coordinates from the last.
template <class G>
std::vector<typename G::Element> random_points(std::mt19937& rng, std::size_t m, double step) {
  std::vector<typename G::Element> points{G::exp(normal_tangent<typename G::Tangent>(rng, 1.0))};
  for (std::size_t c = 1; c < m; ++c) {
    points.push_back(
        G::compose(points.back(), G::exp(normal_tangent<typename G::Tangent>(rng, step))));
  }
  return points;
}

// |log(a^{-1} b)|: the distance the tests compare elements by.
template <class G>
double distance(const typename G::Element& a, const typename G::Element& b) {
  return G::log(G::compose(G::inverse(a), b)).norm();
}

// Noisy samples of a spline at n covariates spread over its range: one
// per n-th of it, jittered by up to 0.3 of that, each the curve's value
// times exp of N(0, noise^2) coordinates.
template <class G>
struct Samples {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

template <class G>
Samples<G> sample(const bireg::Spline<G>& curve, std::size_t n, double noise, std::mt19937& rng) {
  Samples<G> out;
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = (double(i) + 0.5 + jitter(rng)) / double(n);
    const double t = curve.t_min() + s * (curve.t_max() - curve.t_min());
    out.t.push_back(t);
    out.f.push_back(G::compose(curve(t), G::exp(normal_tangent<typename G::Tangent>(rng, noise))));
  }
  return out;
}

// The observations translated by g on the left (g f_i) and on the right
// (f_i g): the data of the equivariance and invariance tests.
template <class G>
struct Translated {
  std::vector<typename G::Element> left, right;
};

template <class G>
Translated<G> translated(const std::vector<typename G::Element>& f, const typename G::Element& g) {
  Translated<G> out{f, f};
  for (std::size_t i = 0; i < f.size(); ++i) {
    out.left[i] = G::compose(g, f[i]);
    out.right[i] = G::compose(f[i], g);
  }
  return out;
}

}  // namespace bireg_test
