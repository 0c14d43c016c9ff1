// bireg: bi-invariant two-sample tests of group elements: do samples A and
// B come from one population? docs/cohorts.md has the definitions, the
// proofs of invariance and what the null hypothesis is and is not.
//
// With the bi-invariant means m_A, m_B (mean.hpp), left-trivialised
// coordinates x_i = log(m_A^{-1} a_i), y_j = log(m_B^{-1} b_j), covariances
// S_A = sum x x^T / m, S_B = sum y y^T / n and c = log(m_A^{-1} m_B):
//
//   Hotelling      T^2 = m n / (m + n) c^T S_pool^{-1} c,  S_pool = (m S_A + n S_B') / (m + n - 2)
//   Bhattacharyya  D_B = c^T S_avg^{-1} c / 8 + log(det S_avg / sqrt(det S_A det S_B')) / 2
//   Hellinger      H^2 = 1 - exp(-D_B)
//
// with S_avg = (S_A + S_B') / 2. The invariant variant (default) carries B's
// coordinates to m_A by the Cartan-Schouten parallel transport along the
// geodesic from m_B, T = Ad(exp(c/2)), S_B' = T S_B T^T: the statistics are
// then unchanged by left and right translation, inversion and exchanging
// the samples (docs/cohorts.md, Theorem). The published variant (S_B' =
// S_B, Hanik, Hege and von Tycowicz's definition) is unchanged by
// translations and exchange, not by inversion.
//
// p = (1 + #{b : T_b >= T}) / (B + 1) over B relabellings of the pooled
// sample, each with both means recomputed (the exact mode). Relabelling b
// depends on (seed, b) only (permutation.hpp) and is evaluated by the same
// arithmetic on any thread, so p does not depend on `threads`.
//
// The relabellings can be shared out among processes (bireg.dask, MPI):
// each share runs b = first_permutation .. first_permutation + B_s - 1 of
// the same seed, and combine_two_sample adds the shares' counts. The
// counts are integers, so the combined p equals the one-process p exactly,
// for any number and order of shares.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "bireg/concept.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/status.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"
#include "bireg/statistics/inference/scatter.hpp"

namespace bireg {

enum class TwoSampleStatistic {
  hotelling,      // T^2: most sensitive to a difference of means
  bhattacharyya,  // D_B: differences of means and of covariances
  hellinger,      // H^2 = 1 - exp(-D_B): the same test as D_B (ranked by D_B), another scale
};

enum class TwoSampleVariant {
  invariant,  // B's coordinates transported to m_A: invariant under inversion too
  published,  // B's covariance at m_B: invariant under translations and exchange, not inversion
};

inline const char* to_string(TwoSampleStatistic statistic) {
  switch (statistic) {
    case TwoSampleStatistic::hotelling:
      return "hotelling";
    case TwoSampleStatistic::bhattacharyya:
      return "bhattacharyya";
    case TwoSampleStatistic::hellinger:
      return "hellinger";
  }
  return "unknown";
}

inline const char* to_string(TwoSampleVariant variant) {
  return variant == TwoSampleVariant::invariant ? "invariant" : "published";
}

template <class Scalar>
struct TwoSampleOptions {
  TwoSampleStatistic statistic = TwoSampleStatistic::hotelling;
  TwoSampleVariant variant = TwoSampleVariant::invariant;
  // Relabellings B, 0 to kMaxTwoSamplePermutations (0: the statistic only,
  // p_value = 1).
  int permutations = 9999;
  std::uint64_t seed = 0;
  // The first relabelling's index in the seed's stream: 0 for a whole
  // test, the share's offset when a test is shared out (combine_two_sample).
  // first_permutation + permutations is at most kMaxTwoSamplePermutations.
  std::uint64_t first_permutation = 0;
  // Threads for the relabellings (1 to kMaxThreads); the result does not
  // depend on it. A std::bad_alloc on a worker terminates.
  int threads = 1;
  MeanOptions<Scalar> mean;  // for every mean, the relabelled ones included
};

inline constexpr int kMaxTwoSamplePermutations = 100'000'000;

template <class G>
struct TwoSampleResult {
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;

  // converged: the test ran. invalid_input: refused (message says why; for
  // a bad element, bad_sample is 'A' or 'B' and bad_index its position).
  // Another status: a mean of the data failed (message).
  Status status = Status::invalid_input;
  std::string message;
  char bad_sample = 0;
  std::ptrdiff_t bad_index = -1;

