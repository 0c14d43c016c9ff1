// Algebraic properties every group in bireg must have, checked on random
// samples for every group and scalar type.
//
// Tolerances. Each identity below is evaluated with O(10) floating-point
// operations on quantities of size O(1) (tangent entries up to 1.5, so
// angles below 2.6 rad, where log is well conditioned), and exp/log are
// accurate to a few ulps (test_group_accuracy). The accumulated rounding is
// therefore a modest multiple of epsilon; we allow kUlps = 64 epsilon, scaled
// by the size of the quantities compared. A sign or convention error shows up
// as an O(1) discrepancy, many orders above this.
#include <algorithm>
#include <limits>
#include <random>
#include <type_traits>

#include "bireg/core/concept.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::eps;
using bireg_test::random_tangent;
using bireg_test::relative_error;

namespace {
constexpr long double kUlps = 64;
constexpr double kSampleScale = 1.5;
constexpr int kSamples = 200;

template <class G>
typename G::Element random_element(std::mt19937& rng) {
  return G::exp(random_tangent<typename G::Tangent>(rng, kSampleScale));
}

template <class G>
long double tolerance(long double scale = 1) {
  return kUlps * eps<typename G::Scalar>() * scale;
}
}  // namespace

#define BIREG_ALL_GROUPS                                                                       \
  bireg::SO2<float>, bireg::SO2<double>, bireg::SO2<long double>, bireg::SO3<float>,           \
      bireg::SO3<double>, bireg::SO3<long double>, bireg::SE2<float>, bireg::SE2<double>,      \
      bireg::SE2<long double>, bireg::SE3<float>, bireg::SE3<double>, bireg::SE3<long double>, \
      (bireg::Rn<3, float>), (bireg::Rn<3, double>), (bireg::Rn<3, long double>),              \
      bireg::Sim3<float>, bireg::Sim3<double>, bireg::Sim3<long double>

TEMPLATE_TEST_CASE("every group satisfies the concept", "[groups]", BIREG_ALL_GROUPS) {
  STATIC_REQUIRE(bireg::check_lie_group<TestType>());
}

TEMPLATE_TEST_CASE("exp and log are mutually inverse", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  std::mt19937 rng(1);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    const typename G::Element g = G::exp(x);
    REQUIRE(relative_error(G::log(g), x) <= tolerance<G>());
    REQUIRE(relative_error(G::exp(G::log(g)), g) <= tolerance<G>());
  }
}

TEMPLATE_TEST_CASE("hat and vee are mutually inverse", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  std::mt19937 rng(2);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    // hat and vee only move entries: exact.
    REQUIRE(G::vee(G::hat(x)) == x);
  }
}

TEMPLATE_TEST_CASE("ad is the bracket of the algebra", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  std::mt19937 rng(3);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    const typename G::Tangent y = random_tangent<typename G::Tangent>(rng, kSampleScale);
    const typename G::Algebra hx = G::hat(x);
    const typename G::Algebra hy = G::hat(y);
    const typename G::Algebra bracket = hx * hy - hy * hx;
    const typename G::Tangent expected = G::vee(bracket);
    // Entries of the bracket are sums of products of O(1.5) entries.
    REQUIRE(((G::ad(x) * y - expected).cwiseAbs().maxCoeff()) <= tolerance<G>(4));
  }
}

TEMPLATE_TEST_CASE("Ad is conjugation", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  std::mt19937 rng(4);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Element g = random_element<G>(rng);
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    const typename G::Tangent expected =
        G::vee(G::hat(G::log(G::compose(G::compose(g, G::exp(x)), G::inverse(g)))));
    // Ad_g x = log(g exp(x) g^{-1}) for the principal log as long as |x| < pi.
    // The conjugated element is rounded at the scale of g's entries, so the
    // comparison is absolute, at the scale of Ad_g x's entries or 1.
    const typename G::Tangent direct = G::Ad(g) * x;
    const long double scale = std::max<long double>(1, direct.cwiseAbs().maxCoeff());
    REQUIRE((direct - expected).cwiseAbs().maxCoeff() <= tolerance<G>(8 * scale));
  }
}

