// bireg: bi-invariant spline regression (docs/splines.md), the smooth
// curve beside the geodesic of regression.hpp.
//
// Data (f_i, t_i, w_i) as for GeodesicRegression. The model is the
// cumulative B-spline of spline.hpp with uniform knots over the covariates'
// range, and the estimator the control points at which, for every c,
//
//   F_c = sum_i w_i B_c(t_i)^2 D_c(t_i)^{-1} log(T(t_i)^{-1} f_i) = 0      (splines.md (6))
//
// (D_c the differential of the curve in P_c, regression/spline/
// differentials.hpp): Definition 2.1 of "Bi-invariant geodesic regression"
// with one equation per control point. For degree 1 and two control points
// it is that definition, in R^n the normal equations of least-squares
// B-spline regression, and for every degree it is equivariant under left
// and right translation of the data (splines.md §6; inversion for degree 1
// only, §3). fit():
//
//   1. the problem (regression/problem.hpp: covariates onto [0, 1], weights
//      normalised), the knots (S segments of equal length, the fewest whose
//      length is at most the requested spacing), and the Schoenberg-Whitney
//      condition, under which the linearised equations have a unique
//      solution (§7): refused, naming the control point and its span, when
//      some basis function's support cannot be given its own observation;
//   2. a start: each control point P_c is the B_c-weighted mean, in the log
//      chart at the observation nearest its Greville abscissa, of the
//      observations in its support (left and right equivariant);
//   3. Gauss-Newton on (6) with the block-banded Jacobian of §9,
//      backtracking on sum_c |F_c|^2 when a full step does not reduce it.
//
// Errors as for GeodesicRegression::fit(): invalid input is reported as
// Status::invalid_input with a message (and `bad_index`), a fit that does
// not converge reports why, and nothing returns NaN.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/regression/diagnostics.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/spline/banded.hpp"
#include "bireg/regression/spline/differentials.hpp"
#include "bireg/regression/status.hpp"
#include "bireg/spline.hpp"

namespace bireg {

template <class Scalar>
struct SplineOptions {
  using Wide = CovariateScalar<Scalar>;
  // Degree of the B-splines: 1 (piecewise geodesic), 2 or 3 (cubic).
  int degree = 3;
  // Largest knot spacing in covariate units (> 0): the range is cut into
  // S = ceil(range / knot_spacing) equal segments. Infinity: one segment.
  Wide knot_spacing = std::numeric_limits<Wide>::infinity();
  // Converged when the Gauss-Newton step's largest control-point component
  // is at or below this (absolute, in tangent coordinates, as for the
  // geodesic).
  Scalar tolerance = std::max(Scalar(1e-10), Scalar(64) * std::numeric_limits<Scalar>::epsilon());
  int max_iterations = 100;
  // A step from the Gauss-Newton matrix K of earlier control points is
  // taken when its norm is at most this times the step before it (it
  // contracts by 1/this per step); otherwise K is assembled where the
  // fit stands (docs/splines.md §9, "Reusing K"). In [0, 1); 0 assembles
  // K with every step. It changes the cost, not the answer beyond the
  // tolerance.
  Scalar jacobian_reuse_contraction = Scalar(0.01);
  // lambda >= 0 of the roughness penalty (splines.md §12): F_c gains
  // -lambda (s_{c-1} - 2 s_c + s_{c+1}), s_c = Omega_{c+1} - Omega_c, the
  // second differences of the control points in increments, bi-invariant
  // without a metric; in R^n the penalised normal equations (B^T W B +
  // lambda D_2^T D_2) p = B^T W x, weights normalised to a largest of 1.
  // 0: none. Degree 2 or 3 (the penalty couples control points two apart,
  // beyond a piecewise geodesic's band).
  Scalar roughness_penalty = 0;
  // The covariates mapped to the first and last knot, as for the geodesic
  // (RegressionOptions::interval); by default their smallest and largest.
  std::optional<std::pair<Wide, Wide>> interval;
  Scalar element_tolerance = default_element_tolerance<Scalar>();
  // Threads for the passes over the observations (regression/parallel.hpp),
  // at least 1; from kParallelMinimum observations on. The results are
  // bit-identical for any value.
  int threads = 1;
};

template <class G>
struct SplineResult {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;

  Status status = Status::invalid_input;
  std::string message;            // what was wrong, for invalid_input and no_descent
  std::ptrdiff_t bad_index = -1;  // offending observation, if any
  // The fitted curve in the user's covariate units; empty for
  // invalid_input, the last iterate for the other failures (check ok()).
  std::optional<Spline<G>> spline;
  int iterations = 0;              // Gauss-Newton steps proposed (the last certifies)
  std::vector<Scalar> step_norms;  // the largest control-point component of each
  // Times K (the Gauss-Newton matrix) was assembled, rejected trials
  // included: fewer than the steps where steps from an earlier K contract
  // well (splines.md §9, SplineOptions::jacobian_reuse_contraction).
  int jacobian_evaluations = 0;
  // SplineOptions::roughness_penalty of the fit (0: none), for what reads
  // the result later (spline_covariance refuses a penalised fit).
  Scalar roughness_penalty = 0;
  std::vector<Tangent> residuals;  // r_i = log(T(t_i)^{-1} f_i), input order
  // max_c |F_c| at the returned control points (splines.md (6)), weights
  // normalised to a largest of 1.
  Scalar equation_norm = 0;
  // Where the curve nears the principal log's cut locus, as the geodesic's
  // diagnostics report it (RegressionDiagnostics): the largest rotation
  // angle (spectral radius of ad) of a residual and its observation, and of
  // an increment Omega_j = log(P_{j-1}^{-1} P_j) (one knot span's turn)
  // and its j. For groups without a closed-form spectral radius (groups/
  // capabilities.hpp): 0 and -1. beyond_domain: either exceeds
  // kBeyondDomainAngle (3 pi / 4): an observation lies near a half turn
  // from the curve (a gross outlier, or motion too fast for the knots), or
  // a knot span turns by nearly pi, where the increment's principal log,
  // and with it the curve, is about to jump; a narrower knot spacing is
  // the remedy for both.
  Scalar largest_residual_angle = 0;
  std::ptrdiff_t largest_residual_observation = -1;
  Scalar largest_increment_angle = 0;
  std::ptrdiff_t largest_increment = -1;
  bool beyond_domain = false;

