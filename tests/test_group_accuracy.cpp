// Accuracy of exp and log at the extremes, against long double references
// that share no code with the library's closed forms:
//   * coefficient functions: long double direct formulas where they do not
//     cancel, else Taylor series with textbook coefficients;
//   * SO(3): rotation matrices built from the unit quaternion in long double;
//   * SE(2), SE(3): the matrix exponential of hat(x) by scaling and squaring.
// The inputs are double (or float) numbers; the references are evaluated in
// long double on exactly those inputs, so the errors measured are the
// library's own.
//
// Set BIREG_ACCURACY_REPORT=1 to print the max relative error per angle.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/math/small_angle.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::eps;
using bireg_test::relative_error;

namespace {

constexpr long double kPi = 3.141592653589793238462643383279502884L;

// Angles of the edge cases: 0 and tiny, the band 1e-8 .. 1e-3 where
// naive formulas lose up to 8 digits (five angles per decade), then
// pi - 1e-k, pi and pi + 1e-k (k = 1..14).
std::vector<double> edge_angles(bool include_beyond_pi) {
  std::vector<double> angles = {0.0, 1e-300, 1e-16, 1e-12};
  for (int decade = -8; decade <= -3; ++decade) {
    for (double mantissa : {1.0, 1.6, 2.5, 4.0, 6.3})
      angles.push_back(mantissa * std::pow(10.0, decade));
  }
  for (double x : {0.01, 0.1, 0.5, 1.0, 2.0, 3.0})
    angles.push_back(x);
  for (int k = 1; k <= 14; ++k)
    angles.push_back(static_cast<double>(kPi) - std::pow(10.0, -k));
  angles.push_back(static_cast<double>(kPi));
  if (include_beyond_pi) {
    for (int k = 1; k <= 14; ++k)
      angles.push_back(static_cast<double>(kPi) + std::pow(10.0, -k));
  }
  return angles;
}

// Dense grid for the scalar coefficient functions: 20 points per decade from
// 1e-10 to 1, then linear steps up to 3.1.
std::vector<long double> dense_grid() {
  std::vector<long double> xs = {0.0L};
  for (int i = 0; i <= 200; ++i)
    xs.push_back(std::pow(10.0L, -10.0L + i / 20.0L));
  for (int i = 1; i <= 42; ++i)
    xs.push_back(1.0L + i * 0.05L);
  return xs;
}

// (x - sin x)/x^3: series (-1)^k x^2k/(2k+3)! summed in long double with
// factorials formed on the fly below 2; the direct formula above 2, where it
// loses at most a factor 2.
long double reference_x_minus_sin_over_x3(long double x) {
  if (x >= 2) return (x - std::sin(x)) / (x * x * x);
  long double sum = 0, term = 1.0L / 6.0L;
  for (int k = 0; k < 40; ++k) {
    sum += term;
    term *= -x * x / static_cast<long double>((2 * k + 4) * (2 * k + 5));
  }
  return sum;
}

// (1 - (x/2) cot(x/2))/x^2 = sum_n |B_2n|/(2n)! x^(2n-2); B_2 .. B_20 are the
// textbook rationals. Below x = 1 ten terms leave < (1/2pi)^20 ~ 1e-16 of
// the first, far below the tolerance; above 1 the long double direct formula
// loses at most a factor 12 of its 1e-19.
long double reference_one_minus_half_cot_over_x2(long double x) {
  if (x >= 1) return (1 - (x / 2) * std::cos(x / 2) / std::sin(x / 2)) / (x * x);
  const long double abs_bernoulli[] = {1.0L / 6,       1.0L / 30,      1.0L / 42, 1.0L / 30,
                                       5.0L / 66,      691.0L / 2730,  7.0L / 6,  3617.0L / 510,
                                       43867.0L / 798, 174611.0L / 330};
  long double sum = 0, power = 1, factorial = 1;
  for (int n = 1; n <= 10; ++n) {
    factorial *= static_cast<long double>((2 * n - 1) * (2 * n));
    sum += abs_bernoulli[n - 1] / factorial * power;
    power *= x * x;
  }
  return sum;
}

template <class Scalar>
long double relative(long double value, long double reference) {
  return std::abs(value - reference) / std::abs(reference);
}

bool report_requested() {
  return std::getenv("BIREG_ACCURACY_REPORT") != nullptr;
}

void report(const char* what, const std::map<double, long double>& worst, long double unit) {
  if (!report_requested()) return;
  std::printf("%s (max relative error, in units of epsilon)\n", what);
  for (const auto& [angle, error] : worst) {
    std::printf("  theta = %-24.17g %8.2Lf\n", angle, error / unit);
  }
}

}  // namespace

