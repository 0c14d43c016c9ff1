// bireg: how a fit ended (Status) and how it evaluates the inverse
// differentials (Method).
#pragma once

namespace bireg {

enum class Status {
  // Success: ok() is true for these two.
  converged,       // the step proposed at the returned endpoints is at or below the tolerance
  rounding_floor,  // converged as far as the data's precision allows: the steps
                   // stopped shrinking at the rounding level (sqrt(epsilon)
                   // relative to |X|) for kStallIterations iterations, above a
                   // tolerance finer than the data's rounding
  // Failure: the last usable endpoints are returned.
  max_iterations,   // the iteration limit was reached first
  diverged,         // the steps grew without bound (or became non-finite)
  series_diverged,  // a step would take the spectral radius of ad_X to 2 pi,
                    // where the inverse differentials' series no longer converges
  no_descent,       // no step along the solver's direction reduces the estimating
                    // equations: the data lie outside the region where the
                    // estimator is defined (e.g. a rotation of more than pi
                    // along the geodesic)
  invalid_input,    // rejected before any work; Result::message says why and
                    // Result::geodesic is empty
};

// Whether a fit with this status answered the question.
constexpr bool is_success(Status status) {
  return status == Status::converged || status == Status::rounding_floor;
}

inline const char* to_string(Status status) {
  switch (status) {
    case Status::converged:
      return "converged";
    case Status::rounding_floor:
      return "rounding_floor";
    case Status::max_iterations:
      return "max_iterations";
    case Status::diverged:
      return "diverged";
    case Status::series_diverged:
      return "series_diverged";
    case Status::no_descent:
      return "no_descent";
    case Status::invalid_input:
      return "invalid_input";
  }
  return "unknown";
}

// How the inverse differentials psi_s(ad_X) are evaluated.
enum class Method {
  series,           // the paper's series truncated at Options::series_order
  series_adaptive,  // the series, truncated where the omitted terms fall below epsilon
  exact,            // the group's closed form (groups/capabilities.hpp) where it is
                    // accurate, the adaptive series elsewhere and for groups without one
};

inline const char* to_string(Method method) {
  switch (method) {
    case Method::series:
      return "series";
    case Method::series_adaptive:
      return "series_adaptive";
    case Method::exact:
      return "exact";
  }
  return "unknown";
}

}  // namespace bireg
