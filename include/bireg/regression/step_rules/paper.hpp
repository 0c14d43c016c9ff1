// bireg: the paper's step (Section 2.2): (d0, d1) = lambda (v0, v1).
//
// Its linear part is I - lambda (H kron I) (Lemma 3.7), which contracts iff
// 0 < lambda < 2/mu_max; the paper analyses lambda <= 1/mu_max, where the
// error shrinks by (1 - lambda eta) per iteration, eta -> mu_min as the
// data concentrate (Theorem 4.8). No safeguard: this is the iteration the
// theorem is about.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

template <class G>
class PaperStep {
 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  static constexpr bool safeguarded = false;

  // requested_step_size: lambda, or 0 for the paper's 1/mu_max.
  static std::optional<Rejection> refuse(const Problem<Scalar>& problem,
                                         Scalar requested_step_size) {
    const Scalar lambda = choose(problem, requested_step_size);
    const Scalar limit = 2 / problem.mu_max;
    if (!(lambda < limit)) {
      return Rejection{"step_size " + std::to_string(double(lambda)) +
                       " is at or above 2/mu_max = " + std::to_string(double(limit)) +
                       ": the linear part of the iteration no longer contracts"};
    }
    return std::nullopt;
  }

  PaperStep(const Problem<Scalar>& problem, Scalar requested_step_size)
      : lambda_(choose(problem, requested_step_size)), mu_max_(problem.mu_max) {}

  Scalar step_size() const { return lambda_; }

  std::pair<Tangent, Tangent> operator()(const State<G>& state) const {
    return {lambda_ * state.force.v0, lambda_ * state.force.v1};
  }

  // Convergence is judged on ||v|| / mu_max, the step of the paper's own
  // lambda = 1/mu_max, whatever lambda is used: a tiny lambda makes the
  // step small without making the force small.
  Scalar convergence_norm(Scalar, const State<G>& state) const {
    return state.force.norm() / mu_max_;
  }

 private:
  static Scalar choose(const Problem<Scalar>& problem, Scalar requested_step_size) {
    return requested_step_size > 0 ? requested_step_size : 1 / problem.mu_max;
  }

  Scalar lambda_;
  Scalar mu_max_;
};

}  // namespace bireg
