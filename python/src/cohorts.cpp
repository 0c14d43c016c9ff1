// The cohorts layer (bireg/statistics/cohorts/): the two-sample test of
// group elements and the element-wise map. Each function calls the
// library's and converts; the GIL is released while it works. A refusal,
// or a mean that failed, is a ValueError with the library's message.
#include <cstddef>
#include <cstdint>
#include <string>

#include "common.hpp"
#include "fit_handle.hpp"

#include "bireg/statistics/cohorts/elementwise.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"

namespace bireg_python {
namespace {

bireg::TwoSampleOptions<double> test_options(const std::string& statistic,
                                             const std::string& variant, int permutations,
                                             std::uint64_t seed, int threads) {
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
  return options;
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
  nb::dict out;
  out["statistic"] = std::string(to_string(result.statistic));
  out["variant"] = std::string(to_string(result.variant));
  out["value"] = result.value;
  out["p_value"] = result.p_value;
  out["permutations"] = result.permutations;
  out["at_least_as_extreme"] = result.at_least_as_extreme;
  out["failed_permutations"] = result.failed_permutations;
  out["mean_a"] = matrix_array(*result.mean_a);
  out["mean_b"] = matrix_array(*result.mean_b);
  out["mean_difference"] = vector_array(result.mean_difference);
  out["covariance_a"] = matrix_array(result.covariance_a);
  out["covariance_b"] = matrix_array(result.covariance_b);
  out["covariance_b_compared"] = matrix_array(result.covariance_b_compared);
  return out;
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
  return out;
}

}  // namespace

void bind_cohorts(nb::module_& m) {
  m.def(
      "two_sample_test",
      [](const std::string& group, const Stack& a, const Stack& b, const std::string& statistic,
         const std::string& variant, int permutations, std::uint64_t seed, int threads) {
        const auto options = test_options(statistic, variant, permutations, seed, threads);
        return with_group(group, [&](auto tag) {
          return two_sample<typename decltype(tag)::type>(a, b, options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), nb::arg("statistic"), nb::arg("variant"),
      nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      "bireg::two_sample_test<G>: a dict with the statistic, p-value, means and covariances.");
  m.def(
      "elementwise_two_sample_test",
      [](const std::string& group, const Stack& a, std::size_t subjects_a, const Stack& b,
         std::size_t subjects_b, std::size_t elements, const std::string& statistic,
         const std::string& variant, int permutations, std::uint64_t seed, int threads,
         const std::string& mode) {
        bireg::ElementwiseOptions<double> options;
        options.test = test_options(statistic, variant, permutations, seed, threads);
        options.mode = parse_choice(
            mode, {bireg::ElementwiseMode::exact, bireg::ElementwiseMode::linearised}, "mode");
        return with_group(group, [&](auto tag) {
          return elementwise<typename decltype(tag)::type>(a, subjects_a, b, subjects_b, elements,
                                                           options);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("subjects_a"), nb::arg("b"), nb::arg("subjects_b"),
      nb::arg("elements"), nb::arg("statistic"), nb::arg("variant"), nb::arg("permutations"),
      nb::arg("seed"), nb::arg("threads"), nb::arg("mode"),
      "bireg::elementwise_two_sample_test<G>: per-element statistics, p-, q- and FWER p-values.");
}

}  // namespace bireg_python
