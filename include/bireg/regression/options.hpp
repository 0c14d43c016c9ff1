// bireg: the options of a fit, and the one rule for them: every option is
// checked before any work, and an option that does not apply to the chosen
// method or solver is refused with a message (not silently ignored).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "bireg/groups/tolerance.hpp"
#include "bireg/math/psi_series.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/solver.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

template <class Scalar>
struct RegressionOptions {
  // Evaluation of the inverse differentials (see Method). The closed form
  // is the most accurate and, on the groups that have one, not slower.
  Method method = Method::exact;
  // Truncation order M >= 1 for Method::series (only; 0 otherwise).
  int series_order = 0;
  // Cap of the adaptive order (series_adaptive, and exact below its closed
  // form's angle or on groups without one), which picks the smallest M whose
  // omitted terms are below epsilon relative at every iteration.
  int max_series_order = kMaxSeriesOrder;
  // The step rule (see Solver). Gauss-Newton converges in a handful of
  // iterations where the paper's step needs dozens.
  Solver solver = Solver::gauss_newton;
  // lambda of the paper solver (only; 0 otherwise); 0 selects the paper's
  // 1/mu_max. Must be below 2/mu_max, where the linear part stops contracting.
  Scalar step_size = Scalar(0);
  // Converged when the proposed step's norm (for the paper solver: the norm
  // of v / mu_max, whatever step_size is) in tangent coordinates is at or
  // below this. It is absolute: data whose tangent coordinates are large
  // (e.g. translations in millimetres) need a proportionally larger value.
  // 0 runs exactly max_iterations iterations (no convergence or stall
  // test), unless the fit fails first.
  Scalar tolerance = std::max(Scalar(1e-10), Scalar(64) * std::numeric_limits<Scalar>::epsilon());
  int max_iterations = 1000;
  // The covariates mapped to 0 and 1 (problem.hpp), in the user's units;
  // by default the smallest and largest covariate. Every covariate must lie
  // inside.
  std::optional<std::pair<CovariateScalar<Scalar>, CovariateScalar<Scalar>>> interval;
  // Tolerance of the group-membership check on every observation.
  Scalar element_tolerance = default_element_tolerance<Scalar>();
  // Keep (g0, g1) after every step in Result::iterates.
  bool record_iterates = false;
  // Threads for the passes over the observations (parallel.hpp: the check,
  // the chart start, the Gauss-Newton moments, the force, the diagnostics),
  // at least 1. A fit of kParallelMinimum observations or more starts
  // threads - 1 workers for its duration, capped at one fewer than its
  // chunks (chunk_count(n)) and at kMaxWorkers (255: so at most kMaxThreads
  // = 256 threads work, whatever is asked); a worker the system refuses to
  // start leaves fewer, never an error. The results are bit-identical for
  // any value. 1 (the default): no thread is ever started.
  int threads = 1;
  // Use the batched kernels where this build has them
  // (regression/batched_force.hpp: the closed-form force of SO(3) and
  // SE(3), compiled with Highway for AVX2 or AVX-512); false keeps the
  // scalar loop everywhere. The two agree to rounding (a fit's endpoints
  // within 1e-13 of each other in the group's distance;
  // tests/test_batched_force.cpp).
  bool batched_kernels = true;

  // How the estimating equations evaluate psi, from the fields above.
  PsiEvaluation psi() const { return {method, series_order, max_series_order, batched_kernels}; }
};

template <class Scalar>
std::optional<Rejection> validate_options(const RegressionOptions<Scalar>& options) {
  using std::isfinite;
  const std::string max_order = std::to_string(kMaxSeriesOrder);
  if (!(options.tolerance >= 0) || !isfinite(options.tolerance)) {
    return Rejection{"tolerance must be a finite non-negative number"};
  }
  if (options.threads < 1) {
    return Rejection{"threads must be at least 1, got " + std::to_string(options.threads)};
  }
  if (options.max_iterations < 1) return Rejection{"max_iterations must be at least 1"};
  if (options.max_series_order < 1 || options.max_series_order > kMaxSeriesOrder) {
    return Rejection{"max_series_order must be in [1, " + max_order + "]"};
  }
  if (options.method == Method::series) {
    if (options.series_order < 1 || options.series_order > kMaxSeriesOrder) {
      return Rejection{"method series needs series_order in [1, " + max_order + "]"};
    }
  } else if (options.series_order != 0) {
    return Rejection{std::string("series_order applies to method series only, not to ") +
                     to_string(options.method)};
  }
  if (!(options.step_size >= 0) || !isfinite(options.step_size)) {
    return Rejection{"step_size must be a finite non-negative number (0 = 1/mu_max)"};
  }
  if (options.solver != Solver::paper && options.step_size != 0) {
    return Rejection{std::string("step_size applies to the paper solver only, not to ") +
                     to_string(options.solver)};
  }
  if (!(options.element_tolerance >= 0) || !isfinite(options.element_tolerance)) {
    return Rejection{"element_tolerance must be a finite non-negative number"};
  }
  return std::nullopt;
}

}  // namespace bireg
