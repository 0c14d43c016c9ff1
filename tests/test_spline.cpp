// Cumulative B-spline curves (bireg/spline.hpp) and their bi-invariant
// regression (bireg/spline_regression.hpp), against docs/splines.md: the
// curve's derivatives against differences of the curve, the control-point
// differentials (4) and the weights W_c = B_c^2 D_c^{-1}, the reductions
// (degree 1 with two control points is GeodesicRegression; R^3 is linear
// least-squares B-spline regression, solved here independently), left and
// right equivariance of the fit, inversion for degree 1 and its
// second-order failure for degree 3, and the refusals.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/spline.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
#include "catch.hpp"
#include "spline_samples.hpp"
#include "test_support.hpp"

namespace {

using SO3 = bireg::SO3d;
using SE3 = bireg::SE3d;
using Sim3 = bireg::Sim3d;
using R3 = bireg::Rnd<3>;

using bireg_test::distance;
using bireg_test::random_points;
using bireg_test::sample;
using bireg_test::Samples;

// The control points of weighted least-squares B-spline regression in R^3
// with the second-difference penalty, (B^T W B + lambda D_2^T D_2) P =
// B^T W F with weights normalised to a largest of 1 (as fit() does),
// solved densely on `curve`'s knots; and the condition number of that
// matrix, for the tolerance of a comparison.
struct DenseSolution {
  Eigen::MatrixXd points;
  double condition = 1;
};

DenseSolution dense_penalised_solution(const bireg::Spline<R3>& curve, const std::vector<double>& t,
                                       const std::vector<R3::Element>& f,
                                       const std::vector<double>& w, double lambda) {
  const int k = curve.degree();
  const std::size_t m = curve.control_points().size();
  const double largest_weight = *std::max_element(w.begin(), w.end());
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(m, m), rhs = Eigen::MatrixXd::Zero(m, 3);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const auto at = curve.position(t[i]);
    const auto basis = bireg::spline_basis(k, at.u);
    const double weight = w[i] / largest_weight;
    for (int a = 0; a <= k; ++a) {
      rhs.row(at.segment + a) += weight * basis.ordinary[a] * f[i].transpose();
      for (int b = 0; b <= k; ++b)
        normal(at.segment + a, at.segment + b) += weight * basis.ordinary[a] * basis.ordinary[b];
    }
  }
  if (lambda > 0) {
    Eigen::MatrixXd second = Eigen::MatrixXd::Zero(m - 2, m);
    for (std::size_t c = 0; c + 2 < m; ++c)
      second.row(c).segment(c, 3) << 1, -2, 1;
    normal += lambda * second.transpose() * second;
  }
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(normal).eigenvalues();
  return {normal.ldlt().solve(rhs), eigenvalues.maxCoeff() / eigenvalues.minCoeff()};
}

}  // namespace

TEST_CASE("Spline basis: partition of unity and derivatives against differences", "[spline]") {
  for (const int k : {1, 2, 3}) {
    for (const double u : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const auto basis = bireg::spline_basis(k, u);
      double sum = 0;
      for (int j = 0; j <= k; ++j)
        sum += basis.ordinary[j];
      CHECK(std::abs(sum - 1) < 1e-15);
      CHECK(std::abs(basis.cumulative[1] - (1 - basis.ordinary[0])) < 1e-15);
      const double e = 1e-6;
      const auto plus = bireg::spline_basis(k, u + e), minus = bireg::spline_basis(k, u - e);
      for (int j = 1; j <= k; ++j) {
        CHECK(std::abs((plus.cumulative[j] - minus.cumulative[j]) / (2 * e) -
                       basis.cumulative_d1[j]) < 1e-9);
        CHECK(std::abs((plus.cumulative_d1[j] - minus.cumulative_d1[j]) / (2 * e) -
                       basis.cumulative_d2[j]) < 1e-8);
      }
    }
  }
}

TEST_CASE(
    "Spline curve: continuity at knots and velocity and acceleration (8) (9) against differences",
    "[spline]") {
  std::mt19937 rng(3);
  const auto points = random_points<SE3>(rng, 7, 0.5);
  for (const int k : {1, 2, 3}) {
    const bireg::Spline<SE3> curve(k, 2.0, 0.5, points);
    CHECK(curve.segments() == 7u - std::size_t(k));
    // Continuous at every interior knot (value; velocity for k >= 2).
    for (std::size_t m = 1; m < curve.segments(); ++m) {
      const double knot = 2.0 + 0.5 * double(m), e = 1e-9;
      CHECK(distance<SE3>(curve(knot - e), curve(knot + e)) < 1e-7);
      if (k >= 2) {
        CHECK((curve.body_velocity(knot - e) - curve.body_velocity(knot + e)).norm() < 1e-6);
      }
    }
    for (const double t : {2.1, 2.73, 3.4, 3.95}) {
      const double e = 1e-5;
      const SE3::Tangent velocity =
          (SE3::log(SE3::compose(SE3::inverse(curve(t - e)), curve(t + e)))) / (2 * e);
      CHECK((velocity - curve.body_velocity(t)).norm() < 1e-7 * (1 + velocity.norm()));
      const SE3::Tangent acceleration =
          (curve.body_velocity(t + e) - curve.body_velocity(t - e)) / (2 * e);
      CHECK((acceleration - curve.body_acceleration(t)).norm() < 1e-6 * (1 + acceleration.norm()));
      CHECK((curve.spatial_velocity(t) - SE3::Ad(curve(t)) * curve.body_velocity(t)).norm() <
            1e-12);
    }
  }
  // Degree 1: the control points are the curve's values at the knots.
  const bireg::Spline<SE3> piecewise(1, 0.0, 1.0, points);
  for (std::size_t c = 0; c < points.size(); ++c)
    CHECK(distance<SE3>(piecewise(double(c)), points[c]) < 1e-14);
}

