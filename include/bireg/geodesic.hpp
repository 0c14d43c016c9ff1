// bireg: geodesics of the Cartan–Schouten connection (paper, Section 2.1).
//
//   Exp_g(u) = g exp(u),   Log_g(f) = log(g^{-1} f),
//   gamma(s; g0, g1) = g0 exp(s log(g0^{-1} g1)),
//
// with tangent vectors at g represented by their left translates g^{-1} u
// in the Lie algebra (DESIGN.md section 2). These geodesics are translated
// one-parameter subgroups: left or right translating g0 and g1 translates
// the whole curve, which is what makes the regression bi-invariant.
#pragma once

#include "bireg/concept.hpp"

namespace bireg {

// The paper's Exp_g(u) for a left-trivialised tangent vector u at g.
template <class G>
typename G::Element exp_at(const typename G::Element& g, const typename G::Tangent& u) {
  return G::compose(g, G::exp(u));
}

// The paper's Log_g(f), left-trivialised: the u with exp_at(g, u) = f
// (principal branch).
template <class G>
typename G::Tangent log_at(const typename G::Element& g, const typename G::Element& f) {
  return G::log(G::compose(G::inverse(g), f));
}

// gamma(s; g0, g1) for s in [0, 1] (and beyond, by extension).
template <class G>
typename G::Element geodesic_point(const typename G::Element& g0, const typename G::Element& g1,
                                   typename G::Scalar s) {
  return exp_at<G>(g0, s * log_at<G>(g0, g1));
}

// A geodesic parametrised in the user's covariate units: gamma(t_min) = g0,
// gamma(t_max) = g1. Evaluation at t maps s = (t - t_min)/(t_max - t_min)
// and returns g0 exp(s X), X = log(g0^{-1} g1); any t is allowed
// (extrapolation follows the one-parameter subgroup).
template <class G>
class Geodesic {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;

  // The constant geodesic at the identity over [0, 1].
  Geodesic() : Geodesic(G::identity(), G::identity()) {}

  // Precondition: t_max > t_min (the regression guarantees it).
  Geodesic(const Element& g0, const Element& g1, Scalar t_min = Scalar(0), Scalar t_max = Scalar(1))
      : g0_(g0), g1_(g1), log_(log_at<G>(g0, g1)), t_min_(t_min), t_max_(t_max) {}

  const Element& start() const { return g0_; }  // gamma(t_min)
  const Element& end() const { return g1_; }    // gamma(t_max)
  Scalar t_min() const { return t_min_; }
  Scalar t_max() const { return t_max_; }

  // X = log(g0^{-1} g1): the displacement over the whole range.
  const Tangent& displacement() const { return log_; }

  // The covariate mapped onto the unit interval.
  Scalar normalized(Scalar t) const { return (t - t_min_) / (t_max_ - t_min_); }

  Element operator()(Scalar t) const { return exp_at<G>(g0_, normalized(t) * log_); }

  // Body (left-trivialised) velocity gamma(t)^{-1} dgamma/dt, per covariate
  // unit. Constant along the curve: X / (t_max - t_min).
  Tangent body_velocity() const { return log_ / (t_max_ - t_min_); }

  // Spatial (right-trivialised) velocity dgamma/dt gamma(t)^{-1} = Ad_gamma(t)
  // of the body velocity.
  Tangent spatial_velocity(Scalar t) const { return G::Ad((*this)(t)) * body_velocity(); }

 private:
  Element g0_;
  Element g1_;
  Tangent log_;
  Scalar t_min_;
  Scalar t_max_;
};

}  // namespace bireg