  TwoSampleStatistic statistic = TwoSampleStatistic::hotelling;
  TwoSampleVariant variant = TwoSampleVariant::invariant;
  Scalar value = 0;  // T^2, D_B or H^2 of the data
  Scalar p_value = 1;
  std::uint64_t seed = 0;               // of the relabellings
  std::uint64_t first_permutation = 0;  // this result's relabellings: first_permutation ..
  int permutations = 0;                 // .. first_permutation + permutations - 1
  int at_least_as_extreme = 0;          // #{b : T_b >= T}, failed relabellings included
  int failed_permutations = 0;          // relabellings whose statistic could not be computed

  std::optional<Element> mean_a, mean_b;
  Tangent mean_difference = Tangent::Zero();          // c = log(m_A^{-1} m_B)
  AdMatrix covariance_a = AdMatrix::Zero();           // S_A, at m_A
  AdMatrix covariance_b = AdMatrix::Zero();           // S_B, at m_B
  AdMatrix covariance_b_compared = AdMatrix::Zero();  // S_B': transported, or S_B

  bool ok() const { return is_success(status); }
};

// p = (1 + #{b : T_b >= T}) / (B + 1): the permutation p-value, which is
// exact (P(p <= alpha) <= alpha under exchangeability) because the
// observed split is counted among the B + 1.
template <class Scalar>
Scalar permutation_p_value(int at_least_as_extreme, int permutations) {
  return Scalar(1 + at_least_as_extreme) / Scalar(1 + permutations);
}

namespace two_sample_detail {

inline std::string failed_relabellings_message(int failed) {
  return std::to_string(failed) +
         " relabellings had no statistic (a mean failed or a covariance was singular) and count "
         "as at least as extreme";
}

// Elements of a pooled sample picked by index: what mean() reads.
template <class Element>
struct Picked {
  const std::vector<Element>* pooled = nullptr;
  const std::size_t* index = nullptr;
  std::size_t count = 0;