  bool ok() const { return is_success(status); }
};

template <class G>
class SplineRegression {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Options = SplineOptions<Scalar>;
  using Result = SplineResult<G>;

  SplineRegression() = default;
  explicit SplineRegression(Options options) : options_(std::move(options)) {}
  const Options& options() const { return options_; }

  template <class Observations, class Covariates>
  Result fit(const Observations& observations, const Covariates& covariates,
             const std::vector<Scalar>& weights = {}) const {
    return run(observations, covariates, weights, nullptr);
  }

  // As fit(), from the given control points (e.g. a previous fit's, for a
  // warm start); their number must be the one the options give.
  template <class Observations, class Covariates>
  Result fit_from(const std::vector<Element>& start, const Observations& observations,
                  const Covariates& covariates, const std::vector<Scalar>& weights = {}) const {
    return run(observations, covariates, weights, &start);
  }

  // The estimating equations F_c of splines.md (6) at `points` for the
  // data fit() would be given (weights normalised to a largest of 1, as
  // fit()'s equation_norm): what a fit drives to zero, for diagnostics and
  // for iterations of one's own (the Exp-stepped P_c <- P_c exp(lambda F_c)
  // of splines.md §7). Input is checked as fit() checks it, `points` as
  // fit_from() checks its start; a refusal is the message, and F is then
  // empty. F is empty too where it is not finite (consecutive control
  // points or residuals outside the log's domain), with that message.
  struct Equations {
    std::string message;
    std::vector<Tangent> force;
    bool ok() const { return message.empty(); }
  };

  template <class Observations, class Covariates>
  Equations equations(const std::vector<Element>& points, const Observations& observations,
                      const Covariates& covariates, const std::vector<Scalar>& weights = {}) const {
    Equations out;
    Prepared prepared;
    if (auto rejection = prepare(observations, covariates, weights, &points, prepared)) {
      out.message = rejection->message;
      return out;
    }
    ChunkPool* const pool = prepared.pool ? &*prepared.pool : nullptr;
    Scratch scratch(prepared.problem, prepared.knots, std::move(prepared.order), options_.degree,
                    pool);
    Evaluation evaluation(prepared.knots.control_points);
    std::vector<Tangent> residuals(observations.size());
    evaluate(observations, prepared.problem, prepared.knots, points, residuals, nullptr, scratch,
             evaluation);
    if (!evaluation.finite) {
      out.message = "the estimating equations are not finite at these control points";
      return out;
    }
    out.force = std::move(evaluation.force);
    return out;
  }

 private:
  // The knots on the unit interval: S segments of length h = 1/S.
  struct Knots {
    std::size_t segments = 1;
    std::size_t control_points = 2;
    Scalar h = 1;
  };

  // The state of the iteration at one set of control points.
  struct Evaluation {
    explicit Evaluation(std::size_t control_points) : force(control_points, Tangent::Zero()) {}
    std::vector<Tangent> force;  // F_c
    Scalar merit = 0;            // sum_c |F_c|^2
    bool finite = true;
  };

  // Observations per chunk of the spline's sums: a quarter of
  // parallel.hpp's kChunkSize, because an observation costs the spline
  // about 5x what it costs the geodesic and the chunks are claimed whole:
  // 1e5 observations in chunks of 4096 make 25, which two threads share
  // 13 to 12 (at best 1.92x less time on two); in chunks of 1024 they
  // make 98. Like kChunkSize, it does not depend on the thread count, so
  // neither do the sums.
  static constexpr std::size_t kSplineChunkSize = 1024;

  // One chunk's share of F and K (kSplineChunkSize observations in
  // covariate order): the control points [first, first +
  // force.size()), and K's rows for them laid out as BlockBandedMatrix's.
  struct ChunkPartial {
    std::size_t begin = 0, end = 0;  // positions in the covariate order
    std::size_t first = 0, rows = 0;
    std::vector<Tangent> force;
    std::vector<Scalar> mass;  // the start's sums of weights
    std::vector<AdMatrix> blocks;
  };

  // What evaluate() works in, allocated once per fit: the increments and
  // their Jacobians, the observations in covariate order and the chunks'
  // partial sums, and the pool that computes them.
  struct Scratch {
    Scratch(const Problem<Scalar>& problem, const Knots& knots, std::vector<std::size_t> sorted,
            int degree, ChunkPool* chunk_pool)
        : increments(knots.control_points - 1),
          jacobians(knots.control_points - 1),
          order(std::move(sorted)),
          partials(chunk_count(order.size(), kSplineChunkSize)),
          pool(chunk_pool) {
      // Each partial is allocated here, where std::bad_alloc can leave
      // fit() (a worker must not throw), and its pages are first touched,
      // zeroed, by the thread that claims its chunk, as in every later
      // pass: assign() within the reserved capacity does not allocate.
      const auto k = static_cast<std::size_t>(degree);
      const auto segment = [&](std::size_t position) {
        return knot_position(problem.t[order[position]], Scalar(0), knots.h, knots.segments)
            .segment;
      };
      for (std::size_t chunk = 0; chunk < partials.size(); ++chunk) {
        ChunkPartial& partial = partials[chunk];
        partial.begin = chunk * kSplineChunkSize;
        partial.end = std::min(order.size(), partial.begin + kSplineChunkSize);
        partial.first = segment(partial.begin);
        partial.rows = segment(partial.end - 1) + k + 1 - partial.first;
        partial.force.reserve(partial.rows);
        partial.mass.reserve(partial.rows);
        partial.blocks.reserve(partial.rows * (2 * k + 1));
      }
      run_pieces(pool, partials.size(), [&](std::size_t chunk) {
        ChunkPartial& partial = partials[chunk];
        partial.force.assign(partial.rows, Tangent::Zero());
        partial.mass.assign(partial.rows, Scalar(0));
        partial.blocks.assign(partial.rows * (2 * k + 1), AdMatrix::Zero());
      });
    }
    std::vector<Tangent> increments;
    std::vector<IncrementJacobians<G>> jacobians;
    std::vector<std::size_t> order;
    std::vector<ChunkPartial> partials;
    ChunkPool* pool;
  };

