// bireg: the step H^{-1} (v0, v1), carried across the geodesic so that it
// stays equivariant (DESIGN.md section 2, "Preconditioning").
//
// H^{-1} mixes v0 (left-trivialised at g0) with v1 (at g1). Mixed as they
// are, the step would keep left and right equivariance but not inverse
// equivariance: inversion maps v0 -> -Ad_g0 v0 and v1 -> -Ad_g1 v1, two
// different frames. Carrying each across by half the geodesic,
// T = Ad_exp(X/2), restores it (T transforms as Ad_g0 T Ad_g1^{-1} under
// inversion), and it is also the first-order term of Gauss-Newton's
// coupling, K01 = b (I + A/2) + O(A^2). The linear part cancels (lambda = 1).
#pragma once

#include <optional>
#include <utility>

#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

template <class G>
class PreconditionedStep {
 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  static constexpr bool safeguarded = true;

  static std::optional<Rejection> refuse(const Problem<Scalar>&, Scalar) { return std::nullopt; }

  PreconditionedStep(const Problem<Scalar>& problem, Scalar)
      : a_(problem.a), b_(problem.b), c_(problem.c) {}

  Scalar step_size() const { return 1; }

  std::pair<Tangent, Tangent> operator()(const State<G>& state) const {
    const Tangent& v0 = state.force.v0;
    const Tangent& v1 = state.force.v1;
    const Scalar determinant = a_ * c_ - b_ * b_;
    const AdMatrix forward = G::Ad(G::exp(state.x / 2));    // from g1's frame to g0's
    const AdMatrix backward = G::Ad(G::exp(-state.x / 2));  // from g0's frame to g1's
    return {(c_ * v0 - b_ * (forward * v1)) / determinant,
            (a_ * v1 - b_ * (backward * v0)) / determinant};
  }

  Scalar convergence_norm(Scalar step_norm, const State<G>&) const { return step_norm; }

 private:
  Scalar a_, b_, c_;
};

}  // namespace bireg