  std::size_t size() const { return count; }
  const Element& operator[](std::size_t i) const { return (*pooled)[index[i]]; }
};

// Below this reciprocal condition number a covariance counts as singular.
template <class Scalar>
constexpr Scalar kSingular = Scalar(1e-12);

// log det of a symmetric matrix that must be positive definite; nullopt
// when it is not (to kSingular).
template <class Matrix>
std::optional<typename Matrix::Scalar> log_determinant(const Matrix& s) {
  using Scalar = typename Matrix::Scalar;
  const auto lambda = symmetric_eigen(s).values;  // ascending; NaN if s is not finite
  const Scalar largest = lambda[lambda.size() - 1];
  if (!(largest > 0) || !(lambda[0] > kSingular<Scalar> * largest)) return std::nullopt;
  return lambda.array().log().sum();
}

// T^2 (hotelling) or D_B (otherwise) from the sizes, S_A, S_B' and c;
// nullopt when a covariance it needs is singular.
template <class G>
std::optional<typename G::Scalar> statistic(TwoSampleStatistic which, std::size_t m, std::size_t n,
                                            const typename G::AdMatrix& s_a,
                                            const typename G::AdMatrix& s_b,
                                            const typename G::Tangent& c) {
  using Scalar = typename G::Scalar;
  using AdMatrix = typename G::AdMatrix;
  const Scalar sm = static_cast<Scalar>(m), sn = static_cast<Scalar>(n);
  if (which == TwoSampleStatistic::hotelling) {
    const AdMatrix pooled = (sm * s_a + sn * s_b) / (sm + sn - 2);
    if (!log_determinant(pooled)) return std::nullopt;
    const Scalar form = c.dot(pooled.ldlt().solve(c));
    return sm * sn / (sm + sn) * form;
  }
  const AdMatrix average = (s_a + s_b) / 2;
  const auto log_a = log_determinant(s_a), log_b = log_determinant(s_b);
  const auto log_average = log_determinant(average);
  if (!log_a || !log_b || !log_average) return std::nullopt;
  const Scalar form = c.dot(average.ldlt().solve(c));
  const Scalar bhattacharyya = form / 8 + (*log_average - (*log_a + *log_b) / 2) / 2;
  // Hellinger too: two_sample_test ranks it by D_B and reports 1 - exp(-D_B).
  return bhattacharyya;
}

// What every split shares: the pooled sample, its mean p, the coordinates
// z_i = log(p^{-1} e_i) and Newton's Jacobians there, J_i = J_r^{-1}(-z_i)
// (mean.hpp), computed once.
template <class G>
struct Pooled {
  std::vector<typename G::Element> elements;
  typename G::Element mean;
  std::vector<typename G::Tangent> z;
  std::vector<typename G::AdMatrix> jacobian;
};

// The mean of the elements `index[0 .. count)` of the pooled sample, and
// their residuals y_i = log(m^{-1} e_i) at it, without allocating
// (`residuals` has the capacity). mean.hpp's Newton iteration solves
// sum y_i = 0 too, but evaluates J_r^{-1} at every element in every
// iteration, which is most of its cost (SE(3): 55 % of a relabelling). Here
// the first step is Newton's from p, made of the shared z_i and J_i alone,
// delta = (sum J_i)^{-1} sum z_i, and the following ones are chord steps
// with that same matrix: delta = (sum J_i)^{-1} sum y_i, logs only. The
// chord iteration converges linearly at the rate |I - K^{-1} K(m)|, where
// K(m) = sum J_r^{-1}(-y_i(m)) differs from K = K(p) by about
// ad(sum z_i) / 2: of the order of |m - p|, the subset mean's distance from
// the pooled one, which is small wherever relabelling makes sense. It
// stops by mean.hpp's rule (a step of at most options.tolerance, 1e-10 by
// default in double) but, linear and without taking that last step, is only about
// that step's size from the root (1e-11 to 1e-10 on samples like
// test_cohorts.cpp's), where Newton's last step leaves rounding error
// (1e-16). False when it does not stop in kMaxChordSteps or a step fails
// to reduce |sum y|, and the caller falls back to mean().
inline constexpr int kMaxChordSteps = 50;

template <class G>
bool split_mean(const Pooled<G>& pooled, const std::size_t* index, std::size_t count,
                const MeanOptions<typename G::Scalar>& options, typename G::Element& mean,
                std::vector<typename G::Tangent>& residuals) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  Tangent force = Tangent::Zero();
  AdMatrix jacobian = AdMatrix::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    force += pooled.z[index[i]];
    jacobian += pooled.jacobian[index[i]];
  }
  const SmallLU<AdMatrix> chord(jacobian);
  Tangent step = chord.solve(force);
  if (!step.allFinite()) return false;
  mean = G::compose(pooled.mean, G::exp(step));
  residuals.resize(count);
  using std::sqrt;
  Scalar previous = std::numeric_limits<Scalar>::infinity();
  for (int iteration = 0; iteration < kMaxChordSteps; ++iteration) {
    const typename G::Element inverse = G::inverse(mean);
    force.setZero();
    for (std::size_t i = 0; i < count; ++i) {
      residuals[i] = G::log(G::compose(inverse, pooled.elements[index[i]]));
      force += residuals[i];
    }
    const Scalar size = sqrt(force.squaredNorm());
    if (!(size < previous)) return size == 0;
    previous = size;
    step = chord.solve(force);
    if (!step.allFinite()) return false;
    if (sqrt(step.squaredNorm()) <= options.tolerance) return true;
    mean = G::compose(mean, G::exp(step));
  }
  return false;
}

// Means, covariances and the statistic of one split of the pooled sample.
template <class G>
struct Split {
  using AdMatrix = typename G::AdMatrix;
  typename G::Element mean_a, mean_b;
  std::vector<typename G::Tangent> y_a, y_b;
  typename G::Tangent c;
  AdMatrix s_a, s_b, s_b_compared;
  std::optional<typename G::Scalar> value;
};

