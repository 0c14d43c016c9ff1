// Algebraic properties every group in bireg must have, checked on random
// samples for every group and scalar type through the laws of
// bireg/testing/group_laws.hpp (the same check users run on their groups).
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

#include "bireg/concept.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/testing/group_laws.hpp"
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

// The laws of bireg/testing/group_laws.hpp. Algebraic identities take O(10)
// operations on entries up to ~3 (Ad's translation block), so 8 kUlps;
// finite differences of exp err by O(h^2 + epsilon/h) = O(epsilon^(2/3)) with
// a constant set by exp's third derivative, below 100 for these sizes.
TEMPLATE_TEST_CASE("every group satisfies the group laws", "[groups]", BIREG_ALL_GROUPS,
                   (bireg::Product<bireg::SO3<double>, bireg::Rn<3, double>>),
                   (bireg::Product<bireg::SO2<float>, bireg::SE2<float>>)) {
  using G = TestType;
  using Scalar = typename G::Scalar;
  std::mt19937 rng(1);
  const bireg::testing::GroupLawErrors e =
      bireg::testing::group_law_errors<G>(rng, kSamples, kSampleScale);
  const long double algebraic = tolerance<G>(8);
  const long double finite_difference =
      100 * std::pow(static_cast<long double>(eps<Scalar>()), 2.0L / 3);
  CAPTURE(G::name, e.log_of_exp, e.exp_of_log, e.inverse, e.associativity, e.ad_antisymmetry,
          e.ad_exp, e.ad_homomorphism, e.ad_conjugation, e.jacobian, e.jacobian_inverse,
          e.jacobian_pair, e.psi);
  REQUIRE(e.log_of_exp <= algebraic);
  REQUIRE(e.exp_of_log <= algebraic);
  REQUIRE(e.inverse <= algebraic);
  REQUIRE(e.associativity <= algebraic);
  REQUIRE(e.ad_antisymmetry <= algebraic);
  REQUIRE(e.ad_exp <= algebraic);
  REQUIRE(e.ad_homomorphism <= algebraic);
  REQUIRE(e.ad_conjugation <= algebraic);
  REQUIRE(e.jacobian <= finite_difference);
  REQUIRE(e.jacobian_inverse <= algebraic);
  REQUIRE(e.jacobian_pair <= algebraic);
  REQUIRE(e.psi <= algebraic);
}

// The laws can fail: a group whose right Jacobian has the wrong sign of its
// first-order term (the left Jacobian instead) is caught by the finite
// differences, by the psi identity and by its (inherited, correct)
// right_jacobian_pair disagreeing with it, by orders of magnitude.
struct SO3WithLeftJacobian : bireg::SO3<double> {
  static AdMatrix right_jacobian(const Tangent& x) {
    return bireg::SO3<double>::right_jacobian(-x);
  }
};
TEST_CASE("the group laws catch a wrong Jacobian", "[groups]") {
  std::mt19937 rng(1);
  const auto e = bireg::testing::group_law_errors<SO3WithLeftJacobian>(rng, 20, kSampleScale);
  REQUIRE(e.jacobian > 1e-2);
  REQUIRE(e.jacobian_inverse > 1e-2);
  REQUIRE(e.jacobian_pair > 1e-2);
  REQUIRE(e.psi > 1e-2);
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

  // An error of a tenth of the default tolerance (1e-7 in double, well above
  // float's ulp too, as the first check proves) passes...
  const Scalar off = bireg::default_element_tolerance<Scalar>() / 10;
  Element slightly_off = g;
  slightly_off(0, 0) += off;
  REQUIRE(slightly_off != g);
  REQUIRE(G::is_element(slightly_off));
  // ... and exp(log) of such a matrix projects it back to within a few
  // times that error of the element it came from.
  REQUIRE(relative_error(G::exp(G::log(slightly_off)), g) <= 4 * off + tolerance<G>());

  Element far_off = g;
  far_off(0, 0) += Scalar(1e-3);
  REQUIRE_FALSE(G::is_element(far_off));

  Element reflected = g;  // determinant -1
  reflected.col(0) = -reflected.col(0);
  REQUIRE_FALSE(G::is_element(reflected));

  Element not_finite = g;
  not_finite(0, 1) = std::numeric_limits<Scalar>::quiet_NaN();
  REQUIRE_FALSE(G::is_element(not_finite));
  // SO(3) and SE(3) have no finiteness scan of their own (a non-finite
  // entry fails one of the comparisons): every entry, each such value.
  const Scalar infinity = std::numeric_limits<Scalar>::infinity();
  for (Eigen::Index r = 0; r < g.rows(); ++r) {
    for (Eigen::Index c = 0; c < g.cols(); ++c) {
      for (const Scalar bad : {std::numeric_limits<Scalar>::quiet_NaN(), infinity, -infinity}) {
        Element e = g;
        e(r, c) = bad;
        REQUIRE_FALSE(G::is_element(e));
        REQUIRE_FALSE(G::is_element(e, infinity));  // a comparison with inf would pass it
      }
    }
  }

  constexpr bool homogeneous = std::is_same_v<G, bireg::SE2<Scalar>> ||
                               std::is_same_v<G, bireg::SE3<Scalar>> ||
                               std::is_same_v<G, bireg::Sim3<Scalar>>;
  if constexpr (homogeneous) {
    Element bad_last_row = g;
    bad_last_row(G::matrix_size - 1, 0) = Scalar(0.5);
    REQUIRE_FALSE(G::is_element(bad_last_row));
  }
}
