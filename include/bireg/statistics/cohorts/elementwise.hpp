// bireg: element-wise two-sample maps (docs/cohorts.md, "Element-wise
// maps"). Each subject is K elements of G sharing one index k (a shape as K
// per-triangle deformation gradients, a skeleton as K joint rotations);
// each k gets the two-sample statistic of two_sample.hpp and its p-value,
// all from the same relabellings of the subjects, with Benjamini-Hochberg
// q-values and Westfall-Young max-statistic family-wise p-values.
//
// Modes. exact: each relabelling recomputes both means at every k
// (two_sample.hpp's computation, k by k). linearised: the coordinates
// z_i = log(p_k^{-1} e_ik) at element k's pooled mean p_k are computed once
// and every relabelling's means, covariances and difference are those of
// the z in that chart (c = mean_B z - mean_A z, no transport): a Euclidean
// two-sample statistic of fixed coordinates. Both are permutation tests of
// exchangeability, exact at any K; both are invariant under left and right
// translation, inversion and exchange (for the linearised mode all z move
// by one matrix: I, Ad(h^{-1}) or -Ad(p_k); docs/cohorts.md).
//
// Memory is O(K + B + (m + n) K) for the data and the results: per
// relabelling only the maximum over k is kept, not K x B statistics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/regression/parallel.hpp"
#include "bireg/regression/status.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"

namespace bireg {

enum class ElementwiseMode { exact, linearised };

inline const char* to_string(ElementwiseMode mode) {
  switch (mode) {
    case ElementwiseMode::exact:
      return "exact";
    case ElementwiseMode::linearised:
      return "linearised";
  }
  return "unknown";
}

template <class Scalar>
struct ElementwiseOptions {
  TwoSampleOptions<Scalar> test;  // statistic, variant (exact mode), permutations, seed, threads
  ElementwiseMode mode = ElementwiseMode::linearised;
  // The index of element 0 in a larger map when a slice of the elements is
  // tested apart (combine_elementwise): bad_element and messages use it.
  std::size_t first_element = 0;
};

template <class G>
struct ElementwiseResult {
  using Scalar = typename G::Scalar;
  // converged: every element was tested; invalid_input: refused (message);
  // another status: the mean of element `bad_element` failed (message).
  Status status = Status::invalid_input;
  std::string message;
  std::ptrdiff_t bad_element = -1;
  std::size_t elements = 0;  // K
  int permutations = 0;
  std::vector<Scalar> value;    // per element: T^2, D_B or H^2
  std::vector<Scalar> p_value;  // per element, (1 + #{b : T_kb >= T_k}) / (B + 1)
  std::vector<Scalar> q_value;  // Benjamini-Hochberg over the K p-values
  std::vector<Scalar> p_fwer;   // (1 + #{b : max_j T_jb >= T_k}) / (B + 1)
  int failed_permutations = 0;  // (element, relabelling) pairs without a statistic
  // What combine_elementwise needs to join slices of elements: T_k on the
  // ranking scale (D_B where the statistic is H^2), and max_k T_kb per
  // relabelling b (failed statistics count as +inf).
  std::vector<Scalar> ranked_value;
  std::vector<Scalar> relabelling_maximum;
  // What the slices of one map must share (combine_elementwise checks).
  TwoSampleStatistic statistic = TwoSampleStatistic::hotelling;
  ElementwiseMode mode = ElementwiseMode::linearised;
  std::uint64_t seed = 0;