  static Result rejected(Rejection rejection) {
    Result result;
    result.message = std::move(rejection.message);
    result.bad_index = rejection.index;
    return result;
  }

  std::optional<Rejection> validate() const {
    using std::isfinite;
    if (options_.degree < 1 || options_.degree > kMaxSplineDegree) {
      return Rejection{"degree must be 1, 2 or 3, got " + std::to_string(options_.degree)};
    }
    if (!(options_.knot_spacing > 0)) {
      return Rejection{"knot_spacing must be positive (infinity: one segment)"};
    }
    if (!(options_.tolerance >= 0) || !isfinite(options_.tolerance)) {
      return Rejection{"tolerance must be a finite non-negative number"};
    }
    if (options_.max_iterations < 1) return Rejection{"max_iterations must be at least 1"};
    if (!(options_.jacobian_reuse_contraction >= 0 && options_.jacobian_reuse_contraction < 1)) {
      return Rejection{"jacobian_reuse_contraction must be in [0, 1)"};
    }
    if (!(options_.roughness_penalty >= 0) || !isfinite(options_.roughness_penalty)) {
      return Rejection{"roughness_penalty must be a finite non-negative number"};
    }
    if (options_.roughness_penalty > 0 && options_.degree < 2) {
      return Rejection{
          "roughness_penalty needs degree 2 or 3: it couples control points two apart"};
    }
    if (options_.threads < 1) {
      return Rejection{"threads must be at least 1, got " + std::to_string(options_.threads)};
    }
    if (!(options_.element_tolerance >= 0) || !isfinite(options_.element_tolerance)) {
      return Rejection{"element_tolerance must be a finite non-negative number"};
    }
    return std::nullopt;
  }

  // S = ceil(range / spacing), refused where the control points would
  // outnumber the observations (the equations could not be determined).
  // With a roughness penalty the penalty determines what the data do not
  // (docs/splines.md §12, "Knots finer than the data"): refused only past
  // kPenalisedPointsPerObservation control points per observation, where
  // the knots are absurdly fine and only memory would be spent.
  std::optional<Rejection> make_knots(const Problem<Scalar>& problem, Knots& knots) const {
    using Wide = CovariateScalar<Scalar>;
    using std::ceil;
    const Wide range = problem.t_max - problem.t_min;
    const Wide ratio = range / options_.knot_spacing;
    const std::size_t n = problem.size();
    const auto k = static_cast<std::size_t>(options_.degree);
    // A spacing within rounding of range / S gives S, not S + 1.
    const Wide segments =
        std::max(Wide(1), ceil(ratio * (1 - 8 * std::numeric_limits<Wide>::epsilon())));
    const bool penalised = options_.roughness_penalty > 0;
    const Wide most = penalised ? Wide(kPenalisedPointsPerObservation) * Wide(n) : Wide(n);
    if (!(segments + Wide(k) <= most)) {
      const auto count = [](Wide x) {  // a whole number, as one
        return x < Wide(1e18) ? std::to_string(static_cast<unsigned long long>(x))
                              : std::to_string(double(x));
      };
      return Rejection{
          "knot spacing " + std::to_string(double(options_.knot_spacing)) + " cuts the range " +
          std::to_string(double(range)) + " into " + count(segments) + " segments: " +
          count(segments + Wide(k)) + " control points for " + std::to_string(n) + " observations" +
          (penalised ? " (a penalised fit takes up to " +
                           std::to_string(kPenalisedPointsPerObservation) + " per observation)"
                     : std::string()) +
          "; use a wider spacing"};
    }
    knots.segments = static_cast<std::size_t>(segments);
    knots.control_points = knots.segments + k;
    knots.h = Scalar(1) / Scalar(knots.segments);
    return std::nullopt;
  }

