// bireg: the step rules, by name. Each is one small type in step_rules/
// (its step, its safeguard policy, what convergence is judged on); all are
// Exp-stepped iterations g0 <- g0 exp(d0), g1 <- g1 exp(d1) with the same
// fixed point v = 0, and all keep left, right and inverse equivariance
// (tests/test_regression.cpp checks each, iterate by iterate). Adding one
// means a new file in step_rules/ and its line in each switch below.
#pragma once

#include <type_traits>

#include "bireg/regression/step_rules/gauss_newton.hpp"
#include "bireg/regression/step_rules/optimal_linear.hpp"
#include "bireg/regression/step_rules/paper.hpp"
#include "bireg/regression/step_rules/preconditioned.hpp"

namespace bireg {

enum class Solver {
  paper,           // (d0, d1) = lambda (v0, v1), lambda given or 1/mu_max (the paper's)
  optimal_linear,  // lambda = 2/(mu_min + mu_max), minimising max|1 - lambda mu|
  preconditioned,  // H^{-1} applied to (v0, v1), the coupling carried across by
                   // Ad_exp(X/2): cancels the linear part
  gauss_newton,    // (d0, d1) = K^{-1}(v0, v1), K the Jacobian of v at zero residual
};

inline const char* to_string(Solver solver) {
  switch (solver) {
    case Solver::paper:
      return "paper";
    case Solver::optimal_linear:
      return "optimal_linear";
    case Solver::preconditioned:
      return "preconditioned";
    case Solver::gauss_newton:
      return "gauss_newton";
  }
  return "unknown";
}

// A value standing for the step rule type Rule.
template <class Rule>
struct StepRuleTag {
  using type = Rule;
};

// Calls visit(StepRuleTag<Rule>{}) with the rule type of `solver` for G.
template <class G, class Visitor>
auto with_step_rule(Solver solver, Visitor&& visit) {
  switch (solver) {
    case Solver::paper:
      return visit(StepRuleTag<PaperStep<G>>{});
    case Solver::optimal_linear:
      return visit(StepRuleTag<OptimalLinearStep<G>>{});
    case Solver::preconditioned:
      return visit(StepRuleTag<PreconditionedStep<G>>{});
    case Solver::gauss_newton:
      break;
  }
  return visit(StepRuleTag<GaussNewtonStep<G>>{});
}

}  // namespace bireg
