// MatrixGroup<N, Basis>: the algebraic identities of test_groups.cpp on the
// Heisenberg group, SL(3) and GL+(3), the Heisenberg group's polynomial
// closed forms and terminating series, exp/log from tiny to near the branch
// cut, and the log's domain (the regression on them: test_scene_groups.cpp
// for the Heisenberg group, test_scene_groups_matrix.cpp for SL(3), GL+(3)).
//
// Tolerance: the matrix exponential (Pade with scaling and squaring) and
// logarithm (inverse scaling and squaring) of bireg/math/matrix_functions.hpp
// are within ~10 epsilon of a long double reference at the norms used here
// (tangent entries up to 0.5, so no eigenvalue near the log's branch cut);
// identities that chain two or three of them are allowed 1e-12 relative,
// ~5000 epsilon, far below the O(1) error of a wrong sign or basis.
//
// Hostile inputs (huge, non-finite, on the branch cut) must come back as NaN
// within a bounded time: Eigen's logarithm looped for ever on some and its
// Schur decomposition asserted on others.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/groups/matrix_group.hpp"
#include "bireg/math/eigenvalue_spread.hpp"
#include "bireg/math/matrix_functions.hpp"
#include "bireg/math/psi_series.hpp"
#include "bireg/regression.hpp"
#include "bireg/testing/group_laws.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;
using bireg_test::relative_error;

namespace {
constexpr double kTolerance = 1e-12;
constexpr double kScale = 0.5;

// Runs f and requires that it returns within one second: a hang guard (the
// functions under test take microseconds), not a speed requirement.
template <class F>
auto within_a_second(F f) {
  const auto start = std::chrono::steady_clock::now();
  const auto result = f();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  REQUIRE(seconds < 1.0);
  return result;
}
}  // namespace

// The laws of bireg/testing/group_laws.hpp, as for every other group
// (test_groups.cpp). Identities within kTolerance (see above); the finite
// differences of exp err by O(epsilon^(2/3)) with a constant below 100.
TEMPLATE_TEST_CASE("matrix groups satisfy the group laws", "[matrix_group]",
                   bireg::Heisenberg<double>, bireg::SL3<double>, (bireg::GLp<3, double>)) {
  using G = TestType;
  std::mt19937 rng(92);
  const auto e = bireg::testing::group_law_errors<G>(rng, 50, kScale);
  CAPTURE(e.log_of_exp, e.exp_of_log, e.inverse, e.associativity, e.ad_antisymmetry, e.ad_exp,
          e.ad_homomorphism, e.ad_conjugation, e.jacobian, e.jacobian_inverse, e.jacobian_pair,
          e.psi);
  REQUIRE(e.log_of_exp <= kTolerance);
  REQUIRE(e.exp_of_log <= kTolerance);
  REQUIRE(e.inverse <= kTolerance);
  REQUIRE(e.associativity <= kTolerance);
  REQUIRE(e.ad_antisymmetry <= kTolerance);
  REQUIRE(e.ad_exp <= kTolerance);
  REQUIRE(e.ad_homomorphism <= kTolerance);
  REQUIRE(e.ad_conjugation <= kTolerance);
  REQUIRE(e.jacobian <= 100 * std::pow(2.220446049250313e-16, 2.0 / 3));
  REQUIRE(e.jacobian_inverse <= kTolerance);
  REQUIRE(e.jacobian_pair <= kTolerance);
  REQUIRE(e.psi <= kTolerance);
}

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