  bool ok() const { return is_success(status); }
};

namespace elementwise_detail {

// Benjamini-Hochberg adjusted p-values: q_(i) = min over j >= i of
// p_(j) K / j, at most 1, in the input order.
template <class Scalar>
std::vector<Scalar> benjamini_hochberg(const std::vector<Scalar>& p) {
  const std::size_t k = p.size();
  std::vector<std::size_t> order(k);
  for (std::size_t i = 0; i < k; ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return p[a] < p[b]; });
  std::vector<Scalar> q(k);
  Scalar running = 1;
  for (std::size_t r = k; r-- > 0;) {
    const Scalar candidate = p[order[r]] * Scalar(k) / Scalar(r + 1);
    running = std::min(running, candidate);
    q[order[r]] = running;
  }
  return q;
}

// The family-wise p-values and the q-values, from T_k (ranked), max_k T_kb
// and the per-element p-values: the one step that needs every element.
// #{b : max_k T_kb >= threshold} by binary search in the sorted maxima:
// O((B + K) log B), not K B comparisons (K = 1e5, B = 1e4 would be 1e9).
template <class G>
void adjust_for_multiplicity(ElementwiseResult<G>& result) {
  using Scalar = typename G::Scalar;
  const std::size_t elements = result.ranked_value.size();
  std::vector<Scalar> sorted = result.relabelling_maximum;
  std::sort(sorted.begin(), sorted.end());
  const Scalar denominator = Scalar(sorted.size() + 1);
  result.p_fwer.assign(elements, 1);
  for (std::size_t k = 0; k < elements; ++k) {
    const Scalar threshold = result.ranked_value[k] * (1 - two_sample_detail::kTie<Scalar>);
    const auto beyond = sorted.end() - std::lower_bound(sorted.begin(), sorted.end(), threshold);
    result.p_fwer[k] = Scalar(1 + beyond) / denominator;
  }
  result.q_value = benjamini_hochberg(result.p_value);
}

// The linearised statistic of one split of fixed coordinates z (the first
// m of `index` in A): means, covariances (divisors m and n) and c in the
// pooled chart. `totals` holds sum z and sum z z^T over all m + n.
template <class G>
std::optional<typename G::Scalar> linearised(TwoSampleStatistic statistic,
                                             const std::vector<typename G::Tangent>& z,
                                             const std::size_t* index, std::size_t m, std::size_t n,
                                             const typename G::Tangent& sum_all,
                                             const typename G::AdMatrix& outer_all) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  Tangent sum_a = Tangent::Zero();
  AdMatrix outer_a = AdMatrix::Zero();
  for (std::size_t i = 0; i < m; ++i) {
    const Tangent& x = z[index[i]];
    sum_a += x;
    outer_a.noalias() += x * x.transpose();
  }
  const Scalar sm = Scalar(m), sn = Scalar(n);
  const Tangent mean_a = sum_a / sm, mean_b = (sum_all - sum_a) / sn;
  const AdMatrix s_a = outer_a / sm - mean_a * mean_a.transpose();
  const AdMatrix s_b = (outer_all - outer_a) / sn - mean_b * mean_b.transpose();
  return two_sample_detail::statistic<G>(statistic, m, n, s_a, s_b, Tangent(mean_b - mean_a));
}

}  // namespace elementwise_detail

