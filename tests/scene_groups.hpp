// The scene groups' regression checks (issue "Model only what a scene
// requires"), shared by test_scene_groups.cpp (Sim(3), the Heisenberg group,
// SO(3) x R^3, and Sim(3) at the extremes of scale) and
// test_scene_groups_matrix.cpp (SL(3) and GL+(3), whose exp and log are
// Eigen's general matrix functions). Two translation units rather than one:
// GCC's compile time grows faster than linearly with one unit's template
// instantiations. For each group: noise-free recovery, left, right and
// inverse equivariance, and the estimating equations at the solution,
// checked with inverse differentials computed here from their definition.
//
// Distances are intrinsic, |log(b^{-1} a)| (left-invariant, so the same
// tolerance serves elements at scale e^20 and at scale 1).
//
// Tolerances. The fits run to a step tolerance of 1e-13, so the returned
// endpoints sit within ~1e-13 of the fixed point. exp and log are accurate to
// a few epsilon on the closed-form groups and to ~1e-13 on the matrix-function
// groups (Eigen's Pade / Schur-Parlett, see test_matrix_groups.cpp); each
// comparison chains O(10) of them on data of size O(1). We therefore allow
// 1e-9, three orders above both effects and many orders below the O(0.01)
// discrepancy of a wrong convention (noise is 0.05).
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace scene_groups {

using bireg_test::random_tangent;

constexpr double kTolerance = 1e-9;
constexpr double kScale = 0.5;
constexpr double kNoise = 0.05;
constexpr int kObservations = 25;

template <class G>
double distance(const typename G::Element& a, const typename G::Element& b) {
  return static_cast<double>(G::log(G::compose(G::inverse(b), a)).norm());
}

template <class G>
struct Scene {
  typename G::Element g0;
  typename G::Tangent x;
  std::vector<typename G::Element> exact, noisy;
  std::vector<double> t;  // in [0, 1]: the library's normalised covariates are the same
};

template <class G>
Scene<G> make_scene(std::mt19937& rng) {
  using Tangent = typename G::Tangent;
  Scene<G> scene;
  scene.g0 = G::exp(random_tangent<Tangent>(rng, kScale));
  scene.x = random_tangent<Tangent>(rng, kScale);
  for (int i = 0; i < kObservations; ++i) {
    const double s = static_cast<double>(i) / (kObservations - 1);
    scene.exact.push_back(G::compose(scene.g0, G::exp(s * scene.x)));
    scene.noisy.push_back(
        G::compose(scene.exact.back(), G::exp(random_tangent<Tangent>(rng, kNoise))));
    scene.t.push_back(s);
  }
  return scene;
}

template <class G>
bireg::GeodesicRegression<G> regression() {
  typename bireg::GeodesicRegression<G>::Options options;
  options.tolerance = 1e-13;
  return bireg::GeodesicRegression<G>(options);
}

// psi_s(A) = s J_r(X) J_r(s X)^{-1} (DESIGN.md, "Exact form"), with
// J_r(X) = sum_k (-A)^k / (k + 1)! summed in long double until the terms
// vanish (|A| <= ~2 here, 40 terms leave < 1e-30). Independent of the
// library's Bernoulli series and closed forms.
template <int D>
Eigen::Matrix<long double, D, D> reference_psi(const Eigen::Matrix<long double, D, D>& a,
                                               long double s) {
  using Matrix = Eigen::Matrix<long double, D, D>;
  const auto right_jacobian = [](const Matrix& m) {
    Matrix sum = Matrix::Identity(), term = Matrix::Identity();
    for (int k = 1; k < 40; ++k) {
      term = -term * m / static_cast<long double>(k + 1);
      sum += term;
    }
    return sum;
  };
  return s * right_jacobian(a) * right_jacobian(Matrix(s * a)).inverse();
}

// With every solver and method: the scene groups take the same options as
// SE(3).
template <class G>
void check_noise_free_recovery() {
  std::mt19937 rng(501);
  const Scene<G> scene = make_scene<G>(rng);
  for (bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::optimal_linear,
                               bireg::Solver::preconditioned, bireg::Solver::gauss_newton}) {
    for (bireg::Method method : {bireg::Method::exact, bireg::Method::series_adaptive}) {
      typename bireg::GeodesicRegression<G>::Options options;
      options.tolerance = 1e-13;
      options.solver = solver;
      options.method = method;
      const auto fit = bireg::GeodesicRegression<G>(options).fit(scene.exact, scene.t);
      CAPTURE(bireg::to_string(solver), bireg::to_string(method));
      REQUIRE(fit.ok());
      REQUIRE(distance<G>(fit.geodesic->start(), scene.g0) <= kTolerance);
      REQUIRE(distance<G>(fit.geodesic->end(), G::compose(scene.g0, G::exp(scene.x))) <=
              kTolerance);
      REQUIRE(fit.diagnostics.residual_rms <= kTolerance);
    }
  }
}