// The spectral radius of ad_x from the eigenvalues of X = hat x
// (math/eigenvalue_spread.hpp): on matrices P D P^{-1} whose eigenvalues
// are chosen, the spread is known by hand. Separated eigenvalues with P of
// condition ~3: 1e-12 relative (a few hundred epsilon through P^{-1}, the
// cubic's coefficients and acos/cbrt); a double eigenvalue, whose cubic
// root moves by the square root of a rounding error: 1e-6 relative.
TEST_CASE("ad's spectral radius is the spread of the matrix's eigenvalues", "[matrix_group]") {
  using Matrix3 = Eigen::Matrix3d;
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> entry(-0.3, 0.3);
  const auto near_identity = [&] {  // condition number ~3
    Matrix3 p;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        p(r, c) = (r == c ? 1.0 : 0.0) + entry(rng);
    return p;
  };
  const auto similar = [&](const Matrix3& d) {
    const Matrix3 p = near_identity();
    return Matrix3(p * d * p.inverse());
  };
  const auto rotation_block = [](double a, double b, double r) {
    Matrix3 d = Matrix3::Zero();  // eigenvalues a +- i b and r
    d << a, -b, 0, b, a, 0, 0, 0, r;
    return d;
  };
  struct Case {
    Matrix3 d;
    double spread;
    double tolerance;
  };
  const Case cases[] = {
      {Eigen::Vector3d(0.3, -1.2, 2.0).asDiagonal(), 3.2, 1e-12},
      {rotation_block(0.5, 2.0, -1.0), 4.0, 1e-12},                   // 2 b wins
      {rotation_block(0.0, 0.5, 3.0), std::sqrt(9.0 + 0.25), 1e-12},  // |r - a -+ i b| wins
      {rotation_block(7.0, 1.5, 7.0), 3.0, 1e-12},                    // a shift changes nothing
      {Eigen::Vector3d(1.0, 1.0, -2.0).asDiagonal(), 3.0, 1e-6},      // a double eigenvalue
  };
  for (const Case& c : cases) {
    for (double scale : {1.0, 1e150, 1e-150}) {
      const Matrix3 x = similar(c.d) * scale;
      CAPTURE(c.spread, scale);
      REQUIRE(std::abs(bireg::math::eigenvalue_spread<double, 3>(x) / scale - c.spread) <=
              c.tolerance * c.spread);
    }
  }
  // Exactly 0: a multiple of the identity, a nilpotent Jordan block, zero.
  REQUIRE(bireg::math::eigenvalue_spread<double, 3>(Matrix3(4.0 * Matrix3::Identity())) == 0.0);
  Matrix3 jordan = Matrix3::Zero();
  jordan(0, 1) = jordan(1, 2) = 1.0;
  REQUIRE(bireg::math::eigenvalue_spread<double, 3>(jordan) == 0.0);
  REQUIRE(bireg::math::eigenvalue_spread<double, 3>(Matrix3(Matrix3::Zero())) == 0.0);
  // Eigenvalues +-1e-150 (real) and +-1e-150 i beside a unit entry, and
  // the cube roots of 1e-200 (spread sqrt(3) 1e-200^(1/3)): their cubes
  // underflow. Entries near the largest double: their trace overflows.
  Matrix3 tiny_pair = Matrix3::Zero();
  tiny_pair(0, 1) = 1.0;
  for (double corner : {1e-300, -1e-300}) {
    tiny_pair(1, 0) = corner;
    REQUIRE(bireg::math::eigenvalue_spread<double, 3>(tiny_pair) == Approx(2e-150).epsilon(1e-12));
  }
  Matrix3 companion = Matrix3::Zero();  // t^3 - 1e-200
  companion(0, 1) = companion(1, 2) = 1.0;
  companion(2, 0) = 1e-200;
  REQUIRE(bireg::math::eigenvalue_spread<double, 3>(companion) ==
          Approx(std::sqrt(3.0) * std::cbrt(1e-200)).epsilon(1e-12));
  const Matrix3 near_max = 1e308 * Matrix3::Identity() + Matrix3::Ones();  // 1e308 + {2, -1, -1}
  REQUIRE(bireg::math::eigenvalue_spread<double, 3>(near_max) == Approx(3.0).epsilon(1e-12));
  // float: the same tiny pair at float's range.
  Eigen::Matrix3f tiny_float = Eigen::Matrix3f::Zero();
  tiny_float(0, 1) = 1.0f;
  tiny_float(1, 0) = 1e-30f;
  REQUIRE(bireg::math::eigenvalue_spread<float, 3>(tiny_float) == Approx(2e-15).epsilon(1e-5));
  // 2 x 2: [1 2; 3 4] has (5 +- sqrt 33)/2, also at 1e300 and 1e-300; a
  // rotation generator +- i theta.
  for (double scale : {1.0, 1e300, 1e-300}) {
    const Eigen::Matrix2d m = scale * (Eigen::Matrix2d() << 1, 2, 3, 4).finished();
    REQUIRE(bireg::math::eigenvalue_spread<double, 2>(m) / scale ==
            Approx(std::sqrt(33.0)).epsilon(1e-14));
  }
  REQUIRE(bireg::math::eigenvalue_spread<double, 2>(
              (Eigen::Matrix2d() << 0, -0.7, 0.7, 0).finished()) == Approx(1.4).epsilon(1e-14));
  // Not finite in, NaN out (callers test !(radius < limit)).
  Matrix3 hostile = similar(cases[0].d);
  hostile(1, 2) = std::numeric_limits<double>::quiet_NaN();
  REQUIRE(std::isnan(bireg::math::eigenvalue_spread<double, 3>(hostile)));
  hostile(1, 2) = std::numeric_limits<double>::infinity();
  REQUIRE(std::isnan(bireg::math::eigenvalue_spread<double, 3>(hostile)));

  // On the groups: GL+(3) takes any X, SL(3) its traceless part. The
  // largest difference lambda_i - lambda_j is an eigenvalue of ad_x on the
  // algebra itself: v_i w_j^T (v_i = P e_i, w_j^T = e_j^T P^{-1}) is in
  // sl(3) for i != j and ad_x maps it to (lambda_i - lambda_j) v_i w_j^T.
  const Eigen::Vector3d lambda(0.3, -1.2, 2.0);
  const Matrix3 p = near_identity();
  const Matrix3 p_inverse = p.inverse();
  const Matrix3 x = p * lambda.asDiagonal() * p_inverse;
  using GL = bireg::GLp<3, double>;
  REQUIRE(bireg::ad_spectral_radius<GL>(GL::vee(x)) == Approx(3.2).epsilon(1e-12));
  using SL = bireg::SL3<double>;
  const Matrix3 traceless = x - (x.trace() / 3.0) * Matrix3::Identity();
  const SL::Tangent sl_x = SL::vee(traceless);
  REQUIRE(bireg::ad_spectral_radius<SL>(sl_x) == Approx(3.2).epsilon(1e-12));
  const Matrix3 rank_one = p.col(2) * p_inverse.row(1);  // i = 2 (2.0), j = 1 (-1.2)
  const SL::Tangent v = SL::vee(rank_one);
  REQUIRE(relative_error(SL::Algebra(SL::hat(v)), rank_one) <= 1e-14);  // in sl(3)
  REQUIRE(relative_error(SL::Tangent(SL::ad(sl_x) * v), SL::Tangent(3.2 * v)) <= 1e-12);
  // Heisenberg: X strictly upper triangular, ad_x nilpotent: both 0.
  using H = bireg::Heisenberg<double>;
  // The three take the closed form, not the eigensolver on ad_x (which
  // would compile again); none claims ad_spectral_radius itself, which
  // would turn on the per-residual angle diagnostics.
  using bireg::capability_detail::ad_spectral_radius_from_matrix;
  static_assert(bireg::provides_v<GL, ad_spectral_radius_from_matrix>);
  static_assert(bireg::provides_v<SL, ad_spectral_radius_from_matrix>);
  static_assert(bireg::provides_v<H, ad_spectral_radius_from_matrix>);
  static_assert(!bireg::provides_v<GL, bireg::capability_detail::ad_spectral_radius>);
  static_assert(!bireg::provides_v<bireg::GLp<4, double>, ad_spectral_radius_from_matrix>);
  REQUIRE(bireg::ad_spectral_radius<H>(H::Tangent(0.4, -2.0, 5.0)) == 0.0);
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

// Outside the principal log's domain no logarithm is returned: bireg returns
// NaN there and the fit names the observation.
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

  // The Heisenberg group's log is a polynomial, defined everywhere.
  const bireg::Heisenberg<double>::Element h = bireg::Heisenberg<double>::exp({1e3, -1e3, 5.0});
  REQUIRE(bireg::Heisenberg<double>::log(h).allFinite());
}