  // Schoenberg-Whitney (splines.md §7): distinct covariates s_1 < ... < s_M
  // of positive weight with B_c(s_c) > 0 for every c. Greedy in covariate
  // order, which finds such a choice whenever one exists; the first control
  // point left without one is named with its support. With a roughness
  // penalty K is positive definite once the data determine the penalty's
  // null space, the curves of equal increments (geodesics, splines.md
  // §12): two distinct covariates of positive weight, which make_problem
  // requires of every fit.
  std::optional<Rejection> check_schoenberg_whitney(const Problem<Scalar>& problem,
                                                    const std::vector<std::size_t>& order,
                                                    const Knots& knots) const {
    if (options_.roughness_penalty > 0) return std::nullopt;  // make_problem has checked
    const int k = options_.degree;
    std::size_t next = 0;  // position in `order`
    Scalar last = -1;      // the covariate given to the previous control point
    for (std::size_t c = 0; c < knots.control_points; ++c) {
      bool found = false;
      for (; next < order.size() && !found; ++next) {
        const std::size_t i = order[next];
        const Scalar t = problem.t[i];
        if (!(problem.w[i] > 0) || !(t > last)) continue;
        const KnotPosition<Scalar> at = knot_position(t, Scalar(0), knots.h, knots.segments);
        const std::ptrdiff_t j =
            static_cast<std::ptrdiff_t>(c) - static_cast<std::ptrdiff_t>(at.segment);
        if (j < 0 || j > k || !(spline_basis(k, at.u).ordinary[std::size_t(j)] > 0)) continue;
        last = t;
        found = true;
      }
      if (!found) {
        using Wide = CovariateScalar<Scalar>;
        const Wide h = (problem.t_max - problem.t_min) / Wide(knots.segments);
        const auto first = std::max<std::ptrdiff_t>(0, std::ptrdiff_t(c) - k);
        const auto end = std::min<std::size_t>(c + 1, knots.segments);
        return Rejection{
            "control point " + std::to_string(c) + " (support [" +
            std::to_string(double(problem.t_min + Wide(first) * h)) + ", " +
            std::to_string(double(problem.t_min + Wide(end) * h)) +
            "]) has no observation of positive weight of its own (Schoenberg-Whitney): the "
            "knot spans there hold too few distinct covariates; use a wider knot spacing"};
      }
    }
    return std::nullopt;
  }

  // Step 2: P_c = a_c exp(sum_i w_i B_c(t_i) log(a_c^{-1} f_i) / sum_i w_i B_c(t_i)),
  // a_c the observation nearest c's Greville abscissa (c - (k-1)/2) h; the
  // sums by chunks as in evaluate().
  template <class Observations>
  std::vector<Element> chart_start(const Observations& observations, const Problem<Scalar>& problem,
                                   const Knots& knots, Scratch& scratch) const {
    const int k = options_.degree;
    const std::vector<std::size_t>& order = scratch.order;
    std::vector<Element> anchors(knots.control_points);
    std::size_t nearest = 0;  // position in `order`, advanced monotonically
    for (std::size_t c = 0; c < knots.control_points; ++c) {
      const Scalar greville =
          std::clamp((Scalar(c) - Scalar(k - 1) / 2) * knots.h, Scalar(0), Scalar(1));
      while (nearest + 1 < order.size() && std::abs(problem.t[order[nearest + 1]] - greville) <=
                                               std::abs(problem.t[order[nearest]] - greville)) {
        ++nearest;
      }
      anchors[c] = observations[order[nearest]];
    }
    const auto chunk_sum = [&](std::size_t chunk) {
      ChunkPartial& partial = scratch.partials[chunk];
      std::fill(partial.force.begin(), partial.force.end(), Tangent::Zero());
      std::fill(partial.mass.begin(), partial.mass.end(), Scalar(0));
      for (std::size_t position = partial.begin; position < partial.end; ++position) {
        const std::size_t i = order[position];
        if (!(problem.w[i] > 0)) continue;
        const KnotPosition<Scalar> at =
            knot_position(problem.t[i], Scalar(0), knots.h, knots.segments);
        const SplineBasis<Scalar> basis = spline_basis(k, at.u);
        for (int j = 0; j <= k; ++j) {
          const std::size_t c = at.segment + std::size_t(j);
          const Scalar mass = problem.w[i] * basis.ordinary[std::size_t(j)];
          if (!(mass > 0)) continue;
          const Tangent offset = G::log(G::compose(G::inverse(anchors[c]), observations[i]));
          if (!offset.allFinite()) continue;
          partial.force[c - partial.first] += mass * offset;
          partial.mass[c - partial.first] += mass;
        }
      }
    };
    run_pieces(scratch.pool, scratch.partials.size(), chunk_sum);
    std::vector<Tangent> sums(knots.control_points, Tangent::Zero());
    std::vector<Scalar> masses(knots.control_points, Scalar(0));
    for (const ChunkPartial& partial : scratch.partials) {
      for (std::size_t r = 0; r < partial.force.size(); ++r) {
        sums[partial.first + r] += partial.force[r];
        masses[partial.first + r] += partial.mass[r];
      }
    }
    std::vector<Element> points = anchors;
    run_ranges(scratch.pool, points.size(), kControlPointPiece,
               [&](std::size_t begin, std::size_t end) {
                 for (std::size_t c = begin; c < end; ++c)
                   if (masses[c] > 0)
                     points[c] = G::compose(anchors[c], G::exp(sums[c] / masses[c]));
               });
    return points;
  }

  // The most control points per observation of a penalised fit
  // (make_knots).
  static constexpr std::size_t kPenalisedPointsPerObservation = 16;

  // Control points per piece of a pass over them on the pool (an exp and
  // a product each: 1024 take about 30 us on SO(3)).
  static constexpr std::size_t kControlPointPiece = 1024;