// D_c of (4) against central differences of the curve in each control
// point, and W_c D_c = B_c^2 I (the closed forms of W_0 and W_k included).
TEST_CASE("Spline control-point differentials (4) and the weights B_c^2 D_c^{-1}", "[spline]") {
  std::mt19937 rng(5);
  const auto points = random_points<SO3>(rng, 6, 0.6);
  for (const int k : {1, 2, 3}) {
    const bireg::Spline<SO3> curve(k, 0.0, 1.0, points);
    for (const double t : {0.37, 1.02, 1.99, 2.5}) {
      bireg::SegmentAt<SO3> segment;
      bireg::segment_at(curve, t, segment);
      const auto& [at, basis, product, jacobians] = segment;
      bireg::ControlPointDifferentials<SO3> out;
      bireg::control_point_differentials<SO3>(k, basis, product, jacobians.data(), out);
      for (int j = 0; j <= k; ++j) {
        const std::size_t c = at.segment + std::size_t(j);
        SO3::AdMatrix numeric;
        const double e = 1e-6;
        for (int a = 0; a < 3; ++a) {
          auto plus = points, minus = points;
          const SO3::Tangent d = e * SO3::Tangent::Unit(a);
          plus[c] = SO3::compose(points[c], SO3::exp(d));
          minus[c] = SO3::compose(points[c], SO3::exp(-d));
          const bireg::Spline<SO3> up(k, 0.0, 1.0, plus), down(k, 0.0, 1.0, minus);
          numeric.col(a) = SO3::log(SO3::compose(SO3::inverse(down(t)), up(t))) / (2 * e);
        }
        INFO("degree " << k << " t " << t << " j " << j);
        CHECK((numeric - out.derivative[j]).norm() < 1e-8);
        const double b = basis.ordinary[j];
        CHECK((out.weight[j] * out.derivative[j] - b * b * SO3::AdMatrix::Identity()).norm() <
              1e-13);
      }
    }
  }
}

// F's terms W_j r are formed without the matrices W_j (products with
// vectors, solves): they equal W_j r to rounding (W_j r's entries are sums
// of three or six products of O(1) numbers: 1e-14 absolute covers them), on
// SO(3) (the adjugate) and SE(3) (LU), and they are the same bits whether
// the matrices are asked for or not, so F does not depend on whether K is
// assembled with it.
TEST_CASE("Spline F terms without matrices equal W_j r and do not depend on K", "[spline]") {
  std::mt19937 rng(6);
  const auto check = [&](auto group) {
    using G = decltype(group);
    std::normal_distribution<double> normal(0.0, 0.3);
    const auto points = random_points<G>(rng, 6, 0.6);
    for (const int k : {1, 2, 3}) {
      const bireg::Spline<G> curve(k, 0.0, 1.0, points);
      for (const double t : {0.37, 1.02, 1.99, 2.5}) {
        bireg::SegmentAt<G> segment;
        bireg::segment_at(curve, t, segment);
        const auto& [at, basis, product, jacobians] = segment;
        typename G::Tangent r;
        for (Eigen::Index a = 0; a < r.size(); ++a)
          r[a] = normal(rng);
        std::array<typename G::Tangent, bireg::kMaxSplineDegree + 1> alone, with;
        bireg::ControlPointDifferentials<G> matrices;
        bireg::weighted_residuals<G>(k, basis, product, jacobians.data(), r, alone);
        bireg::weighted_residuals<G>(k, basis, product, jacobians.data(), r, with, &matrices);
        for (int j = 0; j <= k; ++j) {
          INFO(G::name << " degree " << k << " t " << t << " j " << j);
          CHECK(alone[std::size_t(j)] == with[std::size_t(j)]);
          CHECK(
              (alone[std::size_t(j)] - matrices.weight[j] * r).template lpNorm<Eigen::Infinity>() <
              1e-14);
        }
      }
    }
  };
  check(SO3{});
  check(SE3{});
}

// Near the end of the anchor's support B_0 = (1-u)^3/6 -> 0 and D_0 is a
// difference of two O(1) terms; W_0 in its closed form stays accurate:
// W_0 = B_0 (I + O(|Omega|)) without the eps / B_0 error of inverting D_0.
TEST_CASE("Spline anchor weight is accurate where B_0 is tiny", "[spline]") {
  std::mt19937 rng(8);
  const auto points = random_points<SO3>(rng, 4, 0.3);
  const bireg::Spline<SO3> curve(3, 0.0, 1.0, points);
  std::vector<bireg::IncrementJacobians<SO3>> jacobians;
  for (const auto& omega : curve.increments())
    jacobians.push_back(bireg::IncrementJacobians<SO3>::of(omega));
  const double u = 1 - 1e-6;  // B_0 = 1.7e-19
  const auto basis = bireg::spline_basis(3, u);
  bireg::SegmentProduct<SO3> product;
  bireg::evaluate_segment<SO3>(3, &curve.increments()[0], basis, product);
  bireg::ControlPointDifferentials<SO3> out;
  bireg::control_point_differentials<SO3>(3, basis, product, jacobians.data(), out);
  REQUIRE(basis.ordinary[0] > 0);
  // W_0 / B_0 = J_l(Omega_1) J_l(B_0 Omega_1)^{-1} Ad_{S_1} -> J_l(Omega_1) Ad_{S_1}.
  const SO3::AdMatrix limit = jacobians[0].left * SO3::Ad(product.suffix[1]);
  CHECK((out.weight[0] / basis.ordinary[0] - limit).norm() < 1e-12);
}

