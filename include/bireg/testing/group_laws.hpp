// bireg: the laws every group must satisfy, measured on random samples, for
// bireg's own tests and for users who write a group of their own:
//
//   const auto errors = bireg::testing::group_law_errors<MyGroup>(rng, 200, 1.0);
//   assert(errors.worst() <= 1e-12);
//
// Each field is the largest error over the samples, relative to the size of
// the quantity compared (or absolute where that quantity can vanish). The
// references share no code with the group: products and inverses of its
// matrices, a long double matrix exponential of ad (scaling and squaring a
// Taylor series), central finite differences. Framework-free: it returns
// numbers and asserts nothing, so any test framework can use it.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "bireg/concept.hpp"

namespace bireg {
namespace testing {

// Largest absolute entry of a - b over the largest absolute entry of b (or
// the difference itself when b vanishes).
template <class A, class B>
long double relative_difference(const A& a, const B& b) {
  const long double difference =
      (a.template cast<long double>() - b.template cast<long double>()).cwiseAbs().maxCoeff();
  const long double scale = b.template cast<long double>().cwiseAbs().maxCoeff();
  return scale > 0 ? difference / scale : difference;
}

// exp(a) in long double by scaling to norm <= 1/2 and summing 40 Taylor
// terms (~1e-18 relative at moderate norms).
template <int D>
Eigen::Matrix<long double, D, D> reference_expm(const Eigen::Matrix<long double, D, D>& a) {
  using Matrix = Eigen::Matrix<long double, D, D>;
  const long double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  while (std::ldexp(norm, -squarings) > 0.5L && squarings < 200)
    ++squarings;
  const Matrix scaled = a * std::ldexp(1.0L, -squarings);
  Matrix sum = Matrix::Identity(), term = Matrix::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * scaled / static_cast<long double>(k);
    sum += term;
  }
  for (int i = 0; i < squarings; ++i)
    sum = sum * sum;
  return sum;
}

template <class Tangent>
Tangent random_tangent(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Tangent x;
  for (int i = 0; i < x.size(); ++i)
    x[i] = static_cast<typename Tangent::Scalar>(uniform(rng));
  return x;
}

struct GroupLawErrors {
  long double log_of_exp = 0;        // log(exp x) = x
  long double exp_of_log = 0;        // exp(log g) = g
  long double inverse = 0;           // g g^{-1} = e
  long double associativity = 0;     // (a b) c = a (b c)
  long double ad_antisymmetry = 0;   // ad_x y = -ad_y x
  long double ad_exp = 0;            // Ad(exp x) = exp(ad x)
  long double ad_homomorphism = 0;   // Ad(a b) = Ad(a) Ad(b)
  long double ad_conjugation = 0;    // exp(Ad_g x) = g exp(x) g^{-1}
  long double jacobian = 0;          // J_r(x) by central differences of exp
  long double jacobian_inverse = 0;  // J_r(x) J_r(x)^{-1} = I
  long double jacobian_pair = 0;     // right_jacobian_pair = (J_r, J_r^{-1}) computed apart
  long double psi = 0;               // psi_s(ad x) r = s J_r(x) J_r(s x)^{-1} r

  long double worst() const {
    return std::max({log_of_exp, exp_of_log, inverse, associativity, ad_antisymmetry, ad_exp,
                     ad_homomorphism, ad_conjugation, jacobian, jacobian_inverse, jacobian_pair,
                     psi});
  }
};

// Measures the laws on `samples` random tangent vectors with entries
// uniform in [-scale, scale] (keep the angles below pi, e.g. scale <= 1.5:
// the principal log inverts exp only there). Finite differences use the
// step h = cbrt(epsilon) |x|-scaled, whose error is O(h^2) ~ epsilon^(2/3):
// the jacobian field is therefore ~1e-10 in double even for a correct J_r.
template <class G>
GroupLawErrors group_law_errors(std::mt19937& rng, int samples, double scale) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  constexpr int d = G::dof;
  const auto distance = [](const Element& a, const Element& b) {
    return static_cast<long double>(G::log(G::compose(G::inverse(b), a)).norm());
  };
  const auto worse = [](long double& field, long double value) {
    using std::isnan;
    field = isnan(value) ? value : std::max(field, value);
  };
  GroupLawErrors e;
  for (int i = 0; i < samples; ++i) {
    const Tangent x = random_tangent<Tangent>(rng, scale);
    const Tangent y = random_tangent<Tangent>(rng, scale);
    const Tangent r = random_tangent<Tangent>(rng, 1.0);
    const Element a = G::exp(x), b = G::exp(y), c = G::exp(random_tangent<Tangent>(rng, scale));
    worse(e.log_of_exp, relative_difference(G::log(a), x));
    worse(e.exp_of_log, distance(G::exp(G::log(b)), b));
    worse(e.inverse, distance(G::compose(a, G::inverse(a)), G::identity()));
    worse(e.associativity,
          distance(G::compose(G::compose(a, b), c), G::compose(a, G::compose(b, c))));
    worse(e.ad_antisymmetry, relative_difference(Tangent(G::ad(x) * y), Tangent(-(G::ad(y) * x))));
    const Eigen::Matrix<long double, d, d> ad = G::ad(x).template cast<long double>();
    worse(e.ad_exp, relative_difference(G::Ad(a), reference_expm<d>(ad)));
    worse(e.ad_homomorphism,
          relative_difference(G::Ad(G::compose(a, b)), AdMatrix(G::Ad(a) * G::Ad(b))));
    worse(e.ad_conjugation,
          distance(G::exp(Tangent(G::Ad(a) * y)), G::compose(G::compose(a, b), G::inverse(a))));

    // J_r(x) dx = log(exp(x)^{-1} exp(x + dx)) + O(dx^2): column k by central
    // differences along e_k.
    const AdMatrix jacobian = right_jacobian<G>(x);
    const Scalar h = std::cbrt(std::numeric_limits<Scalar>::epsilon()) *
                     std::max(Scalar(1), Scalar(x.cwiseAbs().maxCoeff()));
    AdMatrix differences;
    for (int k = 0; k < d; ++k) {
      Tangent step = Tangent::Zero();
      step[k] = h;
      const Tangent forward = G::log(G::compose(G::inverse(a), G::exp(Tangent(x + step))));
      const Tangent backward = G::log(G::compose(G::inverse(a), G::exp(Tangent(x - step))));
      differences.col(k) = (forward - backward) / (2 * h);
    }
    worse(e.jacobian, relative_difference(differences, jacobian));
    worse(e.jacobian_inverse, relative_difference(AdMatrix(jacobian * right_jacobian_inverse<G>(x)),
                                                  AdMatrix(AdMatrix::Identity())));
    const RightJacobianPair<AdMatrix> pair = right_jacobian_pair<G>(x);
    worse(e.jacobian_pair,
          std::max(relative_difference(pair.jacobian, jacobian),
                   relative_difference(pair.inverse, right_jacobian_inverse<G>(x))));
    for (const Scalar s : {Scalar(0.25), Scalar(0.5), Scalar(0.9)}) {
      const Tangent closed = apply_psi<G>(x, s, r);
      const Tangent through_jacobians =
          s * (jacobian * (right_jacobian_inverse<G>(Tangent(s * x)) * r));
      worse(e.psi, relative_difference(closed, through_jacobians));
    }
  }
  return e;
}

}  // namespace testing
}  // namespace bireg
