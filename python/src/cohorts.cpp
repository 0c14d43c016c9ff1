// The cohorts layer (bireg/statistics/cohorts/): the two-sample test of
// group elements, the element-wise map, the library's functions that join
// shares of them computed apart (bireg.dask), and the subjects' trends
// (fit_many, compare_trends, population_trend; one file per group,
// cohorts.hpp). Each function calls the library's and converts; the GIL is released while it works.
// A refusal, or a mean that failed, is a ValueError with the library's message.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nanobind/stl/vector.h>

#include "cohorts.hpp"

#include "bireg/statistics/cohorts/elementwise.hpp"

namespace bireg_python {
namespace {

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
        return with_group(group, [&](auto tag) {
          return TrendFunctions<typename decltype(tag)::type>::fit_many(t, y, t0, t1, threads,
                                                                        first_subject);
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
        return with_group(group, [&](auto tag) {
          return TrendFunctions<typename decltype(tag)::type>::compare_trends(a, b, options);
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
        return with_group(group, [&](auto tag) {
          return TrendFunctions<typename decltype(tag)::type>::compare_trends_at(a, b, t0, t1, t,
                                                                                 options);
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
        return with_group(group, [&](auto tag) {
          return TrendFunctions<typename decltype(tag)::type>::compare_velocities(a, b, t0, t1,
                                                                                  options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("t0"), nb::arg("t1"),
      nb::arg("statistic"), nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      "bireg::compare_velocities<G>: the two-sample test of the trends' body velocities.");
  m.def(
      "population_trend",
      [](const std::string& group, const Trends& trends, double t0, double t1, double level,
         double outlier_level) {
        return with_group(group, [&](auto tag) {
          return TrendFunctions<typename decltype(tag)::type>::population_trend(
              trends, t0, t1, level, outlier_level);
        });
      },
      nb::arg("group"), nb::arg("trends"), nb::arg("t0"), nb::arg("t1"), nb::arg("level"),
      nb::arg("outlier_level"),
      "bireg::population_trend<G>: the mean trend, its confidence region, outlying subjects.");
}

}  // namespace bireg_python