// Splits the pooled sample into index[0 .. m) and index[m .. m + n); each
// mean by split_mean(), or by mean() where that fails.
template <class G>
void evaluate(const Pooled<G>& pooled, const std::size_t* index, std::size_t m, std::size_t n,
              const TwoSampleOptions<typename G::Scalar>& options, Split<G>& split) {
  using Scalar = typename G::Scalar;
  split.value.reset();
  const auto mean_of = [&](const std::size_t* first, std::size_t count,
                           typename G::Element& mean_out,
                           std::vector<typename G::Tangent>& residuals) {
    if (split_mean<G>(pooled, first, count, options.mean, mean_out, residuals)) return true;
    const MeanResult<G> full =
        mean<G>(Picked<typename G::Element>{&pooled.elements, first, count}, {}, options.mean);
    if (!full.ok()) return false;
    mean_out = *full.mean;
    residuals = full.residuals;
    return true;
  };
  if (!mean_of(index, m, split.mean_a, split.y_a) ||
      !mean_of(index + m, n, split.mean_b, split.y_b)) {
    return;
  }
  split.c = G::log(G::compose(G::inverse(split.mean_a), split.mean_b));
  if (!split.c.allFinite()) return;
  split.s_a = scatter_matrix(split.y_a, {}) / Scalar(m);
  split.s_b = scatter_matrix(split.y_b, {}) / Scalar(n);
  if (options.variant == TwoSampleVariant::invariant) {
    // Parallel transport from m_B to m_A (docs/cohorts.md).
    const typename G::AdMatrix transport = G::Ad(G::exp(split.c / 2));
    split.s_b_compared = transport * split.s_b * transport.transpose();
  } else {
    split.s_b_compared = split.s_b;
  }
  split.value = statistic<G>(options.statistic, m, n, split.s_a, split.s_b_compared, split.c);
  using std::isfinite;
  if (split.value && !isfinite(*split.value)) split.value.reset();
}

// A relabelled statistic within this relative distance below T counts as
// T: the relabellings that reproduce the observed split give T up to
// rounding, and must count as at least as extreme.
template <class Scalar>
constexpr Scalar kTie = Scalar(1e-9);

// Relabellings per task: each block reuses one index buffer.
inline constexpr std::size_t kBlock = 16;

enum class Verdict : unsigned char { less_extreme, at_least_as_extreme, failed };

// Why options and sample sizes m, n cannot be tested (`sizes` describes
// them for the message); empty when they can.
template <class G>
std::string refusal(std::size_t m, std::size_t n,
                    const TwoSampleOptions<typename G::Scalar>& options, const std::string& sizes) {
  const std::size_t d = static_cast<std::size_t>(G::dof);
  const int which = static_cast<int>(options.statistic);
  if (which < 0 || which > static_cast<int>(TwoSampleStatistic::hellinger)) {
    return "statistic " + std::to_string(which) + " is not a TwoSampleStatistic";
  }
  const int variant = static_cast<int>(options.variant);
  if (variant < 0 || variant > static_cast<int>(TwoSampleVariant::published)) {
    return "variant " + std::to_string(variant) + " is not a TwoSampleVariant";
  }
  if (options.permutations < 0 || options.permutations > kMaxTwoSamplePermutations) {
    return "permutations must be 0 to " + std::to_string(kMaxTwoSamplePermutations) + ", not " +
           std::to_string(options.permutations);
  }
  const auto limit = static_cast<std::uint64_t>(kMaxTwoSamplePermutations);
  if (options.first_permutation > limit - static_cast<std::uint64_t>(options.permutations)) {
    return "first_permutation + permutations must be at most " + std::to_string(limit) + ", not " +
           std::to_string(options.first_permutation) + " + " + std::to_string(options.permutations);
  }
  if (options.threads < 1 || options.threads > kMaxThreads) {
    return "threads must be 1 to " + std::to_string(kMaxThreads) + ", not " +
           std::to_string(options.threads);
  }
  if (m < 2 || n < 2) return "each sample needs at least two elements; there are " + sizes;
  if (options.statistic == TwoSampleStatistic::hotelling && m + n - 2 < d) {
    return "the pooled covariance is singular: it needs m + n - 2 >= " + std::to_string(d) +
           ", and there are " + sizes;
  }
  if (options.statistic != TwoSampleStatistic::hotelling && (m <= d || n <= d)) {
    return std::string("each sample's covariance is singular unless it has more than ") +
           std::to_string(d) + " elements (" + to_string(options.statistic) +
           " needs both); there are " + sizes;
  }
  return {};
}

}  // namespace two_sample_detail