template <class G>
void check_equivariance() {
  using Element = typename G::Element;
  std::mt19937 rng(502);
  const Scene<G> scene = make_scene<G>(rng);
  const Element h = G::exp(random_tangent<typename G::Tangent>(rng, 2 * kScale));
  std::vector<Element> left, right, inverted;
  for (const Element& f : scene.noisy) {
    left.push_back(G::compose(h, f));
    right.push_back(G::compose(f, h));
    inverted.push_back(G::inverse(f));
  }
  const auto fit = regression<G>();
  const auto base = fit.fit(scene.noisy, scene.t);
  const auto l = fit.fit(left, scene.t);
  const auto r = fit.fit(right, scene.t);
  const auto v = fit.fit(inverted, scene.t);
  REQUIRE((base.ok() && l.ok() && r.ok() && v.ok()));
  for (double s : {0.0, 0.5, 1.0}) {
    const Element b = (*base.geodesic)(s);
    CAPTURE(s);
    REQUIRE(distance<G>((*l.geodesic)(s), G::compose(h, b)) <= kTolerance);
    REQUIRE(distance<G>((*r.geodesic)(s), G::compose(b, h)) <= kTolerance);
    REQUIRE(distance<G>((*v.geodesic)(s), G::inverse(b)) <= kTolerance);
  }
}

// At the solution v0 = sum psi_{1-t}(-A) r and v1 = sum psi_t(A) r vanish.
// The returned endpoints are those whose proposed step is below 1e-13, and
// the step is K^{-1} v with |K| <= ~2 N, so |v| <= 2 N 1e-13 = 5e-12; the
// reference's own rounding adds ~1e-13 |sum r|. A wrong sign or frame in
// the library's psi leaves |v| of the order of the residuals' sum, ~0.1.
template <class G>
void check_estimating_equations() {
  constexpr int d = G::dof;
  using LongMatrix = Eigen::Matrix<long double, d, d>;
  using LongVector = Eigen::Matrix<long double, d, 1>;
  std::mt19937 rng(503);
  const Scene<G> scene = make_scene<G>(rng);
  const auto fit = regression<G>().fit(scene.noisy, scene.t);
  REQUIRE(fit.ok());
  const typename G::Element g0 = fit.geodesic->start();
  const typename G::Tangent x = G::log(G::compose(G::inverse(g0), fit.geodesic->end()));
  const LongMatrix a = G::ad(x).template cast<long double>();
  LongVector v0 = LongVector::Zero(), v1 = LongVector::Zero();
  long double residual_sum = 0;
  for (std::size_t i = 0; i < scene.noisy.size(); ++i) {
    const long double t = scene.t[i];
    const typename G::Element prediction = G::compose(g0, G::exp(scene.t[i] * x));
    const LongVector r =
        G::log(G::compose(G::inverse(prediction), scene.noisy[i])).template cast<long double>();
    v0 += reference_psi<d>(LongMatrix(-a), 1 - t) * r;
    v1 += reference_psi<d>(a, t) * r;
    residual_sum += r.norm();
  }
  // The residuals are O(noise): the equations are not trivially satisfied.
  REQUIRE(residual_sum >= kObservations * kNoise / 4);
  REQUIRE(static_cast<double>(v0.norm()) <= 1e-10);
  REQUIRE(static_cast<double>(v1.norm()) <= 1e-10);
}

}  // namespace scene_groups
