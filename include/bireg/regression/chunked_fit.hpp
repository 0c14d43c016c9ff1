// bireg: one fit whose observations live in chunks elsewhere (on the
// workers of a Dask cluster, the ranks of an MPI job), driven from one
// place. The fit of regression.hpp passes over its observations in five
// ways, each a sum over observations that chunks can compute separately:
//
//   survey     the covariates' range, the largest weight, and the first
//              covariate, weight or observation that is invalid;
//   design     H of Lemma 3.7, the observation nearest the middle
//              covariate, and the moments of the Gauss-Newton matrix K;
//   chart      the least-squares line in the log chart at that observation
//              (start.hpp);
//   force      the net force (v0, v1) at given endpoints
//              (estimating_equations.hpp), once per evaluation of the
//              iteration;
//   residuals  sum w |r_i|^2 and the largest residual angle at the
//              returned endpoints (diagnostics.hpp).
//
// chunk_sums(request, chunk) computes what the request's pass needs over
// one chunk, with the same per-observation functions that fit() uses;
// ChunkSums::add joins two chunks' sums (sums add, the first invalid
// observation is the one with the smaller index, in either order).
// fit_by_chunks(options, reduce) runs fit()'s steps, asking `reduce` for
// the sums over all chunks whenever fit() would pass over its
// observations: reduce(request) must return the chunk_sums of every chunk
// joined by add, in an order fixed by the caller (MPI: a reduction with
// add as a non-commutative operation; bireg.dask: the chunks in order).
// The result equals fit()'s on the same observations except for the
// summation order, i.e. to a few units of rounding relative to the
// sums' magnitudes (tests/test_chunked_fit.cpp: 1e-12), with one
// difference: the residuals stay with the chunks (result.residuals is
// empty). Observation indices in messages are global: a chunk's
// observation i is named offset + i.
//
// A transport moves requests and sums as numbers (to_numbers,
// from_numbers): doubles, in a fixed order, exact for float and double,
// for groups whose elements and tangents are Eigen matrices (not the
// product groups of groups/product.hpp, whose elements are pairs).
// The chunks must hold the same observations at every pass: a lazily
// computed chunk must be computed the same way each time.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "bireg/regression.hpp"

namespace bireg {

enum class ChunkPass { survey, design, chart, force, residuals };

// What a pass asks of each chunk.
template <class G>
struct ChunkRequest {
  using Scalar = typename G::Scalar;
  using Wide = CovariateScalar<Scalar>;
  ChunkPass pass = ChunkPass::survey;
  Scalar element_tolerance = 0;
  bool has_interval = false;  // survey: check the covariates against [low, high]
  Wide interval_low = 0, interval_high = 1;
  CovariateFrame<Scalar> frame;  // design and later: the map onto the unit interval
  PsiEvaluation psi;             // force, residuals
  // chart: g0 is the middle observation (the chart's reference);
  // force, residuals: the endpoints.
  typename G::Element g0 = G::identity(), g1 = G::identity();

  // Whether a request that came through a transport is one fit_by_chunks
  // can send: a pass, a method and series orders within validate_options'
  // bounds (a worker must not run a series of 2e9 terms), finite numbers.
  bool valid() const {
    using std::isfinite;
    const auto pass_value = static_cast<int>(pass);
    const auto method_value = static_cast<int>(psi.method);
    return pass_value >= static_cast<int>(ChunkPass::survey) &&
           pass_value <= static_cast<int>(ChunkPass::residuals) &&
           method_value >= static_cast<int>(Method::series) &&
           method_value <= static_cast<int>(Method::exact) && psi.series_order >= 0 &&
           psi.series_order <= kMaxSeriesOrder && psi.max_series_order >= 1 &&
           psi.max_series_order <= kMaxSeriesOrder && element_tolerance >= 0 &&
           isfinite(frame.t_min) && isfinite(frame.t_max) && isfinite(frame.largest_weight) &&
           g0.allFinite() && g1.allFinite();
  }

  std::optional<std::pair<Wide, Wide>> interval() const {
    if (!has_interval) return std::nullopt;
    return std::make_pair(interval_low, interval_high);
  }

  // Calls f on every number, in the transport's order.
  template <class Self, class F>
  static void for_each_number(Self& self, F&& f) {
    f(self.pass);
    f(self.element_tolerance);
    f(self.has_interval);
    f(self.interval_low);
    f(self.interval_high);
    f(self.frame.t_min);
    f(self.frame.t_max);
    f(self.frame.largest_weight);
    f(self.psi.method);
    f(self.psi.series_order);
    f(self.psi.max_series_order);
    f(self.psi.batched);
    f(self.g0);
    f(self.g1);
  }
};

// Everything the passes sum over a chunk; each pass fills its part and
// leaves the others at their neutral values.
template <class G>
struct ChunkSums {
  using Scalar = typename G::Scalar;
  bool weighted = false;                                   // survey: the chunk has weights
  CovariateSurvey<Scalar> covariates;                      // survey
  ObservationFinding observations;                         // survey
  DesignSums<Scalar> design;                               // design
  MiddleCandidate<G> middle;                               // design
  GaussNewtonMoments<Scalar> moments;                      // design
  ChartSums<G> chart;                                      // chart
  Force<G> force{G::Tangent::Zero(), G::Tangent::Zero()};  // force
  ResidualSums<G> residuals;                               // residuals