// The two-sample test of `a` against `b` (indexable, with size(); m, n >=
// 2). Never throws for bad data, never returns NaN: a refusal has status
// invalid_input and says why.
template <class G, class SampleA, class SampleB>
TwoSampleResult<G> two_sample_test(const SampleA& a, const SampleB& b,
                                   const TwoSampleOptions<typename G::Scalar>& options = {}) {
  static_assert(check_lie_group<G>());
  using Scalar = typename G::Scalar;
  namespace detail = two_sample_detail;
  TwoSampleResult<G> result;
  result.statistic = options.statistic;
  result.variant = options.variant;
  const std::size_t m = a.size(), n = b.size();
  const std::string sizes = "m = " + std::to_string(m) + " and n = " + std::to_string(n) +
                            " elements of " + G::name + " (dimension " + std::to_string(G::dof) +
                            ")";
  result.message = detail::refusal<G>(m, n, options, sizes);
  if (!result.message.empty()) return result;

  // The data's means, by mean(): it checks every element and says which
  // one is bad.
  const auto refused_by_mean = [&result](const MeanResult<G>& failed, char sample) {
    result.status = failed.status;
    result.bad_sample = failed.bad_index >= 0 ? sample : 0;
    result.bad_index = failed.bad_index;
    result.message = std::string("sample ") + sample + ": " + failed.message;
    return result;
  };
  const MeanResult<G> mean_a = mean<G>(a, {}, options.mean);
  if (!mean_a.ok()) return refused_by_mean(mean_a, 'A');
  const MeanResult<G> mean_b = mean<G>(b, {}, options.mean);
  if (!mean_b.ok()) return refused_by_mean(mean_b, 'B');

  detail::Pooled<G> pooled;
  pooled.elements.reserve(m + n);
  for (std::size_t i = 0; i < m; ++i)
    pooled.elements.push_back(a[i]);
  for (std::size_t j = 0; j < n; ++j)
    pooled.elements.push_back(b[j]);
  const MeanResult<G> pooled_mean = mean<G>(pooled.elements, {}, options.mean);
  if (!pooled_mean.ok()) {
    result.status = pooled_mean.status;
    result.message = "the pooled sample: " + pooled_mean.message;
    return result;
  }
  pooled.mean = *pooled_mean.mean;
  pooled.z = pooled_mean.residuals;
  pooled.jacobian.reserve(m + n);
  for (const auto& z : pooled.z)
    pooled.jacobian.push_back(right_jacobian_inverse<G>(-z));

  // Hellinger's H^2 = 1 - exp(-D_B) is ranked on D_B's scale: the same
  // verdicts, without the rounding of H^2 to 1 where D_B exceeds ~37.
  TwoSampleOptions<Scalar> ranking = options;
  if (options.statistic == TwoSampleStatistic::hellinger) {
    ranking.statistic = TwoSampleStatistic::bhattacharyya;
  }
  // The observed split by the same arithmetic as the relabelled ones, so
  // that T is exchangeable with the T_b under H0.
  std::vector<std::size_t> identity(m + n);
  for (std::size_t i = 0; i < m + n; ++i)
    identity[i] = i;
  detail::Split<G> observed;
  detail::evaluate<G>(pooled, identity.data(), m, n, ranking, observed);
  result.mean_a = observed.value ? observed.mean_a : *mean_a.mean;
  result.mean_b = observed.value ? observed.mean_b : *mean_b.mean;
  result.mean_difference = observed.c;
  result.covariance_a = observed.s_a;
  result.covariance_b = observed.s_b;
  result.covariance_b_compared = observed.s_b_compared;
  if (!observed.value) {
    result.message = std::string("the covariances ") + to_string(options.statistic) +
                     " needs are singular (reciprocal condition number below 1e-12), or the "
                     "means lie beyond the log's domain; there are " +
                     sizes;
    return result;
  }
  const Scalar observed_value = *observed.value;
  using std::expm1;
  result.value =
      options.statistic == TwoSampleStatistic::hellinger ? -expm1(-observed_value) : observed_value;

  const std::size_t count = static_cast<std::size_t>(options.permutations);
  std::vector<detail::Verdict> verdicts(count, detail::Verdict::failed);
  const std::size_t blocks = chunk_count(count, detail::kBlock);
  const Scalar threshold = observed_value * (1 - detail::kTie<Scalar>);
  const auto run_block = [&](std::size_t block) {
    std::vector<std::size_t> order;
    detail::Split<G> split;
    split.y_a.reserve(m);
    split.y_b.reserve(n);
    const std::size_t end = std::min(count, (block + 1) * detail::kBlock);
    for (std::size_t b = block * detail::kBlock; b < end; ++b) {
      permutation(options.seed, options.first_permutation + b, m + n, order);
      detail::evaluate<G>(pooled, order.data(), m, n, ranking, split);
      verdicts[b] = !split.value                ? detail::Verdict::failed
                    : *split.value >= threshold ? detail::Verdict::at_least_as_extreme
                                                : detail::Verdict::less_extreme;
    }
  };
  if (options.threads > 1 && blocks > 1) {
    ChunkPool(options.threads, blocks).run(blocks, run_block);
  } else {
    for (std::size_t block = 0; block < blocks; ++block)
      run_block(block);
  }
  for (const detail::Verdict verdict : verdicts) {
    result.failed_permutations += verdict == detail::Verdict::failed ? 1 : 0;
    result.at_least_as_extreme += verdict == detail::Verdict::less_extreme ? 0 : 1;
  }
  result.seed = options.seed;
  result.first_permutation = options.first_permutation;
  result.permutations = options.permutations;
  result.p_value = permutation_p_value<Scalar>(result.at_least_as_extreme, options.permutations);
  result.status = Status::converged;
  if (result.failed_permutations > 0) {
    result.message = detail::failed_relabellings_message(result.failed_permutations);
  }
  return result;
}

