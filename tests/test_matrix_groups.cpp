// MatrixGroup<N, Basis>: the algebraic identities of test_groups.cpp on the
// Heisenberg group, SL(3) and GL+(3), the Heisenberg group's polynomial
// closed forms and terminating series, exp/log from tiny to near the branch
// cut, and the log's domain (the regression on them: test_scene_groups.cpp).
//
// Tolerance: Eigen's matrix exponential (Pade with scaling and squaring)
// and logarithm (Schur-Parlett with inverse scaling and squaring) are
// backward stable to a few hundred epsilon at the norms used here (tangent
// entries up to 0.5, so no eigenvalue near the log's branch cut); identities
// that chain two or three of them are allowed 1e-12 relative, ~5000 epsilon,
// far below the O(1) error of a wrong sign or basis.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/math/psi_series.hpp"
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
      REQUIRE(relative_error(bireg::apply_psi<G>(x, s, r), first) <= 1e-15);
    }
  }
}

// Extreme sizes: tangent vectors t u with u a random unit (Frobenius) algebra
// element, t from 0 and 1e-300 up to 3 (the eigenvalues of t hat(u) stay
// below t < pi in modulus, inside the principal log's domain), and the
// rotation generator alone at pi - 1e-k. exp is compared with the long
// double reference; log(exp(x)) with x. Eigen's exp is accurate to a few
// hundred epsilon at these norms and its log is backward stable, so the
// forward error of log is its condition number (~1/(pi - t) near the branch
// cut, where two eigenvalues approach -1 from both sides) times that:
// tolerance 1e-12 / (pi - t) relative, capped below by 1e-12.
TEMPLATE_TEST_CASE("matrix groups: exp and log from tiny to near the branch cut",
                   "[matrix_group][accuracy]", bireg::SL3<double>, (bireg::GLp<3, double>)) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  using LongMatrix = Eigen::Matrix<long double, 3, 3>;
  const double pi = 3.141592653589793;
  std::mt19937 rng(94);
  for (double size : {0.0, 1e-300, 1e-16, 1e-12, 1e-8, 1e-4, 0.1, 1.0, 2.0, 3.0}) {
    for (int sample = 0; sample < 10; ++sample) {
      Tangent u = random_tangent<Tangent>(rng, 1.0);
      u /= G::hat(u).norm();
      const Tangent x = size * u;
      CAPTURE(size);
      const LongMatrix reference =
          bireg_test::reference_expm<3>(LongMatrix(G::hat(x).template cast<long double>()));
      REQUIRE(relative_error(G::exp(x), reference) <= 1e-13);
      const Tangent back = G::log(G::exp(x));
      REQUIRE(back.allFinite());
      // Absolute below size 1 (the identity's rounding is absolute), relative above.
      REQUIRE((back - x).cwiseAbs().maxCoeff() <= 1e-12 * std::max(1.0, size) / (pi - size));
    }
  }
  // The rotation about z inside SL(3) / GL+(3), by pi - 1e-k.
  Eigen::Matrix3d skew = Eigen::Matrix3d::Zero();
  skew(0, 1) = -1;
  skew(1, 0) = 1;
  const Tangent axis = G::vee(skew);
  for (int k = 1; k <= 8; ++k) {
    const double angle = pi - std::pow(10.0, -k);
    CAPTURE(angle);
    const Tangent back = G::log(G::exp(angle * axis));
    REQUIRE(back.allFinite());
    REQUIRE((back - angle * axis).cwiseAbs().maxCoeff() <= 1e-12 * pi / (pi - angle));
  }
}

// Outside the principal log's domain Eigen's log is not a logarithm; bireg
// returns NaN there and the fit names the observation.
TEST_CASE("matrix groups: log outside its domain is NaN, and the fit says so",
          "[matrix_group][errors]") {
  using G = bireg::SL3<double>;
  const G::Element negative = Eigen::Vector3d(-2.0, -0.5, 1.0).asDiagonal();
  REQUIRE(G::is_element(negative));
  REQUIRE(G::log(negative).array().isNaN().all());
  // Just inside: a rotation by pi - 1e-3 has a (finite) principal log.
  G::Tangent x = G::Tangent::Zero();
  x[0] = -(3.141592653589793 - 1e-3);  // E01 coefficient -theta, E10 +theta
  x[2] = 3.141592653589793 - 1e-3;
  REQUIRE(G::log(G::exp(x)).allFinite());

  std::vector<G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 5; ++i) {
    G::Tangent y = G::Tangent::Zero();
    y[0] = -0.1 * i;
    y[2] = 0.1 * i;
    f.push_back(i == 4 ? negative : G::exp(y));
    t.push_back(i);
  }
  const auto result = bireg::GeodesicRegression<G>().fit(f, t);
  REQUIRE(result.status == bireg::Status::invalid_input);
  REQUIRE(result.bad_index == 4);
  REQUIRE(result.message.find("observation 4 is out of reach") != std::string::npos);

  // The Heisenberg group declares that its log exists everywhere.
  const bireg::Heisenberg<double>::Element h = bireg::Heisenberg<double>::exp({1e3, -1e3, 5.0});
  REQUIRE(bireg::Heisenberg<double>::log(h).allFinite());
}