// Each coefficient function promises a few ulps: a handful of correctly
// rounded operations (<= 0.5 ulp each) on quantities without cancellation,
// or a Horner sum whose terms shrink geometrically. 4 epsilon covers that;
// the naive formulas miss it by up to 1e8 in the band tested.
TEMPLATE_TEST_CASE("coefficient functions are accurate over the whole range", "[accuracy]", float,
                   double) {
  using Scalar = TestType;
  namespace sa = bireg::small_angle;
  const long double tolerance = 4 * eps<Scalar>();
  for (long double x_ld : dense_grid()) {
    const Scalar x = static_cast<Scalar>(x_ld);
    const long double xl = x;  // the exact input the library sees
    CAPTURE(xl);
    const long double sinc_ref = xl == 0 ? 1.0L : std::sin(xl) / xl;
    const long double half_sinc = xl == 0 ? 1.0L : std::sin(xl / 2) / (xl / 2);
    REQUIRE(relative<Scalar>(sa::sin_over_x(x), sinc_ref) <= tolerance);
    REQUIRE(relative<Scalar>(sa::one_minus_cos_over_x2(x), half_sinc * half_sinc / 2) <= tolerance);
    REQUIRE(relative<Scalar>(sa::x_minus_sin_over_x3(x), reference_x_minus_sin_over_x3(xl)) <=
            tolerance);
    REQUIRE(relative<Scalar>(sa::one_minus_half_x_cot_half_x_over_x2(x),
                             reference_one_minus_half_cot_over_x2(xl)) <= tolerance);
    const long double half_cot_ref =
        xl == 0 ? 1.0L : (xl / 2) * std::cos(xl / 2) / std::sin(xl / 2);
    REQUIRE(relative<Scalar>(sa::half_x_cot_half_x(x), half_cot_ref) <= tolerance);
    // The forms taking x^2 (SO(3)'s Jacobians), against the references at
    // the square root of the rounded square they see.
    const Scalar x2 = x * x;
    const long double root = std::sqrt(static_cast<long double>(x2));
    const long double half_root_sinc = root == 0 ? 1.0L : std::sin(root / 2) / (root / 2);
    REQUIRE(relative<Scalar>(sa::one_minus_cos_over_x2_from_square(x2),
                             half_root_sinc * half_root_sinc / 2) <= tolerance);
    REQUIRE(relative<Scalar>(sa::x_minus_sin_over_x3_from_square(x2),
                             reference_x_minus_sin_over_x3(root)) <= tolerance);
  }
}

// SO(3) exp and log at the edge angles, 16 random axes each.
// exp: each entry of Rodrigues' formula is a sum of three products whose
// coefficients carry <= 2 ulps; near pi the W^2 term reaches 2 in magnitude
// and cancels against the identity, so the entry's absolute error is up to
// ~3 x 2 ulps of 1: 8 epsilon relative to the largest entry (1) bounds it. log: near pi the
// quaternion's small component w is recovered from an O(1) off-diagonal difference with absolute
// error ~eps, and theta = 2 atan2(|v|, w) inherits that absolute error, i.e. eps/pi relative; near
// 0 the vector part is read off the off-diagonals, which carry the relative precision. 4 epsilon
// relative bounds both, beside the ~1e-8 relative error of the acos-based formula at pi - 1e-14.
TEMPLATE_TEST_CASE("SO3 exp and log keep full precision at 0 and pi", "[accuracy]", float, double) {
  using Scalar = TestType;
  using G = bireg::SO3<Scalar>;
  const long double exp_tolerance = 8 * eps<Scalar>();
  const long double log_tolerance = 4 * eps<Scalar>();
  std::mt19937 rng(11);
  std::map<double, long double> worst_exp, worst_log;
  for (double angle : edge_angles(/*include_beyond_pi=*/true)) {
    for (int trial = 0; trial < 16; ++trial) {
      const Eigen::Matrix<long double, 3, 1> axis = bireg_test::random_unit<3>(rng);
      const typename G::Tangent omega =
          (static_cast<long double>(angle) * axis).template cast<Scalar>();
      const Eigen::Matrix<long double, 3, 1> omega_ld = omega.template cast<long double>();
      const long double theta = omega_ld.norm();
      const Eigen::Matrix<long double, 3, 1> unit =
          theta > 0 ? Eigen::Matrix<long double, 3, 1>(omega_ld / theta) : axis;
      const Eigen::Matrix<long double, 3, 3> r_ref = bireg_test::reference_rotation(theta, unit);
      CAPTURE(angle, trial);

      const long double exp_error = relative_error(G::exp(omega), r_ref);
      worst_exp[angle] = std::max(worst_exp[angle], exp_error);
      REQUIRE(exp_error <= exp_tolerance);

      // The principal log of the rounded reference matrix: theta beyond pi
      // wraps to -(2 pi - theta); within a few ulps of pi either sign is a
      // valid logarithm of the rounded matrix.
      const typename G::Element r = r_ref.template cast<Scalar>();
      const Eigen::Matrix<long double, 3, 1> log_ref =
          theta > kPi ? Eigen::Matrix<long double, 3, 1>(omega_ld * (1 - 2 * kPi / theta))
                      : omega_ld;
      const typename G::Tangent log = G::log(r);
      long double log_error = relative_error(log, log_ref);
      if (std::abs(theta - kPi) < 8 * eps<Scalar>()) {
        const Eigen::Matrix<long double, 3, 1> other = log_ref * (1 - 2 * kPi / log_ref.norm());
        log_error = std::min(log_error, relative_error(log, other));
      }
      if (theta > 0) {
        worst_log[angle] = std::max(worst_log[angle], log_error);
        REQUIRE(log_error <= log_tolerance);
      } else {
        REQUIRE(log.isZero(0));
      }
    }
  }
  report(sizeof(Scalar) == 4 ? "SO3 exp, float" : "SO3 exp, double", worst_exp, eps<Scalar>());
  report(sizeof(Scalar) == 4 ? "SO3 log, float" : "SO3 log, double", worst_log, eps<Scalar>());
}

