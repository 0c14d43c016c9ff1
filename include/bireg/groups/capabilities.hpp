// bireg: optional capabilities of a group, found by one detection mechanism.
//
// Beyond what concept.hpp requires, a group may provide any of these static
// members in its own header; each has a generic fallback here, so a group
// that provides none still works everywhere:
//
//   Scalar ad_spectral_radius(const Tangent& x)     spectral radius of ad_x
//       fallback: MatrixGroup's ad_spectral_radius_from_matrix where its
//       basis allows (GL(N), SL(N), Heisenberg; N <= 3), else the
//       eigenvalues of the dof x dof matrix ad_x (fixed size).
//   AdMatrix right_jacobian(const Tangent& x)        J_r(x) = (1 - e^{-ad_x}) / ad_x
//   AdMatrix right_jacobian_inverse(const Tangent& x)
//       fallback: the power series in ad_x (J_r is entire; J_r^{-1} =
//       sum_k b_k (-ad_x)^k, b_k = B_k/k!, converges for spectral radius
//       below 2 pi), truncated where the terms fall below epsilon.
//   RightJacobianPair<AdMatrix> right_jacobian_pair(const Tangent& x)
//       J_r(x) and J_r(x)^{-1} together, sharing their common factors (the
//       covariance needs both at every observation).
//       fallback: right_jacobian(x) and right_jacobian_inverse(x).
//   AdAlgebraBasis<AdMatrix> ad_algebra_basis(const Tangent& x)
//       the algebra of analytic functions of ad_x in five numbers
//       (math/ad_algebra.hpp; SO(3) and SE(3)): the covariance sums its
//       per-observation Jacobians there. fallback: d x d matrices per
//       observation (statistics/inference/covariance.hpp).
//   struct ClosedFormPsi                             psi_s(ad_x) r in closed form
//       (see math/psi_closed_form.hpp and SO3::ClosedFormPsi for the
//       interface; with kTerms, coefficients and combine where it is a sum
//       of scalar coefficients times fixed maps, which the force then sums
//       per coefficient, and exp(prepared, t, t_half) where exp(t x) can
//       reuse the force's half-angle sin and cos) fallback: the power series
//       of math/psi_series.hpp.
//
//   Scalar turn_angle(const Element& g)             angle of g's rotation, in [0, pi]
//       invariant under conjugation g -> h g h^{-1}, so a bound on the
//       turn between two observations, turn_angle(f_a^{-1} f_b), is left
//       and right invariant; the principal log is defined while it is below
//       pi. Local regression caps its windows in it
//       (statistics/smoothing/local_window.hpp). fallback: none (has_turn_angle_v
//       is false and windows are not capped); SO(2), SE(2), SO(3), SE(3)
//       and Sim(3) provide it.
//
// J_r is the right Jacobian of exp: exp(x + dx) = exp(x) exp(J_r(x) dx +
// O(dx^2)), with left-trivialised perturbations as everywhere in bireg.
// Adding a group with a closed form therefore touches that group's header
// and nothing else.
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "bireg/math/bernoulli.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/psi_series.hpp"