TEST_CASE("Spline fit: degree 1 with two control points is GeodesicRegression", "[spline]") {
  std::mt19937 rng(11);
  const auto check = [&](auto group) {
    using G = decltype(group);
    std::vector<typename G::Element> f;
    std::vector<double> t;
    const auto g0 = G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, 1.0));
    const auto x = bireg_test::normal_tangent<typename G::Tangent>(rng, 0.8);
    for (int i = 0; i < 40; ++i) {
      t.push_back(3.0 + 0.1 * i + 0.03 * std::sin(i));
      f.push_back(G::compose(G::compose(g0, G::exp((t.back() - 3.0) / 4 * x)),
                             G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, 0.2))));
    }
    bireg::RegressionOptions<double> geodesic_options;
    geodesic_options.tolerance = 1e-14;
    const auto geodesic = bireg::GeodesicRegression<G>(geodesic_options).fit(f, t);
    REQUIRE(geodesic.ok());
    bireg::SplineOptions<double> options;
    options.degree = 1;
    options.tolerance = 1e-14;
    const auto spline = bireg::SplineRegression<G>(options).fit(f, t);
    INFO(G::name << ": " << spline.message);
    REQUIRE(spline.ok());
    REQUIRE(spline.spline->control_points().size() == 2);
    CHECK(distance<G>(spline.spline->control_points()[0], geodesic.geodesic->start()) < 1e-12);
    CHECK(distance<G>(spline.spline->control_points()[1], geodesic.geodesic->end()) < 1e-12);
    INFO("iterations: spline " << spline.iterations << ", geodesic " << geodesic.iterations);
    // Both Gauss-Newton iterations drop the same second-order term and
    // converge linearly at a similar rate (0.01-0.04 per step here); the
    // spline's start (a B_c-weighted chart mean, blurred towards the middle
    // when there is one segment) costs it at most a few more steps.
    CHECK(spline.iterations <= geodesic.iterations + 3);
  };
  check(SO3{});
  check(SE3{});
  check(Sim3{});
}

// In R^3 the equations are the normal equations of weighted least-squares
// B-spline regression: B^T W B P = B^T W F, solved here densely.
TEST_CASE("Spline fit in R^3 is least-squares B-spline regression", "[spline]") {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<R3::Element> f;
  std::vector<double> t, w;
  for (int i = 0; i < 60; ++i) {
    t.push_back(10 * uniform(rng));
    w.push_back(0.5 + uniform(rng));
    f.push_back(R3::Element(std::sin(t.back()), std::cos(0.7 * t.back()), 0.1 * t.back()) +
                bireg_test::normal_tangent<R3::Tangent>(rng, 0.1));
  }
  for (const int k : {1, 2, 3}) {
    bireg::SplineOptions<double> options;
    options.degree = k;
    options.knot_spacing = 1.5;
    const auto fit = bireg::SplineRegression<R3>(options).fit(f, t, w);
    REQUIRE(fit.ok());
    const auto& curve = *fit.spline;
    const Eigen::MatrixXd solution = dense_penalised_solution(curve, t, f, w, 0.0).points;
    for (std::size_t c = 0; c < curve.control_points().size(); ++c)
      CHECK((curve.control_points()[c] - solution.row(c).transpose()).norm() < 1e-12);
  }
}

// With the roughness penalty (splines.md §12) the equations in R^3 are the
// penalised normal equations (B^T W B + lambda D_2^T D_2) P = B^T W F,
// weights normalised to a largest of 1, D_2 the second differences of the
// control points; solved here densely, at penalties from barely felt to
// dominant. Tolerance as above (linear equations: one Gauss-Newton step).
TEST_CASE("Spline fit in R^3 with a roughness penalty solves the penalised normal equations",
          "[spline]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<R3::Element> f;
  std::vector<double> t, w;
  for (int i = 0; i < 80; ++i) {
    t.push_back(10 * uniform(rng));
    w.push_back(0.5 + uniform(rng));
    f.push_back(R3::Element(std::sin(t.back()), std::cos(0.7 * t.back()), 0.1 * t.back()) +
                bireg_test::normal_tangent<R3::Tangent>(rng, 0.1));
  }
  for (const int k : {2, 3}) {
    for (const double lambda : {1e-3, 1.0, 1e3}) {
      bireg::SplineOptions<double> options;
      options.degree = k;
      options.knot_spacing = 0.5;
      options.roughness_penalty = lambda;
      const auto fit = bireg::SplineRegression<R3>(options).fit(f, t, w);
      INFO("degree " << k << " lambda " << lambda);
      REQUIRE(fit.ok());
      const auto& curve = *fit.spline;
      const Eigen::MatrixXd solution = dense_penalised_solution(curve, t, f, w, lambda).points;
      const double scale = solution.cwiseAbs().maxCoeff();
      for (std::size_t c = 0; c < curve.control_points().size(); ++c)
        CHECK((curve.control_points()[c] - solution.row(c).transpose()).norm() < 1e-12 * scale);
    }
  }
  bireg::SplineOptions<double> options;
  options.roughness_penalty = -1;
  CHECK(bireg::SplineRegression<R3>(options).fit(f, t).message ==
        "roughness_penalty must be a finite non-negative number");
  options.roughness_penalty = std::numeric_limits<double>::quiet_NaN();
  CHECK(bireg::SplineRegression<R3>(options).fit(f, t).message ==
        "roughness_penalty must be a finite non-negative number");
  options.roughness_penalty = 1;
  options.degree = 1;
  CHECK(bireg::SplineRegression<R3>(options).fit(f, t).message ==
        "roughness_penalty needs degree 2 or 3: it couples control points two apart");
}