TEMPLATE_TEST_CASE("Ad of exp is the exponential of ad", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  constexpr int d = G::dof;
  std::mt19937 rng(5);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    const Eigen::Matrix<long double, d, d> ad = G::ad(x).template cast<long double>();
    const Eigen::Matrix<long double, d, d> expected = bireg_test::reference_expm<d>(ad);
    // Ad(exp x) entries reach |rho| (SE3: hat(t) R), hence the scale 8.
    REQUIRE(relative_error(G::Ad(G::exp(x)), expected) <= tolerance<G>(8));
  }
}

TEMPLATE_TEST_CASE("Ad is a homomorphism and the group axioms hold", "[groups]", BIREG_ALL_GROUPS) {
  using G = TestType;
  std::mt19937 rng(6);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Element a = random_element<G>(rng);
    const typename G::Element b = random_element<G>(rng);
    const typename G::Element c = random_element<G>(rng);
    const typename G::AdMatrix ad_ab = G::Ad(G::compose(a, b));
    REQUIRE(relative_error(ad_ab, G::Ad(a) * G::Ad(b)) <= tolerance<G>(8));

    REQUIRE(G::compose(G::identity(), a) == a);
    REQUIRE(G::compose(a, G::identity()) == a);
    REQUIRE(relative_error(G::compose(a, G::inverse(a)), G::identity()) <= tolerance<G>(4));
    REQUIRE(relative_error(G::compose(G::inverse(a), a), G::identity()) <= tolerance<G>(4));
    REQUIRE(relative_error(G::compose(G::compose(a, b), c), G::compose(a, G::compose(b, c))) <=
            tolerance<G>(8));
    REQUIRE(
        G::is_element(G::compose(a, b), bireg::default_element_tolerance<typename G::Scalar>()));
  }
}

TEMPLATE_TEST_CASE("commutative groups have ad = 0", "[groups]", bireg::SO2<double>,
                   (bireg::Rn<3, double>), (bireg::Rn<1, float>)) {
  using G = TestType;
  std::mt19937 rng(7);
  for (int i = 0; i < kSamples; ++i) {
    const typename G::Tangent x = random_tangent<typename G::Tangent>(rng, kSampleScale);
    REQUIRE(G::ad(x).isZero(0));
    const typename G::Element a = random_element<G>(rng);
    const typename G::Element b = random_element<G>(rng);
    REQUIRE(relative_error(G::compose(a, b), G::compose(b, a)) <= tolerance<G>());
  }
}

TEMPLATE_TEST_CASE("is_element accepts near-group matrices and rejects far ones", "[groups]",
                   bireg::SO2<double>, bireg::SO3<double>, bireg::SE2<double>, bireg::SE3<double>,
                   bireg::SO3<float>, bireg::SE3<float>, bireg::Sim3<double>, bireg::Sim3<float>) {
  using G = TestType;
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  std::mt19937 rng(8);
  const Element g = random_element<G>(rng);
  REQUIRE(G::is_element(g));

  // An orthonormality error of 1e-10 (well inside the default 1e-6) passes...
  Element slightly_off = g;
  slightly_off(0, 0) += Scalar(1e-10);
  REQUIRE(G::is_element(slightly_off));
  // ... and the log of such a matrix is still within 1e-10 of the true one.
  REQUIRE(relative_error(G::exp(G::log(slightly_off)), g) <= 1e-9L + tolerance<G>());

  Element far_off = g;
  far_off(0, 0) += Scalar(1e-3);
  REQUIRE_FALSE(G::is_element(far_off));

  Element reflected = g;  // determinant -1
  reflected.col(0) = -reflected.col(0);
  REQUIRE_FALSE(G::is_element(reflected));

  Element not_finite = g;
  not_finite(0, 1) = std::numeric_limits<Scalar>::quiet_NaN();
  REQUIRE_FALSE(G::is_element(not_finite));

  constexpr bool homogeneous = std::is_same_v<G, bireg::SE2<Scalar>> ||
                               std::is_same_v<G, bireg::SE3<Scalar>> ||
                               std::is_same_v<G, bireg::Sim3<Scalar>>;
  if constexpr (homogeneous) {
    Element bad_last_row = g;
    bad_last_row(G::matrix_size - 1, 0) = Scalar(0.5);
    REQUIRE_FALSE(G::is_element(bad_last_row));
  }
}