// Element-wise tests of `a` (m subjects x K elements, subject-major: a[i K
// + k] is subject i's element k) against `b` (n x K). Never throws for bad
// data, never returns NaN.
template <class G, class SampleA, class SampleB>
ElementwiseResult<G> elementwise_two_sample_test(
    const SampleA& a, std::size_t m, const SampleB& b, std::size_t n, std::size_t elements,
    const ElementwiseOptions<typename G::Scalar>& options = {}) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  ElementwiseResult<G> result;
  result.elements = elements;
  const TwoSampleOptions<Scalar>& test = options.test;
  const int mode = static_cast<int>(options.mode);
  if (mode < 0 || mode > static_cast<int>(ElementwiseMode::linearised)) {
    result.message = "mode " + std::to_string(mode) + " is not an ElementwiseMode";
    return result;
  }
  if (elements == 0) {
    result.message = "K, the number of elements per subject, must be at least 1";
    return result;
  }
  if (a.size() != m * elements || b.size() != n * elements) {
    result.message =
        "the samples hold " + std::to_string(a.size()) + " and " + std::to_string(b.size()) +
        " elements, not m K = " + std::to_string(m * elements) +
        " and n K = " + std::to_string(n * elements) + " (K = " + std::to_string(elements) + ")";
    return result;
  }
  result.message = two_sample_detail::refusal<G>(
      m, n, test,
      "m = " + std::to_string(m) + " and n = " + std::to_string(n) + " subjects of " +
          std::to_string(elements) + " elements of " + G::name + " (dimension " +
          std::to_string(G::dof) + ")");
  if (!result.message.empty()) return result;
  const std::size_t count = static_cast<std::size_t>(test.permutations);
  const std::size_t total = m + n;
  // The relabellings, shared by every element.
  std::vector<std::size_t> orders(count * total);
  {
    std::vector<std::size_t> order;
    for (std::size_t r = 0; r < count; ++r) {
      permutation(test.seed, test.first_permutation + r, total, order);
      std::copy(order.begin(), order.end(),
                orders.begin() + static_cast<std::ptrdiff_t>(r * total));
    }
  }
  std::vector<std::size_t> identity(total);
  for (std::size_t i = 0; i < total; ++i)
    identity[i] = i;
  const TwoSampleStatistic ranking = test.statistic == TwoSampleStatistic::hellinger
                                         ? TwoSampleStatistic::bhattacharyya
                                         : test.statistic;
  TwoSampleOptions<Scalar> ranking_options = test;
  ranking_options.statistic = ranking;

  result.value.assign(elements, 0);
  result.p_value.assign(elements, 1);
  std::vector<Scalar> observed(elements, 0);
  std::vector<int> extreme(elements, 0);
  std::vector<char> element_ok(elements, 0);
  std::vector<Status> element_status(elements, Status::converged);
  std::vector<std::string> element_message(elements);
  // max over k of T_kb, per relabelling (failed statistics count as +inf).
  std::vector<Scalar> maximum(count, -std::numeric_limits<Scalar>::infinity());
  std::mutex merge;
  int failed = 0;

  constexpr std::size_t kElementsPerTask = 8;
  const std::size_t tasks = chunk_count(elements, kElementsPerTask);
  const auto run_task = [&](std::size_t task) {
    std::vector<Scalar> local_maximum(count, -std::numeric_limits<Scalar>::infinity());
    int local_failed = 0;
    two_sample_detail::Pooled<G> pooled;
    pooled.elements.resize(total);
    two_sample_detail::Split<G> split;
    split.y_a.reserve(m);
    split.y_b.reserve(n);
    const std::size_t end = std::min(elements, (task + 1) * kElementsPerTask);
    for (std::size_t k = task * kElementsPerTask; k < end; ++k) {
      for (std::size_t i = 0; i < m; ++i)
        pooled.elements[i] = a[i * elements + k];
      for (std::size_t j = 0; j < n; ++j)
        pooled.elements[m + j] = b[j * elements + k];
      const MeanResult<G> pooled_mean = mean<G>(pooled.elements, {}, test.mean);
      if (!pooled_mean.ok()) {
        element_status[k] = pooled_mean.status;
        element_message[k] = pooled_mean.message;
        continue;
      }
      pooled.mean = *pooled_mean.mean;
      pooled.z = pooled_mean.residuals;
      Tangent sum_all = Tangent::Zero();
      AdMatrix outer_all = AdMatrix::Zero();
      if (options.mode == ElementwiseMode::exact) {
        pooled.jacobian.clear();
        for (const auto& z : pooled.z)
          pooled.jacobian.push_back(right_jacobian_inverse<G>(-z));
      } else {
        for (const auto& z : pooled.z) {
          sum_all += z;
          outer_all.noalias() += z * z.transpose();
        }
      }
      const auto statistic_of = [&](const std::size_t* index) -> std::optional<Scalar> {
        if (options.mode == ElementwiseMode::linearised) {
          return elementwise_detail::linearised<G>(ranking, pooled.z, index, m, n, sum_all,
                                                   outer_all);
        }
        two_sample_detail::evaluate<G>(pooled, index, m, n, ranking_options, split);
        return split.value;
      };
      const std::optional<Scalar> value = statistic_of(identity.data());
      if (!value || !std::isfinite(*value)) {
        element_status[k] = Status::invalid_input;
        element_message[k] = "its covariance is singular or its means lie beyond the log's domain";
        continue;
      }
      observed[k] = *value;
      element_ok[k] = 1;
      const Scalar threshold = *value * (1 - two_sample_detail::kTie<Scalar>);
      for (std::size_t r = 0; r < count; ++r) {
        const std::optional<Scalar> t = statistic_of(orders.data() + r * total);
        const bool usable = t && std::isfinite(*t);
        local_failed += usable ? 0 : 1;
        const Scalar ranked = usable ? *t : std::numeric_limits<Scalar>::infinity();
        extreme[k] += ranked >= threshold ? 1 : 0;
        local_maximum[r] = std::max(local_maximum[r], ranked);
      }
    }
    const std::lock_guard<std::mutex> lock(merge);
    for (std::size_t r = 0; r < count; ++r)
      maximum[r] = std::max(maximum[r], local_maximum[r]);
    failed += local_failed;
  };
  if (test.threads > 1 && tasks > 1) {
    ChunkPool(test.threads, tasks).run(tasks, run_task);
  } else {
    for (std::size_t task = 0; task < tasks; ++task)
      run_task(task);
  }
  for (std::size_t k = 0; k < elements; ++k) {
    if (element_ok[k]) continue;
    result.status = element_status[k];
    result.bad_element = static_cast<std::ptrdiff_t>(options.first_element + k);
    result.message =
        "element " + std::to_string(options.first_element + k) + ": " + element_message[k];
    return result;
  }
  for (std::size_t k = 0; k < elements; ++k) {
    result.value[k] =
        test.statistic == TwoSampleStatistic::hellinger ? -std::expm1(-observed[k]) : observed[k];
    result.p_value[k] = permutation_p_value<Scalar>(extreme[k], test.permutations);
  }
  result.ranked_value = std::move(observed);
  result.relabelling_maximum = std::move(maximum);
  elementwise_detail::adjust_for_multiplicity(result);
  result.permutations = test.permutations;
  result.failed_permutations = failed;
  result.statistic = test.statistic;
  result.mode = options.mode;
  result.seed = test.seed;
  result.status = Status::converged;
  return result;
}