// With a penalty the data need not determine every control point
// (splines.md §12, "Knots finer than the data"): a gap of 2 units (40
// spans without an observation) and more control points (203) than
// observations (60) still give the penalised normal equations' solution.
// Their condition number kappa grows with the gap's length (the
// penalty's smallest eigenvalues there go like lambda (pi / 40)^4), so the
// tolerance is kappa times 100 roundings of the solution's scale. Without
// the penalty the same knots are refused, and a penalised fit too needs two
// distinct covariates of positive weight (the penalty's null space, a
// geodesic, is left to the data).
TEST_CASE("Penalised spline fit in R^3: knots finer than the data, and a gap", "[spline]") {
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<R3::Element> f;
  std::vector<double> t, w;
  for (int i = 0; i < 60; ++i) {
    double at = 8 * uniform(rng);
    if (at > 4) at += 2;  // nothing in (4, 6)
    t.push_back(at);
    w.push_back(0.5 + uniform(rng));
    f.push_back(R3::Element(std::sin(at), std::cos(0.7 * at), 0.1 * at) +
                bireg_test::normal_tangent<R3::Tangent>(rng, 0.1));
  }
  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.05;
  for (const double lambda : {1.0, 100.0}) {
    options.roughness_penalty = lambda;
    const auto fit = bireg::SplineRegression<R3>(options).fit(f, t, w);
    INFO("lambda " << lambda << ": " << fit.message);
    REQUIRE(fit.ok());
    const auto& curve = *fit.spline;
    REQUIRE(curve.control_points().size() > t.size());
    const DenseSolution dense = dense_penalised_solution(curve, t, f, w, lambda);
    const double tolerance = 100 * std::numeric_limits<double>::epsilon() * dense.condition *
                             dense.points.cwiseAbs().maxCoeff();
    INFO("condition " << dense.condition);
    for (std::size_t c = 0; c < curve.control_points().size(); ++c)
      CHECK((curve.control_points()[c] - dense.points.row(c).transpose()).norm() < tolerance);
  }
  options.roughness_penalty = 0;
  CHECK(bireg::SplineRegression<R3>(options).fit(f, t, w).message.find(
            "control points for 60 observations; use a wider spacing") != std::string::npos);
  options.roughness_penalty = 1;
  options.knot_spacing = 1e-4;  // 100,000 spans: more than 16 control points per observation
  CHECK(bireg::SplineRegression<R3>(options).fit(f, t, w).message.find(
            "(a penalised fit takes up to 16 per observation)") != std::string::npos);
  options.knot_spacing = 0.5;
  std::vector<double> weights(t.size(), 0.0);
  weights[3] = 1;
  weights[7] = 1;
  std::vector<double> same = t;
  same[7] = same[3];
  const auto single = bireg::SplineRegression<R3>(options).fit(f, same, weights);
  CHECK(single.message.find("the observations with positive weight share one covariate") !=
        std::string::npos);
}

// The same at the sizes where the fit works in pieces: 12,000 observations
// (12 chunks of 1024), 1,203 control points (three pieces of 512 rows when
// the chunks' sums are added, two pieces of control-point updates, and the
// banded solve split in two), and 6 control points (3 segments of 4,000
// observations: several chunks begin at the same control point); on one
// thread and on two. Tolerance as above: the equations are
// linear, so Gauss-Newton lands on the solution in one step and the next
// measures its rounding.
TEST_CASE("Spline fit in R^3 by pieces: every chunk's sums added once", "[spline][threads]") {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  constexpr int kCount = 12000;
  for (const double range : {1200.0, 3.0}) {
    std::vector<R3::Element> f;
    std::vector<double> t, w;
    for (int i = 0; i < kCount; ++i) {
      t.push_back(range * (i + 0.5 * uniform(rng)) / kCount);
      w.push_back(0.5 + uniform(rng));
      const double x = 10 * t.back() / range;
      f.push_back(R3::Element(std::sin(x), std::cos(0.7 * x), 0.1 * x) +
                  bireg_test::normal_tangent<R3::Tangent>(rng, 0.1));
    }
    for (const int threads : {1, 2}) {
      CAPTURE(range, threads);
      bireg::SplineOptions<double> options;
      options.degree = 3;
      options.knot_spacing = 1;  // 1200 segments, or 3
      options.threads = threads;
      const auto fit = bireg::SplineRegression<R3>(options).fit(f, t, w);
      REQUIRE(fit.ok());
      const auto& curve = *fit.spline;
      const std::size_t m = curve.control_points().size();
      CHECK(m == (range == 3.0 ? 6u : 1203u));
      Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(m, m), rhs = Eigen::MatrixXd::Zero(m, 3);
      for (std::size_t i = 0; i < t.size(); ++i) {
        const auto at = curve.position(t[i]);
        const auto basis = bireg::spline_basis(3, at.u);
        for (int a = 0; a <= 3; ++a) {
          rhs.row(at.segment + a) += w[i] * basis.ordinary[a] * f[i].transpose();
          for (int b = 0; b <= 3; ++b)
            normal(at.segment + a, at.segment + b) += w[i] * basis.ordinary[a] * basis.ordinary[b];
        }
      }
      const Eigen::MatrixXd solution = normal.ldlt().solve(rhs);
      double largest = 0;
      for (std::size_t c = 0; c < m; ++c)
        largest =
            std::max(largest, (curve.control_points()[c] - solution.row(c).transpose()).norm());
      CHECK(largest < 4 * kCount * std::numeric_limits<double>::epsilon());
    }
  }
}

// Theorem 2.4's argument with (4) (splines.md §6): translating the data
// on the left or the right translates every control point.
TEST_CASE("Spline fit is left and right equivariant", "[spline]") {
  std::mt19937 rng(17);
  const auto check = [&](auto group) {
    using G = decltype(group);
    const bireg::Spline<G> truth(3, 0.0, 1.0, random_points<G>(rng, 8, 0.4));
    const Samples<G> data = sample(truth, 120, 0.1, rng);
    const auto g = G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, 1.0));
    const auto [left, right] = bireg_test::translated<G>(data.f, g);
    for (const double penalty : {0.0, 0.5}) {
      bireg::SplineOptions<double> options;
      options.knot_spacing = 1.0;
      options.tolerance = 1e-13;
      options.roughness_penalty = penalty;  // splines.md §12: no metric, still bi-invariant
      const bireg::SplineRegression<G> regression(options);
      const auto base = regression.fit(data.f, data.t), l = regression.fit(left, data.t),
                 r = regression.fit(right, data.t);
      INFO(G::name << " roughness penalty " << penalty);
      REQUIRE(base.ok());
      REQUIRE(l.ok());
      REQUIRE(r.ok());
      const auto& p = base.spline->control_points();
      REQUIRE(p.size() == truth.control_points().size());
      for (std::size_t c = 0; c < p.size(); ++c) {
        CHECK(distance<G>(G::compose(g, p[c]), l.spline->control_points()[c]) < 1e-10);
        CHECK(distance<G>(G::compose(p[c], g), r.spline->control_points()[c]) < 1e-10);
      }
    }
  };
  check(SO3{});
  check(SE3{});
  check(Sim3{});
}