// One test from its shares (two_sample_test runs with first_permutation
// and permutations set per share), in any order: the counts are added and
// p recomputed, the rest is the first share's. Refused (invalid_input, the
// message says why) unless every share ran, they agree on the statistic,
// variant and observed value (the same data and build), and their
// relabellings tile 0 .. B - 1 without gap or overlap, with the same seed
// and consistent counts (0 <= failed <= at least as extreme <= B_s).
template <class G>
TwoSampleResult<G> combine_two_sample(const std::vector<TwoSampleResult<G>>& shares) {
  using Scalar = typename G::Scalar;
  TwoSampleResult<G> refused;
  if (shares.empty()) {
    refused.message = "combine_two_sample: no shares";
    return refused;
  }
  std::vector<std::size_t> order(shares.size());
  for (std::size_t s = 0; s < shares.size(); ++s) {
    if (!shares[s].ok()) {
      refused.message = "share " + std::to_string(s) + " did not run: " + shares[s].message;
      return refused;
    }
    order[s] = s;
  }
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return shares[x].first_permutation < shares[y].first_permutation;
  });
  const TwoSampleResult<G>& first = shares[order.front()];
  TwoSampleResult<G> result = first;
  std::uint64_t next = 0;
  long long at_least = 0, failed = 0, total = 0;
  for (const std::size_t s : order) {
    const TwoSampleResult<G>& share = shares[s];
    if (share.permutations < 0 || share.failed_permutations < 0 ||
        share.failed_permutations > share.at_least_as_extreme ||
        share.at_least_as_extreme > share.permutations) {
      refused.message = "share " + std::to_string(s) +
                        " has inconsistent counts (it needs 0 <= failed <= at least as extreme "
                        "<= permutations)";
      return refused;
    }
    if (share.seed != first.seed) {
      refused.message = "share " + std::to_string(s) + " was run with seed " +
                        std::to_string(share.seed) + ", another share with seed " +
                        std::to_string(first.seed) + ": they are not shares of one test";
      return refused;
    }
    if (share.statistic != first.statistic || share.variant != first.variant ||
        !(share.value == first.value)) {
      refused.message = "share " + std::to_string(s) +
                        " disagrees with the others on the statistic or its observed value: "
                        "the shares were computed from different data, options or builds";
      return refused;
    }
    if (share.first_permutation != next) {
      refused.message = "the shares' relabellings do not tile 0 .. B - 1: share " +
                        std::to_string(s) + " starts at " +
                        std::to_string(share.first_permutation) + ", expected " +
                        std::to_string(next);
      return refused;
    }
    next += static_cast<std::uint64_t>(share.permutations);
    at_least += share.at_least_as_extreme;
    failed += share.failed_permutations;
    total += share.permutations;
  }
  if (total > kMaxTwoSamplePermutations) {
    refused.message = "the shares hold " + std::to_string(total) + " relabellings, more than " +
                      std::to_string(kMaxTwoSamplePermutations);
    return refused;
  }
  result.first_permutation = 0;
  result.permutations = static_cast<int>(total);
  result.at_least_as_extreme = static_cast<int>(at_least);
  result.failed_permutations = static_cast<int>(failed);
  result.p_value = permutation_p_value<Scalar>(result.at_least_as_extreme, result.permutations);
  result.message = result.failed_permutations > 0
                       ? two_sample_detail::failed_relabellings_message(result.failed_permutations)
                       : std::string();
  return result;
}

}  // namespace bireg
