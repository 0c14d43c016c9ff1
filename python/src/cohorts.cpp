// The cohorts layer (bireg/statistics/cohorts/): the two-sample test of
// group elements, the element-wise map, the library's functions that join
// shares of them computed apart (bireg.dask), and the subjects' trends
// (fit_many, compare_trends, population_trend; SO3 and SE3). Each function calls the
// library's and converts; the GIL is released while it works. A refusal,
// or a mean that failed, is a ValueError with the library's message.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nanobind/stl/vector.h>

#include "common.hpp"
#include "fit_handle.hpp"

#include "bireg/statistics/cohorts/elementwise.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"

namespace bireg_python {
namespace {

bireg::TwoSampleOptions<double> test_options(const std::string& statistic,
                                             const std::string& variant, int permutations,
                                             std::uint64_t seed, int threads,
                                             std::uint64_t first_permutation = 0) {
  bireg::TwoSampleOptions<double> options;
  options.statistic =
      parse_choice(statistic,
                   {bireg::TwoSampleStatistic::hotelling, bireg::TwoSampleStatistic::bhattacharyya,
                    bireg::TwoSampleStatistic::hellinger},
                   "statistic");
  options.variant = parse_choice(
      variant, {bireg::TwoSampleVariant::invariant, bireg::TwoSampleVariant::published}, "variant");
  options.permutations = permutations;
  options.seed = seed;
  options.threads = threads;
  options.first_permutation = first_permutation;
  return options;
}

// The fields of a two-sample result; `element` writes a mean as an array
// (a matrix, or a trend's two).
template <class G, class WriteElement>
nb::dict test_dict(const bireg::TwoSampleResult<G>& result, const WriteElement& element) {
  nb::dict out;
  out["statistic"] = std::string(to_string(result.statistic));
  out["variant"] = std::string(to_string(result.variant));
  out["value"] = result.value;
  out["p_value"] = result.p_value;
  out["seed"] = result.seed;
  out["first_permutation"] = result.first_permutation;
  out["permutations"] = result.permutations;
  out["at_least_as_extreme"] = result.at_least_as_extreme;
  out["failed_permutations"] = result.failed_permutations;
  out["mean_a"] = element(*result.mean_a);
  out["mean_b"] = element(*result.mean_b);
  out["mean_difference"] = vector_array(result.mean_difference);
  out["covariance_a"] = matrix_array(result.covariance_a);
  out["covariance_b"] = matrix_array(result.covariance_b);
  out["covariance_b_compared"] = matrix_array(result.covariance_b_compared);
  return out;
}

template <class G>
nb::dict two_sample(const Stack& a, const Stack& b,
                    const bireg::TwoSampleOptions<double>& options) {
  bireg::TwoSampleResult<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::two_sample_test<G>(StackView<G>(a), StackView<G>(b), options);
  }
  if (!result.ok()) refuse(result.message);
  return test_dict(result, [](const typename G::Element& mean) { return matrix_array(mean); });
}

// a: m subjects x K elements in one stack, subject i's element k at
// i K + k (the layout of elementwise_two_sample_test); b likewise.
template <class G>
nb::dict elementwise(const Stack& a, std::size_t m, const Stack& b, std::size_t n,
                     std::size_t elements, const bireg::ElementwiseOptions<double>& options) {
  bireg::ElementwiseResult<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::elementwise_two_sample_test<G>(StackView<G>(a), m, StackView<G>(b), n, elements,
                                                   options);
  }
  if (!result.ok()) refuse(result.message);
  nb::dict out;
  out["statistic"] = std::string(to_string(options.test.statistic));
  out["variant"] = std::string(to_string(options.test.variant));
  out["mode"] = std::string(to_string(options.mode));
  out["value"] = vector_array(result.value);
  out["p_value"] = vector_array(result.p_value);
  out["q_value"] = vector_array(result.q_value);
  out["p_fwer"] = vector_array(result.p_fwer);
  out["permutations"] = result.permutations;
  out["failed_permutations"] = result.failed_permutations;
  out["ranked_value"] = vector_array(result.ranked_value);
  out["relabelling_maximum"] = vector_array(result.relabelling_maximum);
  out["seed"] = result.seed;
  return out;
}

template <class T>
T entry(const nb::dict& share, const char* key, std::size_t index) {
  if (!share.contains(key))
    refuse("share " + std::to_string(index) + " has no '" + key +
           "' (not a result of this module)");
  return nb::cast<T>(share[key]);
}