// SE(3) and SE(2) exp and log in the small-angle band and near pi, with a
// translation part of norm ~1, against the long double matrix exponential.
// Beyond the rotation part, t = V rho adds two products with coefficients
// accurate to a few ulps (the coefficient test above); rho = V^{-1} t
// likewise. 8 epsilon relative to the largest entry bounds both; libraries
// that evaluate (th - sin th)/th^3 directly miss it by 1e8 at th = 1e-4.
template <class G>
void check_rigid_motion_accuracy(const char* label) {
  using Scalar = typename G::Scalar;
  constexpr int n = G::matrix_size;
  const long double tolerance = 8 * eps<Scalar>();
  std::mt19937 rng(12);
  std::map<double, long double> worst_exp, worst_log;
  for (double angle : edge_angles(/*include_beyond_pi=*/false)) {
    for (int trial = 0; trial < 16; ++trial) {
      typename G::Tangent xi = bireg_test::random_tangent<typename G::Tangent>(rng, 1.0);
      // Rotation part of norm `angle`: the last dof - (n - 1) coordinates.
      constexpr int rotation_dof = G::dof - (n - 1);
      const Eigen::Matrix<long double, rotation_dof, 1> axis =
          bireg_test::random_unit<rotation_dof>(rng);
      xi.template tail<rotation_dof>() =
          (static_cast<long double>(angle) * axis).template cast<Scalar>();
      CAPTURE(angle, trial);

      const Eigen::Matrix<long double, n, n> hat_ld = G::hat(xi).template cast<long double>();
      const Eigen::Matrix<long double, n, n> g_ref = bireg_test::reference_expm<n>(hat_ld);
      const long double exp_error = relative_error(G::exp(xi), g_ref);
      worst_exp[angle] = std::max(worst_exp[angle], exp_error);
      REQUIRE(exp_error <= tolerance);

      // Within a few ulps of pi the rounded input may lie beyond pi (float's
      // pi does), where the principal log is the other branch: there the
      // round trip exp(log(g)) = g is what log promises.
      const typename G::Element g = g_ref.template cast<Scalar>();
      const long double rotation_angle =
          xi.template tail<rotation_dof>().template cast<long double>().norm();
      if (rotation_angle < kPi - 8 * eps<Scalar>()) {
        const long double log_error = relative_error(G::log(g), xi);
        worst_log[angle] = std::max(worst_log[angle], log_error);
        REQUIRE(log_error <= tolerance);
      } else {
        REQUIRE(relative_error(G::exp(G::log(g)), g_ref) <= tolerance);
      }
    }
  }
  report((std::string(label) + " exp").c_str(), worst_exp, eps<Scalar>());
  report((std::string(label) + " log").c_str(), worst_log, eps<Scalar>());
}

TEST_CASE("SE3 exp and log keep full precision at 0 and pi", "[accuracy]") {
  check_rigid_motion_accuracy<bireg::SE3<double>>("SE3, double");
  check_rigid_motion_accuracy<bireg::SE3<float>>("SE3, float");
}

TEST_CASE("SE2 exp and log keep full precision at 0 and pi", "[accuracy]") {
  check_rigid_motion_accuracy<bireg::SE2<double>>("SE2, double");
  check_rigid_motion_accuracy<bireg::SE2<float>>("SE2, float");
}
