// bireg: the step rules, by name. Each is one small type in step_rules/
// (its step, its safeguard policy, what convergence is judged on); all are
// Exp-stepped iterations g0 <- g0 exp(d0), g1 <- g1 exp(d1) with the same
// fixed point v = 0, and all keep left, right and inverse equivariance
// (tests/test_regression.cpp checks each, iterate by iterate). Adding one
// means a new file in step_rules/ and its line in each switch below.
#pragma once

#include <type_traits>
#include <utility>

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

// A reference to one step rule, whichever it is. The code that runs a
// rule (iterate, the diagnostics, each caller's bookkeeping) takes the
// view and is compiled once instead of once per rule: with_step_rule's
// visitor builds the rule and hands its view on. Each rule's own code
// stays in its type; the view costs one indirect call per iteration.
template <class G>
class StepRuleView {
 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;

  // `rule` must outlive the view.
  template <class Rule>
  explicit StepRuleView(const Rule& rule)
      : safeguarded(Rule::safeguarded),
        rule_(&rule),
        step_([](const void* r, const State<G>& state) {
          return (*static_cast<const Rule*>(r))(state);
        }),
        convergence_norm_([](const void* r, Scalar step_norm, const State<G>& state) {
          return static_cast<const Rule*>(r)->convergence_norm(step_norm, state);
        }),
        step_size_(rule.step_size()) {
    if constexpr (std::is_same_v<Rule, GaussNewtonStep<G>>) gauss_newton_ = &rule;
  }

  std::pair<Tangent, Tangent> operator()(const State<G>& state) const {
    return step_(rule_, state);
  }
  Scalar convergence_norm(Scalar step_norm, const State<G>& state) const {
    return convergence_norm_(rule_, step_norm, state);
  }
  Scalar step_size() const { return step_size_; }
  // The rule when it is the Gauss-Newton one (its K at the estimate is the
  // covariance's), else null.
  const GaussNewtonStep<G>* gauss_newton() const { return gauss_newton_; }

  // As each rule's static member (iteration.hpp reads rule.safeguarded).
  const bool safeguarded;

 private:
  const void* rule_;
  std::pair<Tangent, Tangent> (*step_)(const void*, const State<G>&);
  Scalar (*convergence_norm_)(const void*, Scalar, const State<G>&);
  Scalar step_size_;
  const GaussNewtonStep<G>* gauss_newton_ = nullptr;
};

// A fit's step rule, by name, run: calls run(StepRuleView<G>(rule)) with
// the rule `solver` names for `problem`, or returns refused(rejection) when
// that rule refuses the problem (Rule::refuse). The Gauss-Newton rule is
// gauss_newton()'s (its moments summed wherever the caller's observations
// are), the others are built from step_size. run and refused return the
// same type.
template <class G, class GaussNewton, class Refused, class Run>
auto with_step_rule_view(Solver solver, const Problem<typename G::Scalar>& problem,
                         typename G::Scalar step_size, GaussNewton&& gauss_newton,
                         Refused&& refused, Run&& run) {
  return with_step_rule<G>(solver, [&](auto tag) {
    using Rule = typename decltype(tag)::type;
    if (auto rejection = Rule::refuse(problem, step_size)) return refused(*rejection);
    const Rule rule = [&] {
      if constexpr (std::is_same_v<Rule, GaussNewtonStep<G>>) {
        return gauss_newton();
      } else {
        return Rule(problem, step_size);
      }
    }();
    return run(StepRuleView<G>(rule));
  });
}

}  // namespace bireg