// §3: degree 1 is inversion equivariant; degree 3 is not, by a second-order
// amount: data 10 times more concentrated give a discrepancy ~100 times
// smaller (bounded here between 30 and 300).
TEST_CASE("Spline fit: inversion equivariant for degree 1 only, second order for degree 3",
          "[spline]") {
  std::mt19937 rng(19);
  const auto points = random_points<SO3>(rng, 7, 0.5);
  const auto discrepancy = [&](int k, double scale) {
    std::vector<SO3::Element> scaled;
    for (const auto& p : points)
      scaled.push_back(SO3::exp(scale * SO3::log(p)));
    const bireg::Spline<SO3> truth(k, 0.0, 1.0, scaled);
    std::mt19937 noise_rng(23);
    Samples<SO3> data = sample(truth, 150, 0.05 * scale, noise_rng);
    auto inverted = data.f;
    for (auto& f : inverted)
      f = SO3::inverse(f);
    bireg::SplineOptions<double> options;
    options.degree = k;
    options.knot_spacing = 1.0;
    options.tolerance = 1e-14;
    const bireg::SplineRegression<SO3> regression(options);
    const auto base = regression.fit(data.f, data.t), inv = regression.fit(inverted, data.t);
    REQUIRE(base.ok());
    REQUIRE(inv.ok());
    double largest = 0;
    for (std::size_t c = 0; c < points.size(); ++c) {
      largest = std::max(largest, distance<SO3>(SO3::inverse(base.spline->control_points()[c]),
                                                inv.spline->control_points()[c]));
    }
    return largest;
  };
  CHECK(discrepancy(1, 1.0) < 1e-10);
  const double wide = discrepancy(3, 1.0), narrow = discrepancy(3, 0.1);
  INFO("degree 3: " << wide << " at full spread, " << narrow << " at a tenth");
  CHECK(wide > 1e-4);
  CHECK(wide / narrow > 30);
  CHECK(wide / narrow < 300);
}

TEST_CASE("Spline fit recovers a noise-free cubic spline and its velocity", "[spline]") {
  std::mt19937 rng(29);
  const bireg::Spline<SE3> truth(3, -1.0, 0.8, random_points<SE3>(rng, 9, 0.5));
  const Samples<SE3> data = sample(truth, 200, 0.0, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.8;
  options.interval = std::make_pair(truth.t_min(), truth.t_max());
  const auto fit = bireg::SplineRegression<SE3>(options).fit(data.f, data.t);
  REQUIRE(fit.ok());
  CHECK(fit.iterations <= 10);
  for (std::size_t c = 0; c < truth.control_points().size(); ++c)
    CHECK(distance<SE3>(fit.spline->control_points()[c], truth.control_points()[c]) < 1e-9);
  for (const double t : {-0.9, 0.0, 1.3, 4.5})
    CHECK((fit.spline->body_velocity(t) - truth.body_velocity(t)).norm() < 1e-8);
  CHECK(fit.equation_norm < 1e-9);
}

TEST_CASE("Spline fit refuses what it cannot determine, naming it", "[spline]") {
  std::vector<SO3::Element> f;
  std::vector<double> t;
  // Observations on [0, 1] and [3, 4] only: the span (1, 3) holds none.
  for (int i = 0; i <= 20; ++i) {
    t.push_back(i < 10 ? 0.1 * i : 3.0 + 0.1 * (i - 10));
    f.push_back(SO3::exp(SO3::Tangent(0.1 * t.back(), 0.0, 0.0)));
  }
  bireg::SplineOptions<double> options;
  options.degree = 1;
  options.knot_spacing = 0.5;
  auto fit = bireg::SplineRegression<SO3>(options).fit(f, t);
  CHECK(fit.status == bireg::Status::invalid_input);
  CHECK(fit.message.find("control point 3 (support [1.000000, 2.000000])") != std::string::npos);
  CHECK(fit.message.find("Schoenberg-Whitney") != std::string::npos);
  CHECK_FALSE(fit.spline.has_value());

  options.knot_spacing = 0.01;  // 400 segments for 21 observations
  fit = bireg::SplineRegression<SO3>(options).fit(f, t);
  CHECK(fit.status == bireg::Status::invalid_input);
  CHECK(fit.message.find("control points for 21 observations") != std::string::npos);

  for (const int degree : {0, 4}) {
    options = {};
    options.degree = degree;
    fit = bireg::SplineRegression<SO3>(options).fit(f, t);
    CHECK(fit.message.find("degree must be 1, 2 or 3") != std::string::npos);
  }
  options = {};
  options.knot_spacing = -1;
  CHECK(bireg::SplineRegression<SO3>(options).fit(f, t).message.find("knot_spacing") !=
        std::string::npos);
  options = {};
  f[4](0, 0) = std::nan("");
  fit = bireg::SplineRegression<SO3>(options).fit(f, t);
  CHECK(fit.bad_index == 4);
  CHECK(fit.message.find("non-finite") != std::string::npos);
}

// Cross-validation of the knot spacing (statistics/smoothing/spline_knots.hpp):
// the same choice and criteria for translated data, a spacing too fine for
// the folds refused with its reason, and a choice whose curve is close to
// the best the grid offers against the truth (which the criterion cannot
// see).
TEST_CASE("Knot spacing by cross-validation: invariant and refusals stated", "[spline]") {
  std::mt19937 rng(31);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 8, 0.5));
  const Samples<SO3> data = sample(truth, 150, 0.05, rng);
  const std::vector<double> grid = {0.04, 0.25, 0.5, 1.0, 2.0, 5.0};
  bireg::SplineOptions<double> options;
  const auto selection = bireg::select_knot_spacing<SO3>(data.f, data.t, options, grid);
  REQUIRE(selection.ok());
  // 0.04 cuts ~5 into ~125 segments: 128 control points for 150
  // observations, spans with about one each.
  INFO(selection.refusals[0]);
  CHECK(selection.refusals[0].find("the knots are too dense for the data") != std::string::npos);
  CHECK(selection.failures[0] > 0);
  std::size_t best = grid.size();
  for (std::size_t v = 0; v < grid.size(); ++v) {
    if (!selection.refusals[v].empty()) continue;
    CHECK(std::isfinite(selection.criterion[v]));
    if (best == grid.size() || selection.criterion[v] < selection.criterion[best]) best = v;
  }
  REQUIRE(best < grid.size());
  CHECK(selection.knot_spacing == grid[best]);

  const SO3::Element g = SO3::exp(SO3::Tangent(0.3, -1.1, 0.7));
  const auto [left, right] = bireg_test::translated<SO3>(data.f, g);
  for (const auto& moved : {left, right}) {
    const auto other = bireg::select_knot_spacing<SO3>(moved, data.t, options, grid);
    REQUIRE(other.ok());
    CHECK(other.knot_spacing == selection.knot_spacing);
    for (std::size_t v = 0; v < grid.size(); ++v) {
      if (!std::isfinite(selection.criterion[v])) continue;
      CHECK(std::abs(other.criterion[v] / selection.criterion[v] - 1) < 1e-8);
    }
  }

  // Against the truth: the chosen curve's RMS error within 1.5x of the
  // best grid value's.
  std::vector<double> errors;
  for (std::size_t v = 0; v < grid.size(); ++v) {
    options.knot_spacing = grid[v];
    const auto fit = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
    double sum = 0;
    for (int q = 0; q <= 200 && fit.ok(); ++q) {
      const double t = data.t.front() + (data.t.back() - data.t.front()) * q / 200;
      sum += std::pow(distance<SO3>((*fit.spline)(t), truth(t)), 2);
    }
    errors.push_back(fit.ok() ? std::sqrt(sum / 201) : INFINITY);
  }
  const double oracle = *std::min_element(errors.begin(), errors.end());
  INFO("chosen " << selection.knot_spacing << " error " << errors[best] << ", best " << oracle);
  CHECK(errors[best] <= 1.5 * oracle);
}