// Inputs on which Eigen's MatrixFunctions hung (inverse scaling and squaring
// never terminating once a norm became NaN) or aborted (its Schur
// decomposition's assertion, in builds without NDEBUG): each now returns
// NaN, at once.
TEMPLATE_TEST_CASE("matrix groups: hostile inputs give NaN, never a hang or an abort",
                   "[matrix_group][errors]", bireg::SL3<double>, (bireg::GLp<3, double>)) {
  using G = TestType;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto log_is_nan = [](const Element& g) {
    const Tangent y = within_a_second([&] { return G::log(g); });
    return y.array().isNaN().all();
  };

  // Unit upper triangular, one entry 1.1e63 (in GL+(3) and SL(3)): its
  // logarithm would need ~210 square roots; refused after 64.
  Element shear = Element::Identity();
  shear(0, 2) = 1.1e63;
  REQUIRE(log_is_nan(shear));
  // The same entry in a dense matrix with negative determinant: a negative
  // real eigenvalue, no real logarithm.
  Element dense;
  dense << 2, 1.1e63, 0.3, 0.1, 1, 0, 0, 0, 1;
  REQUIRE(log_is_nan(dense));
  // Unit upper triangular with 1e200 entries: its inverse overflows.
  Element huge = Element::Identity();
  huge(0, 1) = huge(0, 2) = huge(1, 2) = 1e200;
  REQUIRE(log_is_nan(huge));
  // The rotation by exactly pi about z: eigenvalues -1, -1 on the branch cut.
  const Element half_turn = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
  REQUIRE(G::is_element(half_turn));
  REQUIRE(log_is_nan(half_turn));
  // exp of the rotation generator by pi in floating point (eigenvalues
  // within 1e-16 of the cut): either refused or a true logarithm.
  Eigen::Matrix3d skew = Eigen::Matrix3d::Zero();
  skew(0, 1) = -1;
  skew(1, 0) = 1;
  const Element rounded_half_turn = G::exp(3.141592653589793 * G::vee(skew));
  const Tangent y = within_a_second([&] { return G::log(rounded_half_turn); });
  if (y.allFinite()) REQUIRE(relative_error(G::exp(y), rounded_half_turn) <= 1e-8);
  // Non-finite entries.
  for (double bad : {nan, inf, -inf}) {
    Element g = Element::Identity();
    g(1, 0) = bad;
    REQUIRE(log_is_nan(g));
    Tangent x = Tangent::Zero();
    x[1] = bad;
    REQUIRE_FALSE(within_a_second([&] { return G::exp(x); }).allFinite());
  }
  // exp of a huge tangent overflows to a flagged (non-finite) result after
  // a bounded number of squarings instead of running on.
  for (double size : {1e300, 1e30, 1e3}) {
    CAPTURE(size);
    const Tangent x = Tangent::Constant(size);
    REQUIRE_FALSE(within_a_second([&] { return G::exp(x); }).allFinite());
  }
}