  // The residuals, F and sum |F|^2 at `points` into `evaluation`; K too
  // when `jacobian`. Each chunk of observations (in covariate order, so
  // that it touches a run of control points) sums into its own partial,
  // and the partials are added in chunk order: the same arithmetic for any
  // thread count.
  template <class Observations>
  void evaluate(const Observations& observations, const Problem<Scalar>& problem,
                const Knots& knots, const std::vector<Element>& points,
                std::vector<Tangent>& residuals, BlockBandedMatrix<AdMatrix, Tangent>* jacobian,
                Scratch& scratch, Evaluation& evaluation) const {
    const int k = options_.degree;
    const std::size_t band = 2 * std::size_t(k) + 1;
    std::vector<Tangent>& increments = scratch.increments;
    std::vector<IncrementJacobians<G>>& increment_jacobians = scratch.jacobians;
    std::fill(evaluation.force.begin(), evaluation.force.end(), Tangent::Zero());
    evaluation.merit = 0;
    evaluation.finite = true;
    // The increments and their Jacobians, by pieces of kIncrementChunk on
    // the pool (each piece writes its own entries).
    constexpr std::size_t kIncrementChunk = 1024;
    run_ranges(scratch.pool, increments.size(), kIncrementChunk,
               [&](std::size_t begin, std::size_t end) {
                 for (std::size_t j = begin; j < end; ++j) {
                   increments[j] = G::log(G::compose(G::inverse(points[j]), points[j + 1]));
                   increment_jacobians[j] = IncrementJacobians<G>::of(increments[j]);
                 }
               });
    for (const Tangent& increment : increments) {
      if (!increment.allFinite()) {
        evaluation.finite = false;
        return;
      }
    }
    const auto chunk_sum = [&](std::size_t chunk) {
      ChunkPartial& partial = scratch.partials[chunk];
      std::fill(partial.force.begin(), partial.force.end(), Tangent::Zero());
      if (jacobian) std::fill(partial.blocks.begin(), partial.blocks.end(), AdMatrix::Zero());
      SegmentProduct<G> product;
      ControlPointDifferentials<G> differentials;
      std::array<Tangent, kMaxSplineDegree + 1> terms;
      for (std::size_t position = partial.begin; position < partial.end; ++position) {
        const std::size_t i = scratch.order[position];
        const KnotPosition<Scalar> at =
            knot_position(problem.t[i], Scalar(0), knots.h, knots.segments);
        const SplineBasis<Scalar> basis = spline_basis(k, at.u);
        evaluate_segment<G>(k, &increments[at.segment], basis, product);
        const Element curve = G::compose(points[at.segment], product.suffix[0]);
        residuals[i] = G::log(G::compose(G::inverse(curve), observations[i]));
        const Scalar w = problem.w[i];
        if (!(w > 0)) continue;
        weighted_residuals<G>(k, basis, product, &increment_jacobians[at.segment], residuals[i],
                              terms, jacobian ? &differentials : nullptr);
        const std::size_t row = at.segment - partial.first;  // of j = 0
        for (int j = 0; j <= k; ++j)
          partial.force[row + std::size_t(j)] += w * terms[std::size_t(j)];
        if (!jacobian) continue;
        // K_cl = -sum_i w_i W_c J_l(r_i)^{-1} D_l (splines.md §9).
        const AdMatrix left_inverse = right_jacobian_inverse<G>((-residuals[i]).eval());
        for (int j = 0; j <= k; ++j) {
          const AdMatrix weighted = w * (differentials.weight[j] * left_inverse);
          AdMatrix* blocks = &partial.blocks[(row + std::size_t(j)) * band];
          for (int l = 0; l <= k; ++l)
            blocks[std::size_t(l - j + k)].noalias() -= weighted * differentials.derivative[l];
        }
      }
    };
    run_pieces(scratch.pool, scratch.partials.size(), chunk_sum);
    // F and K from the partial sums, by pieces of kReduceRows control
    // points on the pool: a piece zeroes its rows of K and adds, row by
    // row, the partials that hold the row in chunk order (the order of a
    // serial sum, so the same bits). The partials holding a row are
    // consecutive: their first and last rows never decrease.
    constexpr std::size_t kReduceRows = 512;
    const std::size_t m = points.size();
    const auto reduce_rows = [&](std::size_t begin, std::size_t end) {
      if (jacobian) {
        for (std::size_t c = begin; c < end; ++c)
          for (std::size_t l = c > std::size_t(k) ? c - std::size_t(k) : 0;
               l <= std::min(m - 1, c + std::size_t(k)); ++l)
            (*jacobian)(c, l).setZero();
      }
      auto partial = std::partition_point(
          scratch.partials.begin(), scratch.partials.end(),
          [begin](const ChunkPartial& p) { return p.first + p.force.size() <= begin; });
      for (; partial != scratch.partials.end() && partial->first < end; ++partial) {
        const std::size_t last = std::min(end, partial->first + partial->force.size());
        for (std::size_t c = std::max(begin, partial->first); c < last; ++c) {
          const std::size_t r = c - partial->first;
          evaluation.force[c] += partial->force[r];
          if (!jacobian) continue;
          for (std::size_t o = 0; o < band; ++o) {
            if (c + o < std::size_t(k) || c + o - std::size_t(k) >= m) continue;
            (*jacobian)(c, c + o - std::size_t(k)) += partial->blocks[r * band + o];
          }
        }
      }
    };
    run_ranges(scratch.pool, m, kReduceRows, reduce_rows);
    if (options_.roughness_penalty > 0)
      add_penalty(increment_jacobians, increments, jacobian, evaluation);
    for (const Tangent& f : evaluation.force)
      evaluation.merit += f.squaredNorm();
    evaluation.finite = std::isfinite(evaluation.merit);
  }

  // The roughness penalty (splines.md §12) into F and, with `jacobian`,
  // its derivative into K: s_c = Omega_{c+1} - Omega_c for c = 1 .. M - 2
  // (Omega_j = increments[j - 1]) enters F_a with the coefficient
  // -lambda (1, -2, 1) for a = c - 1, c, c + 1; perturbing P_l -> P_l
  // exp(delta_l) moves Omega_l by J_r(Omega_l)^{-1} delta_l and Omega_{l+1}
  // by -J_l(Omega_{l+1})^{-1} delta_l, so ds_c/d delta is J_l(Omega_c)^{-1}
  // at c - 1, -(J_l(Omega_{c+1})^{-1} + J_r(Omega_c)^{-1}) at c and
  // J_r(Omega_{c+1})^{-1} at c + 1. Serial, after the chunks' sums: the
  // same bits for any thread count.
  void add_penalty(const std::vector<IncrementJacobians<G>>& increment_jacobians,
                   const std::vector<Tangent>& increments,
                   BlockBandedMatrix<AdMatrix, Tangent>* jacobian, Evaluation& evaluation) const {
    const Scalar lambda = options_.roughness_penalty;
    const std::size_t m = evaluation.force.size();
    constexpr Scalar kCoefficient[3] = {1, -2, 1};
    for (std::size_t c = 1; c + 1 < m; ++c) {
      const Tangent s = increments[c] - increments[c - 1];
      for (std::size_t a = 0; a < 3; ++a)
        evaluation.force[c - 1 + a] -= (lambda * kCoefficient[a]) * s;
      if (!jacobian) continue;
      const IncrementJacobians<G>& before = increment_jacobians[c - 1];  // of Omega_c
      const IncrementJacobians<G>& after = increment_jacobians[c];       // of Omega_{c+1}
      const AdMatrix derivative[3] = {
          before.left_inverse, -(after.left_inverse + before.right_inverse), after.right_inverse};
      for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t l = 0; l < 3; ++l)
          (*jacobian)(c - 1 + a, c - 1 + l).noalias() -= (lambda * kCoefficient[a]) * derivative[l];
    }
  }