std::vector<double> array_entry(const nb::dict& share, const char* key, std::size_t index) {
  return to_vector(entry<Vector>(share, key, index));
}

// Shares of one two-sample test (dicts of two_sample_test, each with its
// own first_permutation) joined by bireg::combine_two_sample: the first
// share's dict with the counts and p-value of the whole test.
template <class G>
nb::dict combine_two_sample(const std::vector<nb::dict>& shares) {
  std::vector<bireg::TwoSampleResult<G>> results(shares.size());
  std::size_t first = 0;
  for (std::size_t s = 0; s < shares.size(); ++s) {
    bireg::TwoSampleResult<G>& r = results[s];
    r.status = bireg::Status::converged;
    const auto options = test_options(entry<std::string>(shares[s], "statistic", s),
                                      entry<std::string>(shares[s], "variant", s), 0, 0, 1);
    r.statistic = options.statistic;
    r.variant = options.variant;
    r.value = entry<double>(shares[s], "value", s);
    r.seed = entry<std::uint64_t>(shares[s], "seed", s);
    r.first_permutation = entry<std::uint64_t>(shares[s], "first_permutation", s);
    r.permutations = entry<int>(shares[s], "permutations", s);
    r.at_least_as_extreme = entry<int>(shares[s], "at_least_as_extreme", s);
    r.failed_permutations = entry<int>(shares[s], "failed_permutations", s);
    if (r.first_permutation == 0) first = s;
  }
  const bireg::TwoSampleResult<G> whole = bireg::combine_two_sample(results);
  if (!whole.ok()) refuse(whole.message);
  nb::dict out;
  for (const auto& item : shares[first])
    out[item.first] = item.second;
  out["first_permutation"] = whole.first_permutation;
  out["permutations"] = whole.permutations;
  out["at_least_as_extreme"] = whole.at_least_as_extreme;
  out["failed_permutations"] = whole.failed_permutations;
  out["p_value"] = whole.p_value;
  return out;
}

// Maps of consecutive slices of the elements (dicts of
// elementwise_two_sample_test, in element order) joined by
// bireg::combine_elementwise.
template <class G>
nb::dict combine_elementwise(const std::vector<nb::dict>& slices) {
  std::vector<bireg::ElementwiseResult<G>> results(slices.size());
  for (std::size_t s = 0; s < slices.size(); ++s) {
    bireg::ElementwiseResult<G>& r = results[s];
    r.status = bireg::Status::converged;
    const auto options = test_options(entry<std::string>(slices[s], "statistic", s),
                                      entry<std::string>(slices[s], "variant", s), 0, 0, 1);
    r.statistic = options.statistic;
    r.mode =
        parse_choice(entry<std::string>(slices[s], "mode", s),
                     {bireg::ElementwiseMode::exact, bireg::ElementwiseMode::linearised}, "mode");
    r.seed = entry<std::uint64_t>(slices[s], "seed", s);
    r.value = array_entry(slices[s], "value", s);
    r.p_value = array_entry(slices[s], "p_value", s);
    r.ranked_value = array_entry(slices[s], "ranked_value", s);
    r.relabelling_maximum = array_entry(slices[s], "relabelling_maximum", s);
    r.elements = r.value.size();
    r.permutations = entry<int>(slices[s], "permutations", s);
    r.failed_permutations = entry<int>(slices[s], "failed_permutations", s);
  }
  const bireg::ElementwiseResult<G> whole = bireg::combine_elementwise(results);
  if (!whole.ok()) refuse(whole.message);
  nb::dict out;
  for (const char* key : {"statistic", "variant", "mode"})
    out[key] = entry<std::string>(slices.front(), key, 0);
  out["value"] = vector_array(whole.value);
  out["p_value"] = vector_array(whole.p_value);
  out["q_value"] = vector_array(whole.q_value);
  out["p_fwer"] = vector_array(whole.p_fwer);
  out["permutations"] = whole.permutations;
  out["failed_permutations"] = whole.failed_permutations;
  out["ranked_value"] = vector_array(whole.ranked_value);
  out["relabelling_maximum"] = vector_array(whole.relabelling_maximum);
  out["seed"] = whole.seed;
  return out;
}

using Trends = nb::ndarray<const double, nb::ndim<4>, nb::c_contig, nb::device::cpu>;