// Threads share the chunks of each pass; the chunks and the order their
// sums are added in do not depend on the thread count (parallel.hpp).
TEST_CASE("Spline fit: bit-identical for any thread count", "[spline][threads]") {
  std::mt19937 rng(37);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 40, 0.3));
  const Samples<SO3> data = sample(truth, 3 * bireg::kChunkSize, 0.05, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.5;
  const auto serial = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
  REQUIRE(serial.ok());
  for (const int threads : {2, 3}) {
    options.threads = threads;
    const auto parallel = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
    REQUIRE(parallel.ok());
    CHECK(parallel.iterations == serial.iterations);
    for (std::size_t c = 0; c < serial.spline->control_points().size(); ++c)
      CHECK(parallel.spline->control_points()[c] == serial.spline->control_points()[c]);
  }
  options.threads = 0;
  CHECK(bireg::SplineRegression<SO3>(options).fit(data.f, data.t).message ==
        "threads must be at least 1, got 0");
}

// A spin about z at 2.6 rad per knot span: every increment turns by about
// 2.6 rad, past 3 pi / 4 = 2.36, where the principal log of a span is near
// its jump; at 2.0 rad per span nothing is flagged. A gross outlier (a half
// turn away, weight 1) is named as the geodesic's diagnostics name it.
TEST_CASE("Spline fit reports spans and residuals near the log's cut locus", "[spline]") {
  const auto spin = [](double rate, std::size_t outlier) {
    Samples<SO3> data;
    for (std::size_t i = 0; i <= 200; ++i) {
      const double t = 4.0 * double(i) / 200;
      data.t.push_back(t);
      data.f.push_back(SO3::exp(SO3::Tangent(0.0, 0.0, rate * t)));
    }
    if (outlier < data.f.size())
      data.f[outlier] = SO3::compose(data.f[outlier], SO3::exp(SO3::Tangent(2.9, 0.0, 0.0)));
    return data;
  };
  bireg::SplineOptions<double> options;
  options.knot_spacing = 1.0;
  const Samples<SO3> slow = spin(2.0, 1000);
  const auto calm = bireg::SplineRegression<SO3>(options).fit(slow.f, slow.t);
  REQUIRE(calm.ok());
  CHECK_FALSE(calm.beyond_domain);
  CHECK(calm.largest_increment_angle == Approx(2.0).epsilon(0.05));
  const Samples<SO3> fast = spin(2.6, 1000);
  const auto near = bireg::SplineRegression<SO3>(options).fit(fast.f, fast.t);
  REQUIRE(near.ok());
  CHECK(near.beyond_domain);
  CHECK(near.largest_increment_angle > 2.36);
  CHECK(near.largest_increment >= 1);
  CHECK(near.largest_residual_angle < 1e-6);
  const Samples<SO3> bad = spin(2.0, 77);
  const auto outlier = bireg::SplineRegression<SO3>(options).fit(bad.f, bad.t);
  REQUIRE(outlier.ok());
  CHECK(outlier.beyond_domain);
  CHECK(outlier.largest_residual_observation == 77);
  CHECK(outlier.largest_residual_angle > 2.36);

  // One cubic segment over a 3.2 rad turn: its control points would have
  // to lie more than a half turn apart (B-spline control points extend past
  // the curve), and the failure says so rather than blaming dense knots.
  options.knot_spacing = std::numeric_limits<double>::infinity();
  const Samples<SO3> turn = spin(0.8, 1000);
  const auto wide = bireg::SplineRegression<SO3>(options).fit(turn.f, turn.t);
  INFO(wide.message);
  CHECK(wide.status == bireg::Status::no_descent);
  CHECK(wide.message.find("half turn") != std::string::npos);
  CHECK(wide.message.find("try a narrower knot spacing") != std::string::npos);
  CHECK(wide.message.find("swing") == std::string::npos);
}

