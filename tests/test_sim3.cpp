// Sim(3): accuracy of the closed-form exp and log over the (log-scale,
// angle) plane, including the joint limit sigma, theta -> 0, the switch
// between series and closed forms at |sigma + i theta| = 2, the reflection
// at sigma = 0 and log-scales of +-20; and is_element.
//
// Reference: the matrix exponential of hat(x) in long double (scaling and
// squaring of a Taylor series, test_support.hpp), which shares no code with
// Sim3's coefficient functions. Errors are measured per block (scaled
// rotation, translation), each relative to its own size, so the e^-20 scale
// block is not hidden behind a translation of size 1/20.
//
// Tolerance. exp is a handful of roundings on top of the coefficient
// functions, which lose at most a factor ~3 to cancellation (sim3.hpp); log
// adds the SO(3) log (<= 2 eps, test_group_accuracy) and V^{-1}, whose
// condition number is below 2 (V is normal with eigenvalues E(sigma) and
// E(sigma +- i theta)). We allow 16 eps, a factor ~2.5 above the worst
// measured (6.6 eps for exp, 3.5 for log in double; set
// BIREG_ACCURACY_REPORT=1 to print it); an error in any coefficient formula
// or branch is O(1) or at least 1e-8 at these inputs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/groups/sim3.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::eps;
using bireg_test::relative_error;

namespace {

constexpr long double kPi = 3.141592653589793238462643383279502884L;
constexpr long double kUlps = 16;

bool report() {
  return std::getenv("BIREG_ACCURACY_REPORT") != nullptr;
}

std::vector<double> log_scales() {
  std::vector<double> values = {0.0};
  for (double magnitude : {1e-300, 1e-12, 1e-8, 1e-4, 0.01, 0.3, 1.0, 1.4, 1.9999, 2.0, 2.0001, 3.0,
                           5.0, 10.0, 20.0}) {
    values.push_back(magnitude);
    values.push_back(-magnitude);
  }
  return values;
}

std::vector<double> angles() {
  return {0.0,    1e-300, 1e-12, 1e-8,   1e-4, 0.01, 0.5,    1.0,
          1.7320, 1.9999, 2.0,   2.0001, 2.5,  3.0,  3.1415, static_cast<double>(kPi) - 1e-6};
}

template <class Scalar>
struct BlockErrors {
  long double scaled_rotation = 0, translation = 0, tangent = 0;
};

// exp(x) against the long double reference, block by block.
template <class Scalar>
BlockErrors<Scalar> exp_errors(const typename bireg::Sim3<Scalar>::Tangent& x) {
  using G = bireg::Sim3<Scalar>;
  using LongAlgebra = Eigen::Matrix<long double, 4, 4>;
  const LongAlgebra reference =
      bireg_test::reference_expm<4>(LongAlgebra(G::hat(x).template cast<long double>()));
  const typename G::Element g = G::exp(x);
  BlockErrors<Scalar> e;
  e.scaled_rotation =
      relative_error(g.template topLeftCorner<3, 3>(), reference.template topLeftCorner<3, 3>());
  e.translation =
      relative_error(g.template topRightCorner<3, 1>(), reference.template topRightCorner<3, 1>());
  // log of the correctly rounded reference element, against x.
  const typename G::Element rounded = reference.template cast<Scalar>();
  e.tangent = relative_error(G::log(rounded), x);
  return e;
}

}  // namespace

TEMPLATE_TEST_CASE("Sim3 satisfies the group concept", "[sim3]", bireg::Sim3<float>,
                   bireg::Sim3<double>, bireg::Sim3<long double>) {
  STATIC_REQUIRE(bireg::check_lie_group<TestType>());
}