// The groups whose trends the module compiles: the trend functions are
// instantiated on G x G, and each group costs minutes of compile time and
// gigabytes of the compiler's memory; the C++ library has them for every
// group.
inline constexpr const char* kTrendGroups = "SO3, SE3";

template <class F>
nb::dict with_trend_group(const std::string& name, const char* function, F&& f) {
  if (name == "SO3") return f(Tag<bireg::SO3d>{});
  if (name == "SE3") return f(Tag<bireg::SE3d>{});
  return with_group(name, [&](auto) -> nb::dict {
    refuse(std::string(function) + ": the Python module has trends for " + kTrendGroups + ", not " +
           name + " (the C++ library has them for every group)");
  });
}

// A stack of trends, numpy's (S, 2, n, n) in C order, seen as the
// library's elements (gamma(t0), gamma(t1)) of G x G.
template <class G>
class TrendView {
 public:
  using Element = bireg::Trend<G>;
  explicit TrendView(const Trends& a) : data_(a.data()), size_(a.shape(0)) {}
  std::size_t size() const { return size_; }
  Element operator[](std::size_t i) const {
    const StackView<G> pair(data_ + 2 * i * kEntries, 2);
    return {pair[0], pair[1]};
  }

 private:
  static constexpr std::size_t kEntries = std::size_t(side<G>() * side<G>());
  const double* data_ = nullptr;
  std::size_t size_ = 0;
};

template <class G>
void write_trend(const bireg::Trend<G>& trend, double* out) {
  constexpr std::size_t entries = std::size_t(side<G>() * side<G>());
  write_row_major(trend.first, out);
  write_row_major(trend.second, out + entries);
}

template <class G>
Output trend_array(const bireg::Trend<G>& trend) {
  NewArray a({2, std::size_t(side<G>()), std::size_t(side<G>())});
  write_trend<G>(trend, a.data());
  return a.release();
}

// Every subject fitted; a subject whose fit failed refuses the whole call
// (the library's message names the first and counts them), so that no
// trend is returned for a fit that did not succeed.
template <class G>
nb::dict fit_many_dict(const std::vector<Vector>& t, const std::vector<Stack>& y, double t0,
                       double t1, int threads, std::size_t first_subject) {
  if (t.size() != y.size())
    refuse("fit_many: " + std::to_string(t.size()) + " covariate arrays for " +
           std::to_string(y.size()) + " subjects");
  std::vector<bireg::SubjectData<G>> subjects(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i].shape(0) != y[i].shape(0))
      refuse("fit_many: subject " + std::to_string(first_subject + i) + " has " +
             std::to_string(t[i].shape(0)) + " covariates for " + std::to_string(y[i].shape(0)) +
             " observations");
    const StackView<G> view(y[i]);
    subjects[i].covariates = to_vector(t[i]);
    subjects[i].observations.reserve(view.size());
    for (std::size_t k = 0; k < view.size(); ++k)
      subjects[i].observations.push_back(view[k]);
  }
  bireg::FitManyOptions<double> options;
  options.t0 = t0;
  options.t1 = t1;
  options.threads = threads;
  options.first_subject = first_subject;
  bireg::FitManyResult<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::fit_many(bireg::GeodesicRegression<G>(), subjects, options);
  }
  if (!result.ok()) refuse("fit_many: " + result.message);
  NewArray trends({result.trends.size(), 2, std::size_t(side<G>()), std::size_t(side<G>())});
  for (std::size_t i = 0; i < result.trends.size(); ++i)
    write_trend<G>(result.trends[i], trends.data() + i * 2 * side<G>() * side<G>());
  NewArray iterations({result.fits.size()});
  for (std::size_t i = 0; i < result.fits.size(); ++i)
    iterations.data()[i] = result.fits[i].iterations;
  nb::dict out;
  out["t0"] = result.t0;
  out["t1"] = result.t1;
  out["trends"] = trends.release();
  out["n_iter"] = iterations.release();
  return out;
}

template <class G>
nb::dict compare_trends_dict(const Trends& a, const Trends& b,
                             const bireg::TwoSampleOptions<double>& options) {
  using Pair = bireg::Product<G, G>;
  bireg::TwoSampleResult<Pair> result;
  {
    nb::gil_scoped_release release;
    result = bireg::compare_trends<G>(TrendView<G>(a), TrendView<G>(b), options);
  }
  if (!result.ok()) refuse(result.message);
  return test_dict(result, [](const bireg::Trend<G>& mean) { return trend_array<G>(mean); });
}

