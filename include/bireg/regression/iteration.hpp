// bireg: the iteration g0 <- g0 exp(d0), g1 <- g1 exp(d1) (the paper's
// Section 2.2 for the paper step; any step rule of solver.hpp), run until
// the step proposed at the current endpoints is at or below the tolerance.
// Those endpoints are returned: the step certifies them, and is not taken
// (Stopping::certified, what fit() does). Stopping::predicted saves that
// certifying evaluation where the iteration visibly contracts (below).
//
// Safeguard (rules with `safeguarded`): a step that would increase ||v|| is
// halved, up to kMaxHalvings times, so a fast step cannot overshoot where
// the paper's step converges (a full step on a long geodesic can carry an
// endpoint past pi). The test uses the Euclidean norm of v in
// left-trivialised coordinates: left-invariant, and only approximately
// right-invariant on groups without a bi-invariant metric (SE(3)), which
// matters only for a borderline halving decision.
//
// Trial steps are evaluated into a second residual buffer, swapped in when
// the step is taken, so a rejected trial costs nothing to undo. Both buffers
// and the history are reserved before the loop: no heap allocation inside
// it (beyond kReservedHistory iterations the history grows geometrically).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "bireg/geodesic.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

// Iterations without a new smallest step, all below the rounding level,
// after which a fit stops with Status::rounding_floor. Every solver shrinks
// its step at least linearly while it can, so 10 iterations with no progress
// mean rounding dominates: e.g. similarities at scale e^-20 carrying an
// O(1) translation keep only ~1e-7 of their detail in double.
inline constexpr int kStallIterations = 10;

// Iterations whose history is reserved up front (more grow the vectors,
// geometrically: a fit of 1,000 iterations reallocates 4 times). Fits
// converge in 3-30 iterations; the reservation stays in the result, so it
// is kept small: 1,024 kept 8 KB of step norms (256 KB of SE(3) iterates
// when recorded) in every result, 80 MB for fit_many's 10,000 subjects.
inline constexpr int kReservedHistory = 64;

// How the iteration decides it has converged.
enum class Stopping {
  // Return endpoints at which the proposed step is at or below the
  // tolerance: one evaluation more than the steps taken.
  certified,
  // Also stop right after taking a step d_k whose contraction predicts
  // convergence: with theta = |d_k| / |d_{k-1}| (both steps proposed at
  // states reached by full steps), theta <= 1/2 and the a-posteriori bound
  // of a contraction with factor theta, theta / (1 - theta) |d_k|, at or
  // below the tolerance (measured by the rule's convergence_norm: the
  // paper's rule judges the force, which no step bounds, so it never stops
  // this way). The endpoints after d_k are returned without
  // being evaluated: the returned state's x and ad_x are theirs, its force
  // and the residuals are those of the endpoints before the step
  // (IterationRecord::unevaluated). For a sequence of warm-started fits
  // (the local regression), where the first step from the previous fit
  // and one more reach the tolerance: two evaluations instead of three.
  predicted,
};

template <class Scalar>
struct IterationControl {
  Scalar tolerance;
  int max_iterations;
  bool record_iterates;
  Stopping stopping = Stopping::certified;
};

// What the iteration did, for the result and its diagnostics.
template <class G>
struct IterationRecord {
  Status status = Status::max_iterations;
  int iterations = 0;  // evaluations of the step (the last certifies a converged fit)
  int backtracks = 0;  // safeguard halvings
  std::vector<typename G::Scalar> step_norms;  // every proposed step, before halving
  std::vector<std::pair<typename G::Element, typename G::Element>> iterates;  // if recorded
  // Stopping::predicted stopped after an unevaluated step (see there).
  bool unevaluated = false;
  // The caller's decision stopped the iteration before it converged (see
  // iterate): `status` is then meaningless, the fit is unfinished.
  bool decided = false;

  // To the state before any iteration, keeping the vectors' capacity.
  void reset() {
    status = Status::max_iterations;
    iterations = backtracks = 0;
    step_norms.clear();
    iterates.clear();
    unevaluated = decided = false;
  }
};

