// The series inverse differentials (paper, Lemma 3.1 and Corollary
// "diff_1_gam", in DESIGN.md's weighted form psi_s) against finite
// differences of the geodesic's endpoint derivatives.
//
// Both sides are compared through the identities
//   psi_s(A)      (d_1 gamma_s) = s^2 I,
//   psi_{1-s}(-A) (d_0 gamma_s) = (1 - s)^2 I,
// which hold for every s in [0, 1], including s = 0 and s = 1 where one of
// the derivatives is not invertible.
#include <cmath>
#include <random>

#include "bireg/geodesic.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/math/psi_series.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

// psi_s(A) as a matrix, from the series truncated at `order`.
template <int D>
Eigen::Matrix<long double, D, D> psi_matrix(const Eigen::Matrix<long double, D, D>& a,
                                            long double s, int order) {
  Eigen::Matrix<long double, D, D> result = Eigen::Matrix<long double, D, D>::Zero();
  for (int k = 0; k < D; ++k) {
    const Eigen::Matrix<long double, D, 1> e = Eigen::Matrix<long double, D, 1>::Unit(k);
    result.col(k) = bireg::apply_psi_series<long double, D>(a, s, e, order);
  }
  return result;
}

// Left-trivialised derivative of gamma_s with respect to the start (which = 0)
// or end point (which = 1), by the five-point central difference in long
// double: column k is d/dh log(gamma_s^{-1} gamma_s(.. g exp(h e_k) ..)) at 0.
// Error: h^4/30 |f^(5)| ~ 1e-17 for h = 1e-4 and the O(1) derivatives here,
// plus rounding ~ eps_ld / h ~ 1e-15.
template <class G>
typename G::AdMatrix endpoint_derivative(const typename G::Element& g0,
                                         const typename G::Element& g1, long double s, int which) {
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  constexpr long double h = 1e-4L;
  const Element base = bireg::geodesic_point<G>(g0, g1, s);
  const Element base_inverse = G::inverse(base);
  typename G::AdMatrix derivative;
  for (int k = 0; k < G::dof; ++k) {
    const auto moved = [&](long double step) {
      const Tangent delta = step * Tangent::Unit(k);
      const Element a = which == 0 ? bireg::exp_at<G>(g0, delta) : g0;
      const Element b = which == 1 ? bireg::exp_at<G>(g1, delta) : g1;
      return G::log(G::compose(base_inverse, bireg::geodesic_point<G>(a, b, s)));
    };
    derivative.col(k) = (8 * (moved(h) - moved(-h)) - (moved(2 * h) - moved(-2 * h))) / (12 * h);
  }
  return derivative;
}

template <class G>
void check_against_finite_differences(const typename G::Tangent& x_start,
                                      const typename G::Tangent& x) {
  using Matrix = typename G::AdMatrix;
  const typename G::Element g0 = G::exp(x_start);
  const typename G::Element g1 = bireg::exp_at<G>(g0, x);
  const Matrix a = G::ad(x);
  // Series truncated at 64 terms: for rho(A) <= 2.5 the omitted terms are
  // below (2.5 / 2 pi)^64 ~ 1e-26.
  constexpr int kOrder = bireg::kMaxSeriesOrder;
  // The finite differences carry ~1e-15 (see endpoint_derivative); the
  // products below add a few ulps of long double. 1e-13 leaves a margin of
  // 100 over the finite-difference error and is 11 orders below the O(|X|)
  // discrepancy a left/right mix-up in the trivialisation produces.
  constexpr long double kTolerance = 1e-13L;
  for (long double s : {0.0L, 0.3L, 0.5L, 0.9L, 1.0L}) {
    CAPTURE(static_cast<double>(s));
    const Matrix d1 = endpoint_derivative<G>(g0, g1, s, 1);
    const Matrix d0 = endpoint_derivative<G>(g0, g1, s, 0);
    const Matrix end_check = psi_matrix<G::dof>(a, s, kOrder) * d1 - s * s * Matrix::Identity();
    const Matrix start_check =
        psi_matrix<G::dof>(-a, 1 - s, kOrder) * d0 - (1 - s) * (1 - s) * Matrix::Identity();
    REQUIRE(end_check.cwiseAbs().maxCoeff() <= kTolerance);
    REQUIRE(start_check.cwiseAbs().maxCoeff() <= kTolerance);
  }
}

}  // namespace

