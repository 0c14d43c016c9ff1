// MatrixGroup<N, Basis>: the algebraic identities of test_groups.cpp on the
// Heisenberg group, SL(3) and GL+(3), the Heisenberg group's polynomial
// closed forms and terminating series, and the regression on them.
//
// Tolerance: Eigen's matrix exponential (Pade with scaling and squaring)
// and logarithm (Schur-Parlett with inverse scaling and squaring) are
// backward stable to a few hundred epsilon at the norms used here (tangent
// entries up to 0.5, so no eigenvalue near the log's branch cut); identities
// that chain two or three of them are allowed 1e-12 relative, ~5000 epsilon,
// far below the O(1) error of a wrong sign or basis.
#include <random>

#include "bireg/core/concept.hpp"
#include "bireg/core/exact_inverse_differential.hpp"
#include "bireg/core/inverse_differential.hpp"
#include "bireg/groups/matrix_group.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;
using bireg_test::relative_error;

namespace {
constexpr double kTolerance = 1e-12;
constexpr double kScale = 0.5;
}  // namespace

TEMPLATE_TEST_CASE("matrix groups satisfy the group identities", "[matrix_group]",
                   bireg::Heisenberg<double>, bireg::SL3<double>, (bireg::GLp<3, double>)) {
  using G = TestType;
  STATIC_REQUIRE(bireg::check_lie_group<G>());
  constexpr int d = G::dof;
  std::mt19937 rng(91);
  for (int i = 0; i < 50; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kScale);
    const typename G::Tangent y = random_tangent<typename G::Tangent>(rng, kScale);
    const typename G::Element a = G::exp(random_tangent<typename G::Tangent>(rng, kScale));
    const typename G::Element b = G::exp(random_tangent<typename G::Tangent>(rng, kScale));
    REQUIRE(G::is_element(a));
    REQUIRE(relative_error(G::log(G::exp(x)), x) <= kTolerance);
    REQUIRE(relative_error(G::vee(G::hat(x)), x) <= kTolerance);
    const typename G::Algebra bracket = G::hat(x) * G::hat(y) - G::hat(y) * G::hat(x);
    REQUIRE((G::ad(x) * y - G::vee(bracket)).cwiseAbs().maxCoeff() <= kTolerance);
    REQUIRE(relative_error(G::Ad(a) * x,
                           G::vee(typename G::Algebra(a * G::hat(x) * a.inverse()))) <= kTolerance);
    const Eigen::Matrix<long double, d, d> ad = G::ad(x).template cast<long double>();
    REQUIRE(relative_error(G::Ad(G::exp(x)), bireg_test::reference_expm<d>(ad)) <= kTolerance);
    REQUIRE(relative_error(G::Ad(G::compose(a, b)), G::Ad(a) * G::Ad(b)) <= kTolerance);
    REQUIRE(relative_error(G::compose(a, G::inverse(a)), G::identity()) <= kTolerance);
  }
}

TEST_CASE("Heisenberg: polynomial exp and log, nilpotent ad, terminating series",
          "[matrix_group]") {
  using G = bireg::Heisenberg<double>;
  std::mt19937 rng(92);
  for (int i = 0; i < 50; ++i) {
    const G::Tangent x = random_tangent<G::Tangent>(rng, 2.0);
    const G::Algebra h = G::hat(x);
    // X^3 = 0: exp(X) = I + X + X^2/2 and log(g) = (g - I) - (g - I)^2/2.
    const G::Element g = G::Element::Identity() + h + h * h / 2;
    REQUIRE(relative_error(G::exp(x), g) <= kTolerance);
    const G::Element n = g - G::Element::Identity();
    REQUIRE(relative_error(G::log(g), G::vee(G::Algebra(n - n * n / 2))) <= kTolerance);
    // ad_x^2 = 0: [x, [x, y]] lies in the centre.
    REQUIRE((G::ad(x) * G::ad(x)).cwiseAbs().maxCoeff() == 0.0);
    const G::Tangent r = random_tangent<G::Tangent>(rng, 1.0);
    for (double s : {0.0, 0.3, 0.9, 1.0}) {
      const G::Tangent first = bireg::apply_psi_series<double, 3>(G::ad(x), s, r, 1);
      // Every higher-order term multiplies ad_x^2 = 0: exact equality up to
      // the rounding of the (zero) extra Horner steps.
      for (int order : {2, 8, 32}) {
        REQUIRE(relative_error(bireg::apply_psi_series<double, 3>(G::ad(x), s, r, order), first) <=
                1e-15);
      }
      REQUIRE(relative_error(bireg::apply_psi_exact<G>(x, s, r), first) <= 1e-15);
    }
  }
}

// Noise-free recovery and left/right/inverse equivariance of the fit on the
// matrix groups (tolerance 1e-13 on the step; the matrix functions' ~1e-13
// accuracy then bounds the agreement: 1e-9).
TEMPLATE_TEST_CASE("regression on matrix groups", "[matrix_group][regression]",
                   bireg::Heisenberg<double>, bireg::SL3<double>) {
  using G = TestType;
  std::mt19937 rng(93);
  const typename G::Element g0 = G::exp(random_tangent<typename G::Tangent>(rng, kScale));
  const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kScale);
  const typename G::Element h = G::exp(random_tangent<typename G::Tangent>(rng, kScale));
  std::vector<typename G::Element> f, noisy, left, right, inverted;
  std::vector<double> t;
  for (int i = 0; i < 25; ++i) {
    const double s = i / 24.0;
    f.push_back(G::compose(g0, G::exp(s * x)));
    noisy.push_back(G::compose(f.back(), G::exp(random_tangent<typename G::Tangent>(rng, 0.05))));
    left.push_back(G::compose(h, noisy.back()));
    right.push_back(G::compose(noisy.back(), h));
    inverted.push_back(G::inverse(noisy.back()));
    t.push_back(s);
  }
  typename bireg::GeodesicRegression<G>::Options options;
  options.tolerance = 1e-13;
  const bireg::GeodesicRegression<G> regression(options);
  const auto exact = regression.fit(f, t);
  REQUIRE(exact.ok());
  REQUIRE(relative_error(exact.geodesic.start(), g0) <= 1e-9);
  REQUIRE(relative_error(exact.geodesic.end(), G::compose(g0, G::exp(x))) <= 1e-9);

  const auto base = regression.fit(noisy, t);
  const auto l = regression.fit(left, t);
  const auto r = regression.fit(right, t);
  const auto v = regression.fit(inverted, t);
  REQUIRE((base.ok() && l.ok() && r.ok() && v.ok()));
  REQUIRE(relative_error(l.geodesic.start(), G::compose(h, base.geodesic.start())) <= 1e-9);
  REQUIRE(relative_error(r.geodesic.end(), G::compose(base.geodesic.end(), h)) <= 1e-9);
  REQUIRE(relative_error(v.geodesic.start(), G::inverse(base.geodesic.start())) <= 1e-9);
  REQUIRE(relative_error(v.geodesic.end(), G::inverse(base.geodesic.end())) <= 1e-9);
}