// A caller that needs a decision about the fit rather than the fit (the
// trend test: is the permuted statistic beyond the observed one?) passes a
// decision to iterate: decided(residuals, theta) is called at every
// evaluated state that has not converged, with that state's residuals and
// theta = |d_k| / |d_{k-1}|, the contraction factor estimated from the
// step proposed there and the full step that reached it (0 where unknown:
// at the start, after a halved step). Returning true stops the iteration
// there (IterationRecord::decided). A DecisionRef refers to the caller's
// decision (which must outlive it) through one function pointer, so that
// iterate is compiled once whatever decides: a template parameter
// instantiated the whole iteration again for the trend test (about a
// second of a consumer's compile time). The default refers to none and
// never stops the iteration.
template <class Tangent, class Scalar>
class DecisionRef {
 public:
  DecisionRef() = default;
  template <class Decision,
            class = std::enable_if_t<!std::is_same_v<std::decay_t<Decision>, DecisionRef>>>
  DecisionRef(Decision& decision)  // NOLINT(google-explicit-constructor): a view
      : decision_(&decision),
        call_([](void* d, const std::vector<Tangent>& residuals, Scalar theta) {
          return bool((*static_cast<Decision*>(d))(residuals, theta));
        }) {}

  bool operator()(const std::vector<Tangent>& residuals, Scalar theta) const {
    return call_ != nullptr && call_(decision_, residuals, theta);
  }

 private:
  void* decision_ = nullptr;
  bool (*call_)(void*, const std::vector<Tangent>&, Scalar) = nullptr;
};