namespace bireg {

namespace capability_detail {
template <class G, template <class> class Capability, class = void>
struct detect : std::false_type {};
template <class G, template <class> class Capability>
struct detect<G, Capability, std::void_t<Capability<G>>> : std::true_type {};

template <class G>
using Tangent = typename G::Tangent;

template <class G>
using ad_spectral_radius = decltype(G::ad_spectral_radius(std::declval<const Tangent<G>&>()));
template <class G>
using ad_spectral_radius_from_matrix =
    decltype(G::ad_spectral_radius_from_matrix(std::declval<const Tangent<G>&>()));
template <class G>
using right_jacobian = decltype(G::right_jacobian(std::declval<const Tangent<G>&>()));
template <class G>
using right_jacobian_inverse =
    decltype(G::right_jacobian_inverse(std::declval<const Tangent<G>&>()));
template <class G>
using right_jacobian_pair = decltype(G::right_jacobian_pair(std::declval<const Tangent<G>&>()));
template <class G>
using ad_algebra_basis = decltype(G::ad_algebra_basis(std::declval<const Tangent<G>&>()));
template <class G>
using closed_form_psi = typename G::ClosedFormPsi;
template <class G>
using turn_angle = decltype(G::turn_angle(std::declval<const typename G::Element&>()));
template <class Psi>
using closed_form_min_angle = decltype(Psi::kMinAngle);
template <class Psi>
using closed_form_terms = decltype(Psi::kTerms);
template <class Psi>
using closed_form_exp = decltype(Psi::exp(std::declval<const typename Psi::Prepared&>(), 0.0,
                                          std::declval<const typename Psi::SinCos&>()));
}  // namespace capability_detail

// J_r(x) and its inverse at one x.
template <class AdMatrix>
struct RightJacobianPair {
  AdMatrix jacobian;  // J_r(x)
  AdMatrix inverse;   // J_r(x)^{-1}
};

// provides_v<G, capability_detail::X>: whether G declares capability X.
template <class G, template <class> class Capability>
inline constexpr bool provides_v = capability_detail::detect<G, Capability>::value;

template <class G>
inline constexpr bool has_closed_form_psi_v = provides_v<G, capability_detail::closed_form_psi>;

template <class G>
inline constexpr bool has_turn_angle_v = provides_v<G, capability_detail::turn_angle>;

// Spectral radius of ad_x.
template <class G>
typename G::Scalar ad_spectral_radius(const typename G::Tangent& x) {
  if constexpr (provides_v<G, capability_detail::ad_spectral_radius>) {
    return G::ad_spectral_radius(x);
  } else if constexpr (provides_v<G, capability_detail::ad_spectral_radius_from_matrix>) {
    return G::ad_spectral_radius_from_matrix(x);  // MatrixGroup's closed form
  } else {
    const typename G::AdMatrix a = G::ad(x);
    Eigen::EigenSolver<typename G::AdMatrix> solver(a, /*computeEigenvectors=*/false);
    return solver.eigenvalues().cwiseAbs().maxCoeff();
  }
}

namespace capability_detail {
// sum_k coefficient(k) (-A)^k, stopped once two consecutive terms are below
// epsilon relative to the identity (odd Bernoulli numbers vanish, so one
// small term alone proves nothing), or after max_terms.
template <class AdMatrix, class Coefficient>
AdMatrix series_in_minus_ad(const AdMatrix& a, Coefficient coefficient, int max_terms) {
  using Scalar = typename AdMatrix::Scalar;
  using std::sqrt;
  const Scalar epsilon = std::numeric_limits<Scalar>::epsilon();
  const AdMatrix minus_a = -a;
  AdMatrix power = AdMatrix::Identity();
  AdMatrix sum = static_cast<Scalar>(coefficient(0)) * power;
  int small_terms = 0;
  for (int k = 1; k < max_terms && small_terms < 2; ++k) {
    power = power * minus_a;
    const AdMatrix term = static_cast<Scalar>(coefficient(k)) * power;
    sum += term;
    small_terms = sqrt(term.squaredNorm()) <= epsilon ? small_terms + 1 : 0;
  }
  return sum;
}
}  // namespace capability_detail

// J_r(x) = sum_k (-ad_x)^k / (k + 1)!.
template <class G>
typename G::AdMatrix right_jacobian(const typename G::Tangent& x) {
  if constexpr (provides_v<G, capability_detail::right_jacobian>) {
    return G::right_jacobian(x);
  } else {
    constexpr int kMaxTerms = 160;  // (k+1)! outgrows ||ad_x||^k long before, for any usable x
    return capability_detail::series_in_minus_ad(
        G::ad(x),
        [](int k) {
          long double inverse_factorial = 1;
          for (int n = 2; n <= k + 1; ++n)
            inverse_factorial /= n;
          return inverse_factorial;
        },
        kMaxTerms);
  }
}

// J_r(x)^{-1} = ad_x / (1 - e^{-ad_x}) = sum_k b_k (-ad_x)^k, for spectral
// radius of ad_x below 2 pi.
template <class G>
typename G::AdMatrix right_jacobian_inverse(const typename G::Tangent& x) {
  if constexpr (provides_v<G, capability_detail::right_jacobian_inverse>) {
    return G::right_jacobian_inverse(x);
  } else {
    return capability_detail::series_in_minus_ad(
        G::ad(x), [](int k) { return kBernoulliOverFactorial[static_cast<std::size_t>(k)]; },
        static_cast<int>(kBernoulliTableSize));
  }
}

// J_r(x) and J_r(x)^{-1}, from the group's shared computation when it has one.
template <class G>
RightJacobianPair<typename G::AdMatrix> right_jacobian_pair(const typename G::Tangent& x) {
  if constexpr (provides_v<G, capability_detail::right_jacobian_pair>) {
    return G::right_jacobian_pair(x);
  } else {
    return {right_jacobian<G>(x), right_jacobian_inverse<G>(x)};
  }
}

// Whether the exact method evaluates psi_s(ad_x) by G's closed form: from
// ClosedFormPsi::angle(x) = kExactMinAngle on, or from the group's own
// ClosedFormPsi::kMinAngle where it declares one (Sim(3), whose closed form
// costs more than the series on short geodesics).
template <class G>
bool uses_closed_form_psi(const typename G::Tangent& x) {
  if constexpr (has_closed_form_psi_v<G>) {
    using Psi = typename G::ClosedFormPsi;
    double min_angle = kExactMinAngle;
    if constexpr (provides_v<Psi, capability_detail::closed_form_min_angle>) {
      min_angle = Psi::kMinAngle;
    }
    return Psi::angle(x) >= static_cast<typename G::Scalar>(min_angle);
  } else {
    return false;
  }
}

// psi_s(ad_x) r as the exact method evaluates it: G's closed form where
// uses_closed_form_psi; elsewhere, and for groups without one, the series
// truncated adaptively below epsilon.
template <class G>
typename G::Tangent apply_psi(const typename G::Tangent& x, typename G::Scalar s,
                              const typename G::Tangent& r) {
  using Scalar = typename G::Scalar;
  if constexpr (has_closed_form_psi_v<G>) {
    using Psi = typename G::ClosedFormPsi;
    if (uses_closed_form_psi<G>(x)) {
      using SinCos = psi_closed_form::SinCos<Scalar>;
      const auto prepared = Psi::prepare(x);
      return Psi::apply(prepared, s, SinCos::of(s * prepared.theta / 2),
                        SinCos::of((1 - s) * prepared.theta / 2), r);
    }
  }
  const typename G::AdMatrix a = G::ad(x);
  const int order =
      adaptive_series_order(a, std::numeric_limits<Scalar>::epsilon(), kMaxSeriesOrder).first;
  return apply_psi_series<Scalar, G::dof>(a, s, r, order);
}

}  // namespace bireg