// One map from maps of consecutive slices of the elements (each run with
// the same samples' subjects, options and seed on its own elements, e.g. on
// its own machine), given in element order: the per-element values are
// concatenated, max_k T_kb is taken over the slices and the family-wise
// and q-values are computed over all elements, so the result equals the
// map of all elements at once exactly. Refused (invalid_input) unless
// every slice ran with the same statistic, mode, seed and number of
// relabellings.
template <class G>
ElementwiseResult<G> combine_elementwise(const std::vector<ElementwiseResult<G>>& slices) {
  ElementwiseResult<G> result;
  if (slices.empty()) {
    result.message = "combine_elementwise: no slices";
    return result;
  }
  const std::size_t count = slices.front().relabelling_maximum.size();
  result.relabelling_maximum.assign(count, -std::numeric_limits<typename G::Scalar>::infinity());
  for (std::size_t s = 0; s < slices.size(); ++s) {
    const ElementwiseResult<G>& slice = slices[s];
    if (!slice.ok()) {
      result.message = "slice " + std::to_string(s) + " did not run: " + slice.message;
      return result;
    }
    const std::size_t k = slice.elements;
    if (slice.statistic != slices.front().statistic || slice.mode != slices.front().mode ||
        slice.seed != slices.front().seed) {
      result.message = "slice " + std::to_string(s) +
                       " was run with another statistic, mode or seed than slice 0: they are not "
                       "slices of one map";
      return result;
    }
    if (slice.permutations != slices.front().permutations ||
        slice.relabelling_maximum.size() != count || slice.value.size() != k ||
        slice.ranked_value.size() != k || slice.p_value.size() != k) {
      result.message = "slice " + std::to_string(s) +
                       " does not hold one value per element and one maximum per relabelling "
                       "of the same " +
                       std::to_string(count) + " relabellings";
      return result;
    }
    result.value.insert(result.value.end(), slice.value.begin(), slice.value.end());
    result.ranked_value.insert(result.ranked_value.end(), slice.ranked_value.begin(),
                               slice.ranked_value.end());
    result.p_value.insert(result.p_value.end(), slice.p_value.begin(), slice.p_value.end());
    for (std::size_t r = 0; r < count; ++r)
      result.relabelling_maximum[r] =
          std::max(result.relabelling_maximum[r], slice.relabelling_maximum[r]);
    result.failed_permutations += slice.failed_permutations;
  }
  result.elements = result.value.size();
  result.permutations = slices.front().permutations;
  result.statistic = slices.front().statistic;
  result.mode = slices.front().mode;
  result.seed = slices.front().seed;
  elementwise_detail::adjust_for_multiplicity(result);
  result.status = Status::converged;
  return result;
}

}  // namespace bireg