// The trends' elements at covariate t, compared in G: a dict whose means
// are matrices.
template <class G>
nb::dict compare_trends_at_dict(const Trends& a, const Trends& b, double t0, double t1, double t,
                                const bireg::TwoSampleOptions<double>& options) {
  bireg::TwoSampleResult<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::compare_trends_at<G>(TrendView<G>(a), TrendView<G>(b), t0, t1, t, options);
  }
  if (!result.ok()) refuse("compare_trends_at: " + result.message);
  return test_dict(result, [](const typename G::Element& mean) { return matrix_array(mean); });
}

// The trends' body velocities, compared as vectors: a dict whose means are
// vectors of length d.
template <class G>
nb::dict compare_velocities_dict(const Trends& a, const Trends& b, double t0, double t1,
                                 const bireg::TwoSampleOptions<double>& options) {
  bireg::TwoSampleResult<bireg::Rn<G::dof, double>> result;
  {
    nb::gil_scoped_release release;
    result = bireg::compare_velocities<G>(TrendView<G>(a), TrendView<G>(b), t0, t1, options);
  }
  if (!result.ok()) refuse("compare_velocities: " + result.message);
  return test_dict(result, [](const typename G::Tangent& mean) { return vector_array(mean); });
}

template <class G>
nb::dict population_trend_dict(const Trends& trends, double t0, double t1, double level,
                               double outlier_level) {
  bireg::PopulationOptions<double> options;
  options.level = level;
  options.outlier_level = outlier_level;
  bireg::PopulationTrend<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::population_trend<G>(TrendView<G>(trends), t0, t1, options);
  }
  if (!result.ok()) refuse("population_trend: " + result.message);
  NewArray outlying({result.outlying.size()});
  for (std::size_t i = 0; i < result.outlying.size(); ++i)
    outlying.data()[i] = result.outlying[i] ? 1.0 : 0.0;
  nb::dict out;
  out["mean"] = trend_array<G>(*result.mean);
  out["covariance"] = matrix_array(result.covariance);
  out["mean_covariance"] = matrix_array(result.mean_covariance);
  out["radius_squared"] = result.radius_squared;
  out["velocity"] = vector_array(result.velocity);
  out["velocity_covariance"] = matrix_array(result.velocity_covariance);
  out["mahalanobis_squared"] = vector_array(result.mahalanobis_squared);
  out["outlying"] = outlying.release();
  out["outlier_threshold"] = result.outlier_threshold;
  return out;
}

}  // namespace