  // Why no step reduced |F|, from what the last iterate shows, in this
  // order: residuals near a half turn (the curve cannot follow the data:
  // knots too sparse for the motion, or the data leave the log's domain);
  // a step far larger than the data's spread with fewer than three
  // observations per control point (nearly singular equations: knots too
  // dense for the data); consecutive control points near a half turn apart
  // (a span would have to turn past the increments' principal log), told
  // apart by how far the observations around the span move: about as far
  // as the control points when one cubic segment covers a motion of a few
  // radians (knots too sparse), far less when the control points swing out
  // beyond the data (few or noisy observations where a control point's
  // basis is small, as at the ends: knots too dense), the control points'
  // turn more than 1.5 times the observations' (B-spline control points
  // exceed a smooth motion by less: by 1.5 at a period of four spans); a
  // large step alone.
  template <class Observations>
  std::string no_descent_message(const Observations& observations, const Problem<Scalar>& problem,
                                 const Knots& knots, const std::vector<std::size_t>& order,
                                 const std::vector<Tangent>& residuals,
                                 const std::vector<Element>& points,
                                 const std::vector<Tangent>& step) const {
    constexpr Scalar kHalfTurn = Scalar(3.14159265358979323846);
    std::ptrdiff_t far = -1;
    Scalar farthest = 0;
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      const Scalar radius = ad_spectral_radius<G>(residuals[i]);
      if (radius > farthest) far = static_cast<std::ptrdiff_t>(i), farthest = radius;
    }
    std::string why = "no step along the Gauss-Newton direction reduces |F|: ";
    if (farthest > kHalfTurn / 2) {
      return why + "observation " + std::to_string(far) + " lies " +
             std::to_string(double(farthest)) +
             " rad from the curve (spectral radius of ad of its residual): the knots are too "
             "sparse for the motion, or the data leave the domain of " +
             G::name + "'s log; try a narrower knot spacing";
    }
    Scalar largest = 0;
    for (const Tangent& s : step)
      largest = std::max(largest, s.template lpNorm<Eigen::Infinity>());
    // Fewer than three observations per control point: spans with about
    // one each, where the equations are nearly singular.
    const bool sparse_data = residuals.size() < 3 * points.size();
    const std::string dense = "the equations are nearly singular (proposed step " +
                              std::to_string(double(largest)) + " rad): ";
    if (largest > 1 && sparse_data) {
      return why + dense +
             "the knots are too dense for the data (spans with about one observation); try a "
             "wider knot spacing";
    }
    std::size_t span = 0;
    Scalar widest = 0;
    for (std::size_t j = 1; j < points.size(); ++j) {
      const Scalar turn =
          ad_spectral_radius<G>(G::log(G::compose(G::inverse(points[j - 1]), points[j])));
      if (turn > widest) span = j, widest = turn;
    }
    if (widest > kBeyondDomainAngle<Scalar>) {
      const std::string apart = "control points " + std::to_string(span - 1) + " and " +
                                std::to_string(span) + " are " + std::to_string(double(widest)) +
                                " rad apart, near the half turn where their increment's log "
                                "jumps";
      const Scalar motion = motion_around(observations, problem, knots, order, span);
      if (widest > Scalar(1.5) * motion) {
        return why + apart + ", while the observations around them turn by " +
               std::to_string(double(motion)) +
               " rad: the control points swing out beyond the data, which determine them only "
               "weakly there (at 10 observations per span an end increment of a cubic spreads "
               "by about 14 times the noise per axis, of a quadratic by 3, of a piecewise "
               "geodesic by 0.9); try a lower degree, a roughness penalty or more "
               "observations (wider knots barely help)";
      }
      return why + apart +
             ": the motion within a knot span is too large for the spline's control points; try "
             "a narrower knot spacing";
    }
    if (largest > 1) return why + dense + "try another knot spacing";
    return why + "the largest residual is " + std::to_string(double(farthest)) +
           " rad; the equations have no solution reachable from the start at this knot spacing";
  }

  // How far the observations turn around the span between control points
  // span - 1 and span: the turns (spectral radius of ad of log(f_a^{-1}
  // f_b)) between the observations nearest g_{span-1} - h, g_{span-1},
  // g_span and g_span + h within the data, added, g_c = (c - (k - 1)/2) h
  // the Greville abscissae (chart_start's anchors). Pieces of one span
  // keep each log short of the half turn where it would wrap for any
  // motion the spline can follow; observations of zero weight (out of the
  // fit, perhaps outliers) are passed over. 0 when the pieces meet in one
  // observation.
  template <class Observations>
  Scalar motion_around(const Observations& observations, const Problem<Scalar>& problem,
                       const Knots& knots, const std::vector<std::size_t>& order,
                       std::size_t span) const {
    const auto weighted = [&](std::size_t position) { return problem.w[order[position]] > 0; };
    const auto nearest = [&](Scalar abscissa) {
      const Scalar at = std::clamp(abscissa, Scalar(0), Scalar(1));
      const std::size_t after = static_cast<std::size_t>(
          std::partition_point(order.begin(), order.end(),
                               [&](std::size_t i) { return problem.t[i] < at; }) -
          order.begin());
      std::size_t right = after, left = after;
      while (right < order.size() && !weighted(right))
        ++right;
      while (left > 0 && !weighted(left - 1))
        --left;
      if (left == 0) return order[right];  // fit() has a weighted observation
      if (right == order.size()) return order[left - 1];
      const std::size_t below = order[left - 1], above = order[right];
      return at - problem.t[below] <= problem.t[above] - at ? below : above;
    };
    const Scalar first = Scalar(span - 1) - Scalar(options_.degree - 1) / 2 - 1;
    Scalar motion = 0;
    std::size_t from = nearest(first * knots.h);
    for (int piece = 1; piece <= 3; ++piece) {
      const std::size_t to = nearest((first + Scalar(piece)) * knots.h);
      if (to != from) {
        motion += ad_spectral_radius<G>(
            G::log(G::compose(G::inverse(observations[from]), observations[to])));
      }
      from = to;
    }
    return motion;
  }

  // What fit() and equations() work on, checked: the problem, the pool (from
  // kParallelMinimum observations on), the knots, the observations in
  // covariate order (ties by input position).
  struct Prepared {
    Problem<Scalar> problem;
    std::optional<ChunkPool> pool;
    Knots knots;
    std::vector<std::size_t> order;
  };

  template <class Observations, class Covariates>
  std::optional<Rejection> prepare(const Observations& observations, const Covariates& covariates,
                                   const std::vector<Scalar>& weights,
                                   const std::vector<Element>* start, Prepared& out) const;

  template <class Observations, class Covariates>
  Result run(const Observations& observations, const Covariates& covariates,
             const std::vector<Scalar>& weights, const std::vector<Element>* start) const;

  Options options_;
};