// The opposite failure: 40 observations with 0.2 rad of noise per axis
// over four cubic spans. An end control point's basis is at most 1/6 over
// its one span, so the end increment's least-squares estimate spreads by
// about 14 times the noise per axis (14.2 for this design in R^3, from
// (B^T B)^{-1}; docs/splines.md §7), past the half turn; the data around
// it move far less, and the message says that the data determine the
// control points too weakly there, not that the knots are too sparse.
TEST_CASE("Spline fit: control points swinging out beyond sparse noisy data are named as such",
          "[spline]") {
  std::mt19937 rng(13);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, bireg_test::random_points<SO3>(rng, 7, 0.4));
  const Samples<SO3> data = bireg_test::sample(truth, 40, 0.2, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 1.0;
  const auto fit = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
  INFO(fit.message);
  REQUIRE(fit.status == bireg::Status::no_descent);
  CHECK(fit.message.find("swing out beyond the data") != std::string::npos);
  CHECK(fit.message.find("try a lower degree") != std::string::npos);
  CHECK(fit.message.find("narrower") == std::string::npos);
  // The advice holds: a quadratic's end increment spreads by 2.7 times
  // the noise, and its fit converges on the same data.
  options.degree = 2;
  CHECK(bireg::SplineRegression<SO3>(options).fit(data.f, data.t).ok());
  // So does the cubic with a roughness penalty (splines.md §12), which
  // ties the end increments to their neighbours where the data cannot.
  options.degree = 3;
  options.roughness_penalty = 1;
  const auto penalised = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
  INFO(penalised.message);
  REQUIRE(penalised.ok());
  CHECK_FALSE(penalised.beyond_domain);
}

// The Exp-stepped iteration P_c <- P_c exp(lambda F_c) of splines.md §7, run
// here on SplineRegression::equations. On concentrated data (control points
// 0.05 rad apart, noise 0.002 rad) its linear part is I - lambda H kron I,
// so it converges at max_mu |1 - lambda mu| over H's eigenvalues:
// (kappa - 1)/(kappa + 1) at lambda = 2/(mu_min + mu_max), and
// 1 - mu_min / beta at the always-safe lambda = 1/beta (beta the largest
// row sum of H, Gershgorin). The rate is measured as |F| falls over the
// second half of 3 / (1 - predicted) steps, when the slowest mode leads
// by e^{-1.5} at least over the next (the first half): 1 - rate within
// 15% of 1 - predicted. Degree 3's uniform clamped knots give kappa ~ 1400
// (the end control points' B_0 = (1 - u)^3 / 6 touches one segment), so
// its safe step needs ~4,600 steps: Gauss-Newton, which fit() runs, does
// not depend on kappa.
TEST_CASE("Spline Exp-stepped iteration contracts at the rate H predicts", "[spline]") {
  const int degree = GENERATE(1, 2, 3);
  std::mt19937 rng(41);
  const bireg::Spline<SO3> truth(degree, 0.0, 1.0, random_points<SO3>(rng, 6 + degree, 0.05));
  const Samples<SO3> data = sample(truth, 240, 0.002, rng);
  bireg::SplineOptions<double> options;
  options.degree = degree;
  options.knot_spacing = 1.0;
  options.interval = std::make_pair(truth.t_min(), truth.t_max());
  const bireg::SplineRegression<SO3> regression(options);

  // H = B^T B (unit weights): its extreme eigenvalues and largest row sum.
  const std::size_t m = truth.control_points().size();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(Eigen::Index(m), Eigen::Index(m));
  for (const double t : data.t) {
    const auto at = truth.position(t);
    const auto basis = bireg::spline_basis(degree, at.u);
    for (std::size_t j = 0; j <= std::size_t(degree); ++j)
      for (std::size_t l = 0; l <= std::size_t(degree); ++l)
        h(Eigen::Index(at.segment + j), Eigen::Index(at.segment + l)) +=
            basis.ordinary[j] * basis.ordinary[l];
  }
  const Eigen::VectorXd mu = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(h).eigenvalues();
  const double mu_min = mu.minCoeff(), mu_max = mu.maxCoeff();
  const double beta = h.rowwise().sum().maxCoeff();
  REQUIRE(mu_max <= beta * (1 + 1e-12));

  const auto measured_rate = [&](double lambda, double predicted) {
    std::vector<SO3::Element> points = truth.control_points();
    for (auto& p : points)
      p = SO3::compose(p, SO3::exp(bireg_test::normal_tangent<SO3::Tangent>(rng, 0.01)));
    const int steps = 2 * int(std::ceil(1.5 / (1 - predicted)));
    double half = 0, last = 0;
    for (int k = 0; k <= steps; ++k) {
      const auto f = regression.equations(points, data.f, data.t);
      REQUIRE(f.ok());
      double squares = 0;
      for (std::size_t c = 0; c < m; ++c) {
        squares += f.force[c].squaredNorm();
        points[c] = SO3::compose(points[c], SO3::exp((lambda * f.force[c]).eval()));
      }
      if (k == steps / 2) half = std::sqrt(squares);
      if (k == steps) last = std::sqrt(squares);
    }
    return std::pow(last / half, 2.0 / steps);
  };
  const double kappa = mu_max / mu_min;
  const double best_predicted = (kappa - 1) / (kappa + 1);
  const double best = measured_rate(2 / (mu_min + mu_max), best_predicted);
  const double safe_predicted = 1 - mu_min / beta;
  const double safe = measured_rate(1 / beta, safe_predicted);
  INFO("degree " << degree << ", kappa " << kappa << ": rate " << best << " (predicted "
                 << best_predicted << "); safe step " << safe << " (predicted " << safe_predicted
                 << ")");
  CHECK(std::abs((1 - best) - (1 - best_predicted)) < 0.15 * (1 - best_predicted));
  CHECK(std::abs((1 - safe) - (1 - safe_predicted)) < 0.15 * (1 - safe_predicted));

  // Refusals as fit_from's: the wrong number of control points.
  const std::vector<SO3::Element> short_points(m - 1, SO3::identity());
  const auto refused = regression.equations(short_points, data.f, data.t);
  CHECK_FALSE(refused.ok());
  CHECK(refused.message.find("the knots need " + std::to_string(m)) != std::string::npos);
}