  void add(const ChunkSums& other) {
    weighted = weighted || other.weighted;
    covariates.add(other.covariates);
    observations.add(other.observations);
    design.add(other.design);
    middle.add(other.middle);
    moments.add(other.moments);
    chart.add(other.chart);
    force.v0 += other.force.v0;
    force.v1 += other.force.v1;
    residuals.add(other.residuals);
  }

  template <class Self, class F>
  static void for_each_number(Self& self, F&& f) {
    f(self.weighted);
    f(self.covariates.count);
    f(self.covariates.smallest);
    f(self.covariates.largest);
    f(self.covariates.largest_weight);
    f(self.covariates.bad_covariate);
    f(self.covariates.bad_weight);
    f(self.covariates.outside_interval);
    f(self.observations.index);
    f(self.observations.finite);
    f(self.design.a);
    f(self.design.b);
    f(self.design.c);
    f(self.design.weight_sum);
    f(self.middle.index);
    f(self.middle.distance);
    f(self.middle.element);
    for (auto& row : self.moments.s)
      for (auto& moment : row)
        f(moment);
    f(self.chart.moment0);
    f(self.chart.moment1);
    f(self.chart.square_sum);
    f(self.chart.outside_index);
    f(self.chart.outside_finite);
    f(self.force.v0);
    f(self.force.v1);
    f(self.residuals.residual_sum);
    f(self.residuals.largest_angle);
    f(self.residuals.largest_observation);
    f(self.residuals.not_finite);
  }
};

namespace chunked_detail {

// Elements [begin, begin + size) of an indexable container, indexed from 0.
template <class Container>
class Slice {
 public:
  Slice(const Container& container, std::size_t begin, std::size_t size)
      : container_(&container), begin_(begin), size_(size) {}
  std::size_t size() const { return size_; }
  decltype(auto) operator[](std::size_t i) const { return (*container_)[begin_ + i]; }

