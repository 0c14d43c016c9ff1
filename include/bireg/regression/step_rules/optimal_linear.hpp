// bireg: the paper's step with lambda = 2/(mu_min + mu_max), the step size
// that minimises max |1 - lambda mu| over the eigenvalues of H (Lemma 3.7),
// i.e. the fastest linear contraction, (mu_max - mu_min)/(mu_max + mu_min).
// It lies beyond the paper's lambda <= 1/mu_max, so it carries the
// safeguard (a step that would increase ||v|| is halved).
#pragma once

#include <optional>
#include <utility>

#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

template <class G>
class OptimalLinearStep {
 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  static constexpr bool safeguarded = true;

  static std::optional<Rejection> refuse(const Problem<Scalar>&, Scalar) { return std::nullopt; }

  OptimalLinearStep(const Problem<Scalar>& problem, Scalar)
      : lambda_(2 / (problem.mu_min + problem.mu_max)) {}

  Scalar step_size() const { return lambda_; }

  std::pair<Tangent, Tangent> operator()(const State<G>& state) const {
    return {lambda_ * state.force.v0, lambda_ * state.force.v1};
  }

  Scalar convergence_norm(Scalar step_norm, const State<G>&) const { return step_norm; }

 private:
  Scalar lambda_;
};

}  // namespace bireg