template <class G>
template <class Observations, class Covariates>
std::optional<Rejection> SplineRegression<G>::prepare(const Observations& observations,
                                                      const Covariates& covariates,
                                                      const std::vector<Scalar>& weights,
                                                      const std::vector<Element>* start,
                                                      Prepared& out) const {
  if (auto rejection = validate()) return rejection;
  const std::size_t n = observations.size();
  if (covariates.size() != n) {
    return Rejection{"observations and covariates differ in length (" + std::to_string(n) + " vs " +
                     std::to_string(covariates.size()) + ")"};
  }
  if (n < 2) return Rejection{"need at least 2 observations, got " + std::to_string(n)};
  if (auto rejection = make_problem(covariates, weights, options_.interval, out.problem)) {
    return rejection;
  }
  if (options_.threads > 1 && n >= kParallelMinimum) {
    out.pool.emplace(options_.threads, chunk_count(n, kSplineChunkSize));
  }
  if (auto rejection = check_observations<G>(observations, options_.element_tolerance,
                                             out.pool ? &*out.pool : nullptr)) {
    return rejection;
  }
  if (auto rejection = make_knots(out.problem, out.knots)) return rejection;
  out.order.resize(n);
  std::iota(out.order.begin(), out.order.end(), std::size_t(0));
  const std::vector<Scalar>& t = out.problem.t;
  if (!std::is_sorted(t.begin(), t.end())) {  // a time series usually is: nothing to do
    std::stable_sort(out.order.begin(), out.order.end(),
                     [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
  }
  if (auto rejection = check_schoenberg_whitney(out.problem, out.order, out.knots)) {
    return rejection;
  }
  if (start) {
    if (start->size() != out.knots.control_points) {
      return Rejection{"got " + std::to_string(start->size()) + " control points; the knots need " +
                       std::to_string(out.knots.control_points)};
    }
    for (std::size_t c = 0; c < start->size(); ++c) {
      if (!G::is_element((*start)[c], options_.element_tolerance)) {
        return Rejection{"control point " + std::to_string(c) + " is not an element of " + G::name};
      }
    }
  }
  return std::nullopt;
}

template <class G>
template <class Observations, class Covariates>
typename SplineRegression<G>::Result SplineRegression<G>::run(
    const Observations& observations, const Covariates& covariates,
    const std::vector<Scalar>& weights, const std::vector<Element>* start) const {
  // 1. The problem, the knots, Schoenberg-Whitney, the start's size.
  Prepared prepared;
  if (auto rejection = prepare(observations, covariates, weights, start, prepared)) {
    return rejected(*rejection);
  }
  const std::size_t n = observations.size();
  const Problem<Scalar>& problem = prepared.problem;
  const Knots& knots = prepared.knots;
  ChunkPool* const chunk_pool = prepared.pool ? &*prepared.pool : nullptr;

  // 2. The start.
  Scratch scratch(problem, knots, std::move(prepared.order), options_.degree, chunk_pool);
  std::vector<Element> points = start ? *start : chart_start(observations, problem, knots, scratch);

  // 3. Gauss-Newton with backtracking.
  Result result;
  result.roughness_penalty = options_.roughness_penalty;
  result.residuals.resize(n);
  BlockBandedMatrix<AdMatrix, Tangent> jacobian(knots.control_points, std::size_t(options_.degree));
  Evaluation current(knots.control_points), next(knots.control_points);
  evaluate(observations, problem, knots, points, result.residuals, &jacobian, scratch, current);
  result.jacobian_evaluations = 1;
  if (!current.finite) {
    return rejected(
        {"the estimating equations are not finite at the start: consecutive control "
         "points or residuals leave the domain of " +
         std::string(G::name) + "'s log"});
  }
  std::vector<Tangent> step(knots.control_points), trial_residuals(n);
  std::vector<Element> trial(knots.control_points);
  result.status = Status::max_iterations;
  constexpr int kHalvings = 30;
  // K is reused while it still contracts (docs/splines.md §9, "Reusing
  // K"): `assembled_here` says whether the factors are K's at `points`;
  // a step from older factors is taken only if its norm is at most
  // jacobian_reuse_contraction times the last step taken, and otherwise
  // K is assembled at `points` and the step recomputed (after which K is
  // assembled with every step). The decisions depend on the steps' norms
  // alone, so the bits still do not depend on the thread count.
  const Scalar reuse_contraction = options_.jacobian_reuse_contraction;
  bool factored = false, assembled_here = true, reuse = reuse_contraction > 0;
  Scalar previous_norm = 0;  // the last step taken, as taken (0: none yet)
  const auto assemble_here = [&] {
    evaluate(observations, problem, knots, points, result.residuals, &jacobian, scratch, current);
    ++result.jacobian_evaluations;
    factored = false;
    assembled_here = true;
  };
  while (result.iterations < options_.max_iterations) {
    if (!factored && !(factored = jacobian.factorize(chunk_pool))) {
      result.status = Status::no_descent;
      result.message = "the Gauss-Newton matrix is singular at the current control points";
      break;
    }
    for (std::size_t c = 0; c < step.size(); ++c)
      step[c] = -current.force[c];
    const bool solved = jacobian.substitute(step, chunk_pool);
    Scalar norm = 0;
    for (const Tangent& s : step)
      norm = std::max(norm, s.template lpNorm<Eigen::Infinity>());
    const bool contracts = solved && norm <= reuse_contraction * previous_norm;
    if (!assembled_here && !contracts) {
      reuse = false;
      assemble_here();
      continue;
    }
    if (!solved) {
      result.status = Status::no_descent;
      result.message = "the Gauss-Newton step is not finite at the current control points";
      break;
    }
    ++result.iterations;
    result.step_norms.push_back(norm);
    if (norm <= options_.tolerance) {
      result.status = Status::converged;
      break;
    }
    bool accepted = false;
    Scalar scale = 1, taken = 0;
    for (int halving = 0; halving <= kHalvings && !accepted; ++halving, scale /= 2) {
      run_ranges(chunk_pool, points.size(), kControlPointPiece,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t c = begin; c < end; ++c)
                     trial[c] = G::compose(points[c], G::exp(scale * step[c]));
                 });
      // The full step's trial assembles K as it goes unless this K is to
      // be reused there; a halved one only F, and K is assembled once it
      // is taken. The trial's K overwrites the factors in place: the step
      // is already solved, and if the trial is refused a halved one
      // needs no K (with_jacobian implies assembled_here, so no retry
      // from these factors follows), which spares a second K of
      // M (2k + 1) blocks, copied and page-faulted serially.
      const bool full_step = halving == 0;
      const bool with_jacobian = full_step && !(reuse && contracts);
      evaluate(observations, problem, knots, trial, trial_residuals,
               with_jacobian ? &jacobian : nullptr, scratch, next);
      result.jacobian_evaluations += with_jacobian;
      if (with_jacobian) factored = false;
      if (next.finite && next.merit < current.merit) {
        accepted = true;
        taken = scale * norm;
        points.swap(trial);
        result.residuals.swap(trial_residuals);
        std::swap(current, next);
        if (with_jacobian) {
          assembled_here = true;
        } else if (full_step) {
          assembled_here = false;
        } else {
          assemble_here();
        }
      } else if (!assembled_here) {
        break;  // not halved: older factors are not trusted that far
      }
    }
    if (!accepted && !assembled_here) {
      // Older factors may point nowhere useful: retry from K at `points`.
      reuse = false;
      assemble_here();
      continue;
    }
    if (!accepted) {
      // No step reduces |F|: at the rounding floor when the step is at the
      // data's precision, otherwise outside the estimator's domain.
      const bool floor = norm <= std::sqrt(std::numeric_limits<Scalar>::epsilon());
      result.status = floor ? Status::rounding_floor : Status::no_descent;
      if (!floor)
        result.message = no_descent_message(observations, problem, knots, scratch.order,
                                            result.residuals, points, step);
      break;
    }
    previous_norm = taken;
  }
  for (const Tangent& f : current.force)
    result.equation_norm = std::max(result.equation_norm, f.norm());
  using Wide = CovariateScalar<Scalar>;
  const Wide h = (problem.t_max - problem.t_min) / Wide(knots.segments);
  result.spline = Spline<G>(options_.degree, static_cast<Scalar>(problem.t_min),
                            static_cast<Scalar>(h), std::move(points));
  if constexpr (provides_v<G, capability_detail::ad_spectral_radius>) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!(problem.w[i] > 0)) continue;  // a zero weight takes the observation out of the fit
      const Scalar angle = G::ad_spectral_radius(result.residuals[i]);
      if (angle > result.largest_residual_angle) {
        result.largest_residual_angle = angle;
        result.largest_residual_observation = static_cast<std::ptrdiff_t>(i);
      }
    }
    const std::vector<Tangent>& increments = result.spline->increments();
    for (std::size_t j = 0; j < increments.size(); ++j) {
      const Scalar angle = G::ad_spectral_radius(increments[j]);
      if (angle > result.largest_increment_angle) {
        result.largest_increment_angle = angle;
        result.largest_increment = static_cast<std::ptrdiff_t>(j + 1);
      }
    }
    result.beyond_domain = result.largest_residual_angle > kBeyondDomainAngle<Scalar> ||
                           result.largest_increment_angle > kBeyondDomainAngle<Scalar>;
  }
  return result;
}

}  // namespace bireg