// Found by fuzz_bireg_fit: two GL+(3) observations, one with entries 9e10
// and 1e93 (determinant > 0, each log finite on its own). The residual of
// one against the other cannot be computed in double, so the estimating
// equations are not finite at any start. The fit used to report
// `diverged` after 0 iterations with a non-finite force, residual RMS and
// explained variance; it now refuses the data, naming the observation.
TEST_CASE("GL+(3): data whose residuals double cannot compute are refused, not NaN",
          "[matrix_group][errors]") {
  using G = bireg::GLp<3, double>;
  G::Element huge, moderate;
  huge << 1.1967519434554703, 0.10848340422183004, 0.01583330414573588, -0.00349044317780999,
      94274214889, 0.20396611242540016, 0.05399143513734126, 0.0320959019764489, 1e93;
  moderate << 0.4124386583903679, -0.02333745909697053, 0.13477997402357375, 0.15375817461303468,
      2.97497889436859, 0.2045456942787698, 0.07473029992205144, 0.03317811520773627,
      1.6161007897712676;
  REQUIRE(G::is_element(huge));
  REQUIRE(G::is_element(moderate));
  REQUIRE(G::log(huge).allFinite());
  REQUIRE(G::log(moderate).allFinite());
  const auto result = within_a_second([&] {
    return bireg::GeodesicRegression<G>().fit(std::vector<G::Element>{huge, moderate},
                                              std::vector<double>{0.0, 6.0});
  });
  CAPTURE(result.message);
  REQUIRE(result.status == bireg::Status::invalid_input);
  REQUIRE((result.bad_index == 0 || result.bad_index == 1));
  REQUIRE(result.message.find("observation " + std::to_string(result.bad_index) +
                              " is not finite at the start") != std::string::npos);
  REQUIRE_FALSE(result.geodesic);
}

// The matrix functions in every precision: exp within a few epsilon of the
// long double reference, log inverting it, for random general 3x3 matrices
// (gl(3), eigenvalues up to size in modulus) of the sizes of the range test
// above.
TEMPLATE_TEST_CASE("matrix functions: exp and log in float, double and long double",
                   "[matrix_group][accuracy]", float, double, long double) {
  using Scalar = TestType;
  using Matrix = Eigen::Matrix<Scalar, 3, 3>;
  using LongMatrix = Eigen::Matrix<long double, 3, 3>;
  const long double epsilon = std::numeric_limits<Scalar>::epsilon();
  // The reference is good to ~1e-18: long double's own test is limited by it.
  const long double floor = std::max(epsilon, 1e-18L);
  std::mt19937 rng(95);
  long double worst_exp = 0, worst_log = 0;
  for (double size : {0.0, 1e-30, 1e-8, 1e-3, 0.1, 0.5, 1.0, 2.0, 3.0}) {
    for (int sample = 0; sample < 20; ++sample) {
      const Eigen::Matrix<Scalar, 9, 1> entries =
          random_tangent<Eigen::Matrix<Scalar, 9, 1>>(rng, 1.0);
      Matrix a = Eigen::Map<const Matrix>(entries.data());
      a *= Scalar(size) / std::max(a.norm(), Scalar(1e-30));
      const LongMatrix reference = bireg_test::reference_expm<3>(a.template cast<long double>());
      const Matrix e = bireg::math::matrix_exp(a);
      const Matrix back = bireg::math::matrix_log(e);
      REQUIRE(back.allFinite());
      worst_exp = std::max(worst_exp, relative_error(e, reference) / floor);
      worst_log =
          std::max(worst_log, (back.template cast<long double>() - a.template cast<long double>())
                                      .cwiseAbs()
                                      .maxCoeff() /
                                  (std::max(1.0, size) * floor));
    }
  }
  CAPTURE(worst_exp, worst_log);
  // Measured: <= 6 epsilon (exp) and <= 8 epsilon (log) in double.
  REQUIRE(worst_exp <= 64);
  REQUIRE(worst_log <= 64);
}