// Runs the iteration from (start0, start1), or from (fallback, fallback)
// when that start is unusable, until it converges, fails, or `decided`
// stops it (DecisionRef above). Returns the state at the returned endpoints,
// whose residuals are in `residuals` (sized N; see Stopping::predicted for
// the exception). `record` is reset first, so one record (and one
// workspace) can serve a sequence of fits without allocating again. Every state it returns has
// a convergent series and a finite force, hence finite residuals, except
// when even the fallback start (X = 0) is unusable, which cannot happen.
// Each evaluation is evaluate<G>(observations, ...), found by
// argument-dependent lookup: observations of a type with its own evaluate
// (ChunkedObservations, chunked_fit.hpp: sums computed where the chunks
// are) run this same iteration.
template <class G, class Rule, class Observations>
State<G> iterate(const Observations& observations, const Problem<typename G::Scalar>& problem,
                 const PsiEvaluation& psi, const Rule& rule,
                 const IterationControl<typename G::Scalar>& control,
                 const typename G::Element& start0, const typename G::Element& start1,
                 const typename G::Element& fallback, std::vector<typename G::Tangent>& residuals,
                 IterationRecord<G>& record, ForceWorkspace<G>* workspace = nullptr,
                 DecisionRef<typename G::Tangent, typename G::Scalar> decided = {}) {
  using Scalar = typename G::Scalar;
  using std::isfinite;
  using std::sqrt;
  // A step this much larger than the smallest one seen means the iteration
  // left the basin where it contracts, unless both are at the rounding
  // level (below sqrt(epsilon), or the tolerance), where steps fluctuate by
  // orders of magnitude without meaning anything.
  constexpr Scalar kDivergenceGrowth = Scalar(1e3);
  const Scalar sqrt_epsilon = sqrt(std::numeric_limits<Scalar>::epsilon());
  const Scalar divergence_floor = kDivergenceGrowth * std::max(control.tolerance, sqrt_epsilon);
  constexpr int kMaxHalvings = 20;

  const std::size_t reserved =
      static_cast<std::size_t>(std::min(control.max_iterations, kReservedHistory));
  record.reset();
  record.step_norms.reserve(reserved);
  if (control.record_iterates) record.iterates.reserve(reserved);
  residuals.resize(observations.size());
  ForceWorkspace<G> local_workspace;
  if (!workspace) workspace = &local_workspace;
  std::vector<typename G::Tangent>& trial_residuals = workspace->trial_residuals;
  trial_residuals.resize(observations.size());

  int iterations_without_progress = 0;
  Scalar smallest_step = std::numeric_limits<Scalar>::infinity();
  // The last step's norm when it was proposed at a state reached by a
  // full step (or the start) and taken in full: Stopping::predicted's
  // contraction estimate needs two such steps in a row. 0: none.
  Scalar full_step = 0;
  State<G> state = evaluate<G>(observations, problem, psi, start0, start1, residuals, workspace);
  // A start beyond the series' disc or the log's domain (an extrapolated
  // chart line on a matrix group, a far initial guess): start from the
  // middle observation instead.
  if (!state.usable()) {
    state = evaluate<G>(observations, problem, psi, fallback, fallback, residuals, workspace);
  }
  for (int iteration = 0; iteration < control.max_iterations; ++iteration) {
    if (!state.series_converges) {
      record.status = Status::series_diverged;
      return state;
    }
    const auto [d0, d1] = rule(state);
    const Scalar step_norm = sqrt(d0.squaredNorm() + d1.squaredNorm());
    if (!isfinite(step_norm) ||
        (step_norm > kDivergenceGrowth * smallest_step && step_norm > divergence_floor)) {
      record.status = Status::diverged;
      return state;
    }
    record.step_norms.push_back(step_norm);
    record.iterations = iteration + 1;
    if (rule.convergence_norm(step_norm, state) <= control.tolerance) {
      record.status = Status::converged;
      return state;
    }
    if (decided(residuals, full_step > 0 ? step_norm / full_step : Scalar(0))) {
      record.decided = true;
      return state;
    }
    if (control.stopping == Stopping::predicted && full_step > 0) {
      const Scalar theta = step_norm / full_step;
      if (theta <= Scalar(0.5) &&
          rule.convergence_norm(theta / (1 - theta) * step_norm, state) <= control.tolerance) {
        state.g0 = exp_at<G>(state.g0, d0);
        state.g1 = exp_at<G>(state.g1, d1);
        state.x = log_at<G>(state.g0, state.g1);
        state.a = G::ad(state.x);
        record.status = Status::converged;
        record.unevaluated = true;
        if (control.record_iterates) record.iterates.emplace_back(state.g0, state.g1);
        return state;
      }
    }
    // Steps below sqrt(epsilon) relative to the geodesic's size are at the
    // rounding level, where they fluctuate without meaning.
    const Scalar rounding_level = std::max(
        control.tolerance, sqrt_epsilon * std::max(Scalar(1), sqrt(state.x.squaredNorm())));
    if (step_norm < smallest_step) {
      smallest_step = step_norm;
      iterations_without_progress = 0;
    } else if (control.tolerance > 0 && step_norm <= rounding_level &&
               ++iterations_without_progress >= kStallIterations) {
      record.status = Status::rounding_floor;
      return state;
    }

    State<G> next = evaluate<G>(observations, problem, psi, exp_at<G>(state.g0, d0),
                                exp_at<G>(state.g1, d1), trial_residuals, workspace);
    full_step = step_norm;
    if (rule.safeguarded) {
      const Scalar force_norm = state.force.norm();
      const auto acceptable = [&](const State<G>& trial) {
        return trial.series_converges && trial.force.norm() <= force_norm;
      };
      Scalar fraction = 1;
      for (int halving = 0; halving < kMaxHalvings && !acceptable(next); ++halving) {
        fraction /= 2;
        full_step = 0;
        ++record.backtracks;
        next = evaluate<G>(observations, problem, psi, exp_at<G>(state.g0, fraction * d0),
                           exp_at<G>(state.g1, fraction * d1), trial_residuals, workspace);
      }
      // Every halving failed: no step along this direction decreases the
      // force. Above the rounding level that means the data are outside
      // the estimator's domain; stop rather than wander.
      if (!acceptable(next) && step_norm > rounding_level) {
        record.status = Status::no_descent;
        return state;
      }
    }
    // The step left the series' disc, or the domain of the group's log
    // (MatrixGroup returns NaN there, so the force is not finite). Keep the
    // last usable endpoints.
    if (!next.usable()) {
      record.status = next.series_converges ? Status::diverged : Status::series_diverged;
      return state;
    }
    state = next;
    std::swap(residuals, trial_residuals);
    if (control.record_iterates) record.iterates.emplace_back(state.g0, state.g1);
  }
  return state;
}

}  // namespace bireg