void bind_cohorts(nb::module_& m) {
  m.def(
      "two_sample_test",
      [](const std::string& group, const Stack& a, const Stack& b, const std::string& statistic,
         const std::string& variant, int permutations, std::uint64_t seed, int threads,
         std::uint64_t first_permutation) {
        const auto options =
            test_options(statistic, variant, permutations, seed, threads, first_permutation);
        return with_group(group, [&](auto tag) {
          return two_sample<typename decltype(tag)::type>(a, b, options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("statistic"), nb::arg("variant"),
      nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      nb::arg("first_permutation") = 0,
      "bireg::two_sample_test<G>: a dict with the statistic, p-value, means and covariances; "
      "relabellings first_permutation .. first_permutation + permutations - 1.");
  m.def(
      "combine_two_sample",
      [](const std::string& group, const std::vector<nb::dict>& shares) {
        return with_group(group, [&](auto tag) {
          return combine_two_sample<typename decltype(tag)::type>(shares);
        });
      },
      nb::arg("group"), nb::arg("shares"),
      "bireg::combine_two_sample<G>: one test from two_sample_test's shares of its "
      "relabellings.");
  m.def(
      "combine_elementwise",
      [](const std::string& group, const std::vector<nb::dict>& slices) {
        return with_group(group, [&](auto tag) {
          return combine_elementwise<typename decltype(tag)::type>(slices);
        });
      },
      nb::arg("group"), nb::arg("slices"),
      "bireg::combine_elementwise<G>: one map from the maps of consecutive slices of the "
      "elements.");
  m.def(
      "elementwise_two_sample_test",
      [](const std::string& group, const Stack& a, std::size_t subjects_a, const Stack& b,
         std::size_t subjects_b, std::size_t elements, const std::string& statistic,
         const std::string& variant, int permutations, std::uint64_t seed, int threads,
         const std::string& mode, std::size_t first_element) {
        bireg::ElementwiseOptions<double> options;
        options.test = test_options(statistic, variant, permutations, seed, threads);
        options.mode = parse_choice(
            mode, {bireg::ElementwiseMode::exact, bireg::ElementwiseMode::linearised}, "mode");
        options.first_element = first_element;
        return with_group(group, [&](auto tag) {
          return elementwise<typename decltype(tag)::type>(a, subjects_a, b, subjects_b, elements,
                                                           options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("subjects_a"), nb::arg("b"), nb::arg("subjects_b"),
      nb::arg("elements"), nb::arg("statistic"), nb::arg("variant"), nb::arg("permutations"),
      nb::arg("seed"), nb::arg("threads"), nb::arg("mode"), nb::arg("first_element") = 0,
      "bireg::elementwise_two_sample_test<G>: per-element statistics, p-, q- and FWER p-values.");
  m.def(
      "fit_many",
      [](const std::string& group, const std::vector<Vector>& t, const std::vector<Stack>& y,
         double t0, double t1, int threads, std::size_t first_subject) {
        return with_trend_group(group, "fit_many", [&](auto tag) {
          return fit_many_dict<typename decltype(tag)::type>(t, y, t0, t1, threads, first_subject);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("y"), nb::arg("t0"), nb::arg("t1"),
      nb::arg("threads"), nb::arg("first_subject") = 0,
      "bireg::fit_many<G>: every subject's trend (gamma(t0), gamma(t1)) on one interval.");
  m.def(
      "compare_trends",
      [](const std::string& group, const Trends& a, const Trends& b, const std::string& statistic,
         const std::string& variant, int permutations, std::uint64_t seed, int threads,
         std::uint64_t first_permutation) {
        const auto options =
            test_options(statistic, variant, permutations, seed, threads, first_permutation);
        return with_trend_group(group, "compare_trends", [&](auto tag) {
          return compare_trends_dict<typename decltype(tag)::type>(a, b, options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("statistic"), nb::arg("variant"),
      nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      nb::arg("first_permutation") = 0,
      "bireg::compare_trends<G>: the two-sample test of two cohorts' trends in G x G.");
  m.def(
      "compare_trends_at",
      [](const std::string& group, const Trends& a, const Trends& b, double t0, double t1, double t,
         const std::string& statistic, const std::string& variant, int permutations,
         std::uint64_t seed, int threads) {
        const auto options = test_options(statistic, variant, permutations, seed, threads);
        return with_trend_group(group, "compare_trends_at", [&](auto tag) {
          return compare_trends_at_dict<typename decltype(tag)::type>(a, b, t0, t1, t, options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("t0"), nb::arg("t1"), nb::arg("t"),
      nb::arg("statistic"), nb::arg("variant"), nb::arg("permutations"), nb::arg("seed"),
      nb::arg("threads"),
      "bireg::compare_trends_at<G>: the two-sample test of the trends' elements at t, in G.");
  m.def(
      "compare_velocities",
      [](const std::string& group, const Trends& a, const Trends& b, double t0, double t1,
         const std::string& statistic, int permutations, std::uint64_t seed, int threads) {
        const auto options = test_options(statistic, "invariant", permutations, seed, threads);
        return with_trend_group(group, "compare_velocities", [&](auto tag) {
          return compare_velocities_dict<typename decltype(tag)::type>(a, b, t0, t1, options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("t0"), nb::arg("t1"),
      nb::arg("statistic"), nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      "bireg::compare_velocities<G>: the two-sample test of the trends' body velocities.");
  m.def(
      "population_trend",
      [](const std::string& group, const Trends& trends, double t0, double t1, double level,
         double outlier_level) {
        return with_trend_group(group, "population_trend", [&](auto tag) {
          return population_trend_dict<typename decltype(tag)::type>(trends, t0, t1, level,
                                                                     outlier_level);
        });
      },
      nb::arg("group"), nb::arg("trends"), nb::arg("t0"), nb::arg("t1"), nb::arg("level"),
      nb::arg("outlier_level"),
      "bireg::population_trend<G>: the mean trend, its confidence region, outlying subjects.");
}

}  // namespace bireg_python
