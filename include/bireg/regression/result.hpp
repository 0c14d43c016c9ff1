// bireg: what fit() returns.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/geodesic.hpp"
#include "bireg/regression/diagnostics.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/iteration.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

template <class G>
struct RegressionResult {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using Jacobian = Eigen::Matrix<Scalar, 2 * G::dof, 2 * G::dof>;

  Status status = Status::invalid_input;
  std::string message;            // what was wrong, for invalid_input
  std::ptrdiff_t bad_index = -1;  // offending observation, if any
  // The fitted geodesic in the user's covariate units; empty for
  // invalid_input (nothing was fitted), the last usable endpoints for the
  // other failures (check ok()).
  std::optional<Geodesic<G>> geodesic;
  // Iterations: evaluations of the step at the current endpoints. Each but
  // the last of a converged fit is taken; the last, at or below the
  // tolerance, certifies the returned endpoints. step_norms holds the norm
  // of every proposed step (before any safeguard halving).
  int iterations = 0;
  std::vector<Scalar> step_norms;
  std::vector<Tangent> residuals;                     // r_i = log(gamma(t_i)^{-1} f_i), input order
  std::vector<std::pair<Element, Element>> iterates;  // after each step taken, if recorded
  RegressionDiagnostics<Scalar> diagnostics;
  // K, the Gauss-Newton matrix (step_rules/gauss_newton.hpp) at the
  // returned endpoints: -dv/d(delta0, delta1) where the residuals vanish,
  // in left-trivialised coordinates on the unit interval. The covariance of
  // the estimate is built on it. Zero for invalid_input and series_diverged.
  Jacobian jacobian = Jacobian::Zero();

  bool ok() const { return is_success(status); }
};

// The result of a fit refused before any work (Status::invalid_input).
template <class G>
RegressionResult<G> rejected_result(Rejection rejection) {
  RegressionResult<G> result;
  result.status = Status::invalid_input;
  result.message = std::move(rejection.message);
  result.bad_index = rejection.index;
  return result;
}

// Fills `result` from where the iteration ended: its status, count, step
// norms and iterates (moved out of `record`), the `diagnostics` (computed
// from `record` before this call) and the geodesic through the final
// state's endpoints in the covariates' units.
template <class G>
void fill_result(RegressionResult<G>& result, const Problem<typename G::Scalar>& problem,
                 const State<G>& state, IterationRecord<G>& record,
                 RegressionDiagnostics<typename G::Scalar> diagnostics) {
  using Scalar = typename G::Scalar;
  result.status = record.status;
  result.iterations = record.iterations;
  result.diagnostics = std::move(diagnostics);
  result.step_norms = std::move(record.step_norms);
  result.iterates = std::move(record.iterates);
  result.geodesic = Geodesic<G>(state.g0, state.g1, static_cast<Scalar>(problem.t_min),
                                static_cast<Scalar>(problem.t_max));
}

}  // namespace bireg