TEST_CASE("series inverse differentials match finite differences on SO3", "[series]") {
  using G = bireg::SO3<long double>;
  check_against_finite_differences<G>(G::Tangent(0.3L, -1.2L, 0.8L), G::Tangent(1.1L, 0.4L, -1.6L));
  check_against_finite_differences<G>(G::Tangent(2.0L, 0.1L, 0.2L),
                                      G::Tangent(-0.05L, 0.02L, 0.01L));
}

TEST_CASE("series inverse differentials match finite differences on SE3", "[series]") {
  using G = bireg::SE3<long double>;
  G::Tangent start, x;
  start << 1.0L, -2.0L, 0.5L, 0.3L, -1.2L, 0.8L;
  x << 0.7L, 1.5L, -0.4L, 1.1L, 0.4L, -1.6L;
  check_against_finite_differences<G>(start, x);
}

TEST_CASE("series inverse differentials match finite differences on SE2", "[series]") {
  using G = bireg::SE2<long double>;
  check_against_finite_differences<G>(G::Tangent(0.4L, -1.0L, 2.5L), G::Tangent(1.2L, 0.3L, -2.2L));
}

// psi_s has its poles nearest the origin at z = +-2 pi i / s (unless s = 1/n,
// where the numerator 1 - e^{-z} cancels every pole and psi_s is entire:
// psi_{1/2}(z) = (1 + e^{-z/2}) / 4), and ad_X on SO(3) has eigenvalues
// +-i theta, so the truncation error of the order-M series decays like
// (s theta / 2 pi)^M once M is past the transient of the entire factor
// 1 - e^{-z}, whose terms shrink like theta / M (below the pole's rate for
// M >= 10 at the s tested). Simple poles give a purely geometric tail, so
// the rate fitted over M = 10..22 must match the prediction to within 2%
// (the remaining poles, at least twice as far, perturb it by < 2^-10).
TEST_CASE("the series converges at the rate the spectral radius predicts", "[series]") {
  using G = bireg::SO3<long double>;
  constexpr long double kPi = 3.141592653589793238462643383279502884L;
  const G::Tangent x(1.5L, -1.5L, 1.0L);  // theta = 2.345
  const long double theta = x.norm();
  const G::AdMatrix a = G::ad(x);
  const G::Tangent r(0.3L, 0.5L, -0.2L);
  for (long double s : {0.7L, 0.9L}) {
    const G::Tangent converged =
        bireg::apply_psi_series<long double, 3>(a, s, r, bireg::kMaxSeriesOrder);
    const auto error = [&](int order) {
      return (bireg::apply_psi_series<long double, 3>(a, s, r, order) - converged).norm();
    };
    const long double measured = std::pow(error(22) / error(10), 1.0L / 12);
    const long double predicted = s * theta / (2 * kPi);
    CAPTURE(static_cast<double>(s), static_cast<double>(measured), static_cast<double>(predicted));
    REQUIRE(std::abs(measured / predicted - 1) <= 0.02L);
  }
}

TEST_CASE("psi is regular at s = 0 and s = 1", "[series]") {
  using G = bireg::SO3<double>;
  const G::Tangent x(0.4, -2.0, 1.0);
  const G::AdMatrix a = G::ad(x);
  const G::Tangent r(1.0, 2.0, 3.0);
  // psi_1 = 1 identically: every coefficient beyond the first cancels
  // exactly in the table (a sum of b_k / (m - k + 1)! that vanishes), up to
  // the rounding of its long double entries.
  REQUIRE((bireg::apply_psi_series<double, 3>(a, 1.0, r, 40) - r).norm() <= 1e-15 * r.norm());
  // At s -> 0, psi_s(z) = s^2 (1 - e^{-z})/(1 - e^{-sz}) = s J_r(z) (1 + O(s z)):
  // the series divided by s tends to the right Jacobian (SO3's closed form,
  // no series), with an error of first order in s |x| (2.3e-8 at s = 1e-8).
  for (double s : {1e-8, 1e-4}) {
    const G::Tangent limit = G::right_jacobian(x) * r;
    const G::Tangent scaled = bireg::apply_psi_series<double, 3>(a, s, r, 40) / s;
    CAPTURE(s);
    REQUIRE((scaled - limit).norm() <= 2 * s * x.norm() * limit.norm() + 1e-14);
    REQUIRE((scaled - limit).norm() >= 1e-3 * s * limit.norm());  // the O(s) term is there
  }
}