// Gauss-Newton keeps K while the steps from it contract by
// jacobian_reuse_contraction (splines.md §9). On concentrated data it
// does, and K is assembled fewer times than steps are taken; the answer is
// still a zero of F to the tolerance: a fit started there, with K
// assembled afresh, certifies it with its first step, and a fit that
// assembles K at every step (contraction 0) stops within 2.1 tolerances of
// it (each answer within tolerance / (1 - c) of the zero, c = 0.01). The
// decisions read the steps' norms, which are the same bits on 1 and 2
// threads (9,000 observations: above kParallelMinimum).
TEST_CASE("Spline Gauss-Newton reuses K on concentrated data and still certifies its answer",
          "[spline]") {
  std::mt19937 rng(41);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 14, 0.3));
  const Samples<SO3> data = sample(truth, 9000, 0.002, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 1.0;
  options.interval = std::make_pair(truth.t_min(), truth.t_max());
  const bireg::SplineRegression<SO3> regression(options);
  const auto fit = regression.fit(data.f, data.t);
  REQUIRE(fit.ok());
  INFO("steps " << fit.iterations << ", K assembled " << fit.jacobian_evaluations);
  CHECK(fit.jacobian_evaluations <= fit.iterations - 2);
  const auto refit = regression.fit_from(fit.spline->control_points(), data.f, data.t);
  REQUIRE(refit.ok());
  CHECK(refit.iterations == 1);
  CHECK(refit.jacobian_evaluations == 1);
  CHECK(refit.spline->control_points() == fit.spline->control_points());  // no step taken

  auto every_step = options;
  every_step.jacobian_reuse_contraction = 0;
  const auto fresh = bireg::SplineRegression<SO3>(every_step).fit(data.f, data.t);
  REQUIRE(fresh.ok());
  CHECK(fresh.jacobian_evaluations == fresh.iterations);
  for (std::size_t c = 0; c < truth.control_points().size(); ++c) {
    CHECK(distance<SO3>(fresh.spline->control_points()[c], fit.spline->control_points()[c]) <
          2.1 * options.tolerance);
  }

  auto two = options;
  two.threads = 2;
  const auto parallel = bireg::SplineRegression<SO3>(two).fit(data.f, data.t);
  REQUIRE(parallel.ok());
  CHECK(parallel.jacobian_evaluations == fit.jacobian_evaluations);
  CHECK(parallel.step_norms == fit.step_norms);
  CHECK(parallel.spline->control_points() == fit.spline->control_points());

  for (const double refused : {1.0, -0.5, std::numeric_limits<double>::quiet_NaN()}) {
    auto bad = options;
    bad.jacobian_reuse_contraction = refused;
    const auto rejected = bireg::SplineRegression<SO3>(bad).fit(data.f, data.t);
    CHECK(rejected.status == bireg::Status::invalid_input);
    CHECK(rejected.message.find("jacobian_reuse_contraction") != std::string::npos);
  }
}

// Where a step from an older K contracts too little, K is assembled where
// the fit stands and kept fresh from then on. Noise-free data at
// contraction 0.05: the third step from the K of the second iterate
// contracts by 14 only (checked when this test was written), so the fit
// takes K back; Gauss-Newton's superlinear rate on noise-free data then
// shows in the last step, and the answer is the one of a fit that
// assembles K at every step within 1 + 1/(1 - 0.05) < 2.1 tolerances
// (each answer within tolerance / (1 - c) of the zero).
TEST_CASE("Spline Gauss-Newton takes K back where an older one contracts too little", "[spline]") {
  std::mt19937 rng(13);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 7, 0.4));
  const Samples<SO3> exact = sample(truth, 40, 0.0, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 1.0;
  options.interval = std::make_pair(truth.t_min(), truth.t_max());
  options.jacobian_reuse_contraction = 0.05;
  const auto fit = bireg::SplineRegression<SO3>(options).fit(exact.f, exact.t);
  REQUIRE(fit.ok());
  REQUIRE(fit.step_norms.size() >= 3);
  const std::size_t last = fit.step_norms.size() - 1;
  INFO("steps " << fit.iterations << ", K assembled " << fit.jacobian_evaluations);
  CHECK(fit.jacobian_evaluations < fit.iterations);  // K was reused for a step
  CHECK(fit.step_norms[last] < 1e-6 * fit.step_norms[last - 1]);
  auto every_step = options;
  every_step.jacobian_reuse_contraction = 0;
  const auto fresh = bireg::SplineRegression<SO3>(every_step).fit(exact.f, exact.t);
  REQUIRE(fresh.ok());
  for (std::size_t c = 0; c < truth.control_points().size(); ++c) {
    CHECK(distance<SO3>(fresh.spline->control_points()[c], fit.spline->control_points()[c]) <
          2.1 * options.tolerance);
  }
}