 private:
  const Container* container_;
  std::size_t begin_, size_;
};

// The request's pass over one slice of a chunk (the whole set's
// observations offset + i), into `sums`; `problem` and `residuals` are
// the caller's buffers, reused from slice to slice.
template <class G, class Observations, class Covariates>
void add_slice_sums(const ChunkRequest<G>& request, const Observations& observations,
                    const Covariates& covariates, const typename G::Scalar* weights,
                    std::size_t offset, Problem<typename G::Scalar>& problem,
                    std::vector<typename G::Tangent>& residuals, ChunkSums<G>& sums) {
  using Scalar = typename G::Scalar;
  const std::size_t n = observations.size();
  ChunkSums<G> slice;
  if (request.pass == ChunkPass::survey) {
    slice.covariates =
        CovariateSurvey<Scalar>::over(covariates, weights, request.interval(), 0, n, offset);
    slice.observations =
        ObservationFinding::over<G>(observations, request.element_tolerance, 0, n, offset);
    sums.add(slice);
    return;
  }
  normalise_covariates(covariates, weights, request.frame, problem);
  switch (request.pass) {
    case ChunkPass::design:
      slice.design = DesignSums<Scalar>::over(problem);
      slice.middle = MiddleCandidate<G>::over(observations, problem, 0, n, offset);
      slice.moments = GaussNewtonMoments<Scalar>::over(problem, 0, n);
      break;
    case ChunkPass::chart:
      slice.chart = ChartSums<G>::over(observations, problem, G::inverse(request.g0), 0, n, offset);
      break;
    case ChunkPass::force:
    case ChunkPass::residuals: {
      residuals.resize(n);
      const State<G> state =
          evaluate<G>(observations, problem, request.psi, request.g0, request.g1, residuals);
      if (request.pass == ChunkPass::force) {
        if (state.series_converges) slice.force = state.force;
        break;
      }
      if (!state.series_converges)  // no force was evaluated there: residuals alone
        residuals_alone<G>(observations, problem, state, residuals);
      slice.residuals = ResidualSums<G>::over(problem, residuals, 0, n, offset);
      break;
    }
    case ChunkPass::survey:
      break;
  }
  sums.add(slice);
}

}  // namespace chunked_detail

// The request's pass over one chunk: observations[i], covariates[i] and
// weights[i] (weights empty: all 1; the chunks of one fit either all have
// weights or none has) are the whole set's observation offset + i. The
// sizes must agree (the caller checks; a mismatch is a programming error).
// The chunk is worked through in slices of kChunkSize observations, so
// that the memory it needs beyond the chunk itself is a slice's (a
// residual and two numbers per observation), whatever the chunk's size.
template <class G, class Observations, class Covariates>
ChunkSums<G> chunk_sums(const ChunkRequest<G>& request, const Observations& observations,
                        const Covariates& covariates,
                        const std::vector<typename G::Scalar>& weights, std::size_t offset) {
  using chunked_detail::Slice;
  const std::size_t n = observations.size();
  ChunkSums<G> sums;
  sums.weighted = request.pass == ChunkPass::survey && !weights.empty();
  Problem<typename G::Scalar> problem;
  std::vector<typename G::Tangent> residuals;
  for (std::size_t begin = 0; begin < n; begin += kChunkSize) {
    const std::size_t size = std::min(kChunkSize, n - begin);
    chunked_detail::add_slice_sums<G>(request, Slice<Observations>(observations, begin, size),
                                      Slice<Covariates>(covariates, begin, size),
                                      weights.empty() ? nullptr : weights.data() + begin,
                                      offset + begin, problem, residuals, sums);
  }
  return sums;
}

namespace chunked_detail {

template <class T, class = void>
struct IsEigen : std::false_type {};
template <class T>
struct IsEigen<
    T, std::void_t<decltype(std::declval<T&>().data()), decltype(std::declval<T&>().size())>>
    : std::true_type {};

// Calls number(x) for x itself, or for each coefficient of an Eigen object.
template <class T, class Number>
void each(T& x, Number&& number) {
  if constexpr (IsEigen<std::remove_const_t<T>>::value) {
    for (Eigen::Index k = 0; k < x.size(); ++k)
      number(x.data()[k]);
  } else {
    number(x);
  }
}

// The integer type of T's values: T itself, or an enumeration's
// underlying type.
template <class T, bool = std::is_enum_v<T>>
struct IntegerOf {
  using type = T;
};
template <class T>
struct IntegerOf<T, true> {
  using type = std::underlying_type_t<T>;
};

// A number as a double, and back (enumerations by their value). Back
// refuses (false) what the type cannot hold: a bool other than 0 or 1, an
// integer or enumeration value that is not an integer in the type's range
// (a cast from such a double is undefined behaviour); floating-point
// fields take any value.
template <class T>
double as_double(const T& x) {
  if constexpr (std::is_enum_v<T>) {
    return static_cast<double>(static_cast<std::underlying_type_t<T>>(x));
  } else {
    return static_cast<double>(x);
  }
}
template <class T>
bool from_double(double x, T& out) {
  if constexpr (std::is_same_v<T, bool>) {
    if (x != 0 && x != 1) return false;
    out = x == 1;
  } else if constexpr (std::is_enum_v<T> || std::is_integral_v<T>) {
    using I = typename IntegerOf<T>::type;
    // 2^53: every integer below is exact in a double, and fits in 64 bits.
    constexpr double kExact = 9007199254740992.0;
    const double low = std::max(double(std::numeric_limits<I>::min()), -kExact);
    const double high = std::min(double(std::numeric_limits<I>::max()), kExact);
    if (!(x >= low && x <= high) || x != std::floor(x)) return false;
    out = static_cast<T>(static_cast<I>(x));
  } else {
    out = static_cast<T>(x);
  }
  return true;
}

template <class T, class = void>
struct HasValid : std::false_type {};
template <class T>
struct HasValid<T, std::void_t<decltype(std::declval<const T&>().valid())>> : std::true_type {};

}  // namespace chunked_detail

// A request's or sums' numbers, in for_each_number's order.
template <class Record>
std::vector<double> to_numbers(const Record& record) {
  std::vector<double> numbers;
  Record::for_each_number(record, [&](const auto& field) {
    chunked_detail::each(field,
                         [&](const auto& x) { numbers.push_back(chunked_detail::as_double(x)); });
  });
  return numbers;
}

// The record of to_numbers' numbers; nothing when their count is not the
// record's (another version of bireg wrote them), when a number does not
// fit its field (chunked_detail::from_double), or for a request that is
// not valid(). Numbers from a network are checked before any use.
template <class Record>
std::optional<Record> from_numbers(const double* numbers, std::size_t count) {
  Record record;
  std::size_t k = 0;
  bool fits = true;
  Record::for_each_number(record, [&](auto& field) {
    chunked_detail::each(field, [&](auto& x) {
      if (k < count) fits = chunked_detail::from_double(numbers[k], x) && fits;
      ++k;
    });
  });
  if (k != count || !fits) return std::nullopt;
  if constexpr (chunked_detail::HasValid<Record>::value) {
    if (!record.valid()) return std::nullopt;
  }
  return record;
}

// The observations of a chunked fit as iterate() sees them: none here
// (size 0: iterate keeps no residuals), every evaluation of the force a
// request to `reduce`. iterate() calls evaluate<G>(observations, ...),
// found by argument-dependent lookup: the overload below.
template <class G, class Reduce>
struct ChunkedObservations {
  Reduce* reduce;
  ChunkRequest<G> request;  // the frame and psi of every force request
  std::size_t size() const { return 0; }
};

template <class G, class Reduce>
State<G> evaluate(const ChunkedObservations<G, Reduce>& observations,
                  const Problem<typename G::Scalar>&, const PsiEvaluation& psi,
                  const typename G::Element& g0, const typename G::Element& g1,
                  std::vector<typename G::Tangent>&, ForceWorkspace<G>* = nullptr) {
  bool closed_form = false;
  State<G> state = prepare_state<G>(psi, g0, g1, closed_form);
  if (!state.series_converges) return state;
  ChunkRequest<G> request = observations.request;
  request.pass = ChunkPass::force;
  request.g0 = g0;
  request.g1 = g1;
  state.force = (*observations.reduce)(request).force;
  return state;
}

// fit()'s steps (regression.hpp) on observations held in chunks, summed by
// `reduce` (a callable ChunkSums<G>(const ChunkRequest<G>&), see above).
// options.threads is not used here: the chunks' owners choose their
// parallelism. Never throws for bad input; what `reduce` throws (a lost
// connection) passes through.
template <class G, class Reduce>
RegressionResult<G> fit_by_chunks(const RegressionOptions<typename G::Scalar>& options,
                                  Reduce& reduce) {
  using Scalar = typename G::Scalar;
  using Result = RegressionResult<G>;
  if (auto rejection = validate_options(options)) return rejected_result<G>(*rejection);
  ChunkRequest<G> request;
  request.element_tolerance = options.element_tolerance;
  if (options.interval) {
    request.has_interval = true;
    std::tie(request.interval_low, request.interval_high) = *options.interval;
  }
  request.psi = options.psi();

  // 1. The problem: the survey's checks in fit()'s order.
  request.pass = ChunkPass::survey;
  const ChunkSums<G> survey = reduce(request);
  const std::size_t n = survey.covariates.count;
  if (n < 2) return rejected_result<G>({"need at least 2 observations, got " + std::to_string(n)});
  if (auto rejection =
          covariate_frame(survey.covariates, survey.weighted, options.interval, request.frame)) {
    return rejected_result<G>(*rejection);
  }
  request.pass = ChunkPass::design;
  const ChunkSums<G> design = reduce(request);
  Problem<Scalar> problem;  // H and the frame; the covariates stay with the chunks
  problem.t_min = request.frame.t_min;
  problem.t_max = request.frame.t_max;
  if (auto rejection = set_design(design.design, problem)) return rejected_result<G>(*rejection);
  if (auto rejection = observation_rejection<G>(survey.observations, options.element_tolerance)) {
    return rejected_result<G>(*rejection);
  }

  // 2. The start.
  request.pass = ChunkPass::chart;
  request.g0 = design.middle.element;
  const ChartStart<G> chart =
      chart_from_sums<G>(design.middle.element, problem, reduce(request).chart);
  if (auto rejection = chart_rejection<G>(chart)) return rejected_result<G>(*rejection);

  // 3. The iteration, each evaluation a force request; 4. the diagnostics.
  const ChunkedObservations<G, Reduce> observations{&reduce, request};
  const auto iterate_and_diagnose = [&](const StepRuleView<G>& rule) {
    const IterationControl<Scalar> control{options.tolerance, options.max_iterations,
                                           options.record_iterates};
    Result result;
    IterationRecord<G> record;
    const State<G> state = iterate<G>(observations, problem, request.psi, rule, control, chart.g0,
                                      chart.g1, chart.reference, result.residuals, record);
    request.pass = ChunkPass::residuals;
    request.g0 = state.g0;
    request.g1 = state.g1;
    const ResidualSums<G> residual_sums = reduce(request).residuals;
    if (state.series_converges && !state.usable()) {
      return rejected_result<G>(unevaluable_start<G>(residual_sums.not_finite));
    }
    if (state.series_converges) {
      result.jacobian = GaussNewtonStep<G>(problem, design.moments).matrix(state.a);
    }
    fill_result<G>(
        result, problem, state, record,
        diagnose_from_sums<G>(problem, rule, record, state, chart.spread, residual_sums));
    return result;
  };
  return with_step_rule_view<G>(
      options.solver, problem, options.step_size,
      [&] { return GaussNewtonStep<G>(problem, design.moments); }, rejected_result<G>,
      iterate_and_diagnose);
}

}  // namespace bireg