TEMPLATE_TEST_CASE("Sim3 exp and log are accurate over log-scales and angles", "[sim3][accuracy]",
                   float, double) {
  using Scalar = TestType;
  using G = bireg::Sim3<Scalar>;
  std::mt19937 rng(301);
  long double worst_exp = 0, worst_log = 0;
  std::map<double, std::pair<long double, long double>> by_log_scale;  // grid rows: exp, log
  const auto check = [&](double sigma, double theta) {
    const auto axis = bireg_test::random_unit<3>(rng);
    const auto direction = bireg_test::random_unit<3>(rng);
    typename G::Tangent x;
    x.template head<3>() = direction.template cast<Scalar>();
    x.template segment<3>(3) = (static_cast<long double>(theta) * axis).template cast<Scalar>();
    x[6] = static_cast<Scalar>(sigma);
    const BlockErrors<Scalar> e = exp_errors<Scalar>(x);
    CAPTURE(sigma, theta);
    REQUIRE(e.scaled_rotation <= kUlps * eps<Scalar>());
    REQUIRE(e.translation <= kUlps * eps<Scalar>());
    // log: the log-scale is stored as 1 + sigma in the diagonal, so its
    // error is absolute (eps), hence relative to the largest entry of x.
    REQUIRE(e.tangent <= kUlps * eps<Scalar>());
    worst_exp = std::max({worst_exp, e.scaled_rotation, e.translation});
    worst_log = std::max(worst_log, e.tangent);
    return e;
  };
  for (double sigma : log_scales()) {
    for (double theta : angles()) {
      for (int sample = 0; sample < 4; ++sample) {
        const BlockErrors<Scalar> e = check(sigma, theta);
        auto& row = by_log_scale[sigma];
        row.first = std::max({row.first, e.scaled_rotation, e.translation});
        row.second = std::max(row.second, e.tangent);
      }
    }
  }
  // The grid points share their sin/cos roundings; random (sigma, theta),
  // log-uniform in magnitude, probe every rounding pattern.
  std::uniform_real_distribution<double> exponent(-10.0, std::log10(20.0));
  std::uniform_real_distribution<double> angle_exponent(-10.0, std::log10(3.1));
  std::bernoulli_distribution negative(0.5);
  for (int sample = 0; sample < 4000; ++sample) {
    const double sign = negative(rng) ? -1 : 1;
    const double sigma = sign * std::pow(10.0, exponent(rng));
    check(sigma, std::pow(10.0, angle_exponent(rng)));
  }
  if (report()) {
    const char* scalar = sizeof(Scalar) == 4 ? "float" : "double";
    std::printf("Sim3<%s>: exp max error %.2f eps, log max error %.2f eps\n", scalar,
                static_cast<double>(worst_exp / eps<Scalar>()),
                static_cast<double>(worst_log / eps<Scalar>()));
    std::printf("| log-scale | exp (%s) | log (%s) |\n|---|---|---|\n", scalar, scalar);
    for (const auto& [sigma, row] : by_log_scale) {
      std::printf("| %g | %.2f | %.2f |\n", sigma, static_cast<double>(row.first / eps<Scalar>()),
                  static_cast<double>(row.second / eps<Scalar>()));
    }
  }
}

TEST_CASE("Sim3 log at rotation angle pi keeps exp(log(g)) = g", "[sim3][accuracy]") {
  using G = bireg::Sim3<double>;
  std::mt19937 rng(302);
  for (double sigma : {-20.0, -1.0, 0.0, 1e-9, 1.5, 20.0}) {
    const auto axis = bireg_test::random_unit<3>(rng);
    G::Tangent x;
    x << 0.3, -0.2, 0.9, (kPi * axis).cast<double>(), sigma;
    const G::Element g = G::exp(x);
    const G::Tangent y = G::log(g);
    CAPTURE(sigma);
    REQUIRE(y.segment<3>(3).norm() <= static_cast<double>(kPi) * (1 + 4 * eps<double>()));
    const G::Element back = G::exp(y);
    REQUIRE(relative_error(back.topLeftCorner<3, 3>(), g.topLeftCorner<3, 3>()) <=
            kUlps * eps<double>());
    REQUIRE(relative_error(back.topRightCorner<3, 1>(), g.topRightCorner<3, 1>()) <=
            kUlps * eps<double>());
  }
}

TEST_CASE("Sim3 is_element checks scale-orthogonality, determinant and last row", "[sim3]") {
  using G = bireg::Sim3<double>;
  G::Tangent x;
  x << 1, 2, 3, 0.4, -0.5, 0.6, 3.0;  // scale e^3 ~ 20
  const G::Element g = G::exp(x);
  REQUIRE(G::is_element(g));
  G::Element sheared = g;
  sheared(0, 1) += 1e-3 * sheared(0, 0);
  REQUIRE_FALSE(G::is_element(sheared));
  G::Element reflected = g;
  reflected.col(0) = -reflected.col(0);
  REQUIRE_FALSE(G::is_element(reflected));
  G::Element bad_row = g;
  bad_row(3, 0) = 0.5;
  REQUIRE_FALSE(G::is_element(bad_row));
  G::Element collapsed = G::Element::Identity();
  collapsed.topLeftCorner<3, 3>().setZero();
  REQUIRE_FALSE(G::is_element(collapsed));
  G::Element not_finite = g;
  not_finite(2, 3) = std::numeric_limits<double>::infinity();
  REQUIRE_FALSE(G::is_element(not_finite));
}
