// What the cohorts layer's binding files share: cohorts.cpp, and the
// subjects' trends of one group (trend_group.hpp, compiled once per group in
// trends_<group>.cpp). The trend functions are instantiated on G x G; in
// one file, the trends of two groups took 3 minutes and 3.5 GB of the
// compiler's memory, so each group's are a file of their own, which -j2
// compiles side by side, and the module has them for every group.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"
#include "fit_handle.hpp"

#include "bireg/statistics/cohorts/two_sample.hpp"

namespace bireg_python {

// The test's options from Python's names; ValueError for an unknown name.
inline bireg::TwoSampleOptions<double> test_options(const std::string& statistic,
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

using Trends = nb::ndarray<const double, nb::ndim<4>, nb::c_contig, nb::device::cpu>;

// The library's functions of subjects' trends (bireg/statistics/cohorts/
// trends.hpp) for group G, each a dict; a refusal, or a fit or mean that
// failed, is a ValueError with the library's message. A trend array is
// numpy's (S, 2, n, n): each subject's (gamma(t0), gamma(t1)).
template <class G>
struct TrendFunctions {
  // bireg::fit_many: every subject's trend on [t0, t1] (NaN: the
  // covariates' range); a subject whose fit failed refuses the whole call.
  static nb::dict fit_many(const std::vector<Vector>& t, const std::vector<Stack>& y, double t0,
                           double t1, int threads, std::size_t first_subject);
  // bireg::compare_trends: the two-sample test in G x G.
  static nb::dict compare_trends(const Trends& a, const Trends& b,
                                 const bireg::TwoSampleOptions<double>& options);
  // bireg::compare_trends_at: the test of the trends' elements at t, in G.
  static nb::dict compare_trends_at(const Trends& a, const Trends& b, double t0, double t1,
                                    double t, const bireg::TwoSampleOptions<double>& options);
  // bireg::compare_velocities: the test of the body velocities, as vectors.
  static nb::dict compare_velocities(const Trends& a, const Trends& b, double t0, double t1,
                                     const bireg::TwoSampleOptions<double>& options);
  // bireg::population_trend: the mean trend, its spread and the outliers.
  static nb::dict population_trend(const Trends& trends, double t0, double t1, double level,
                                   double outlier_level);
};

}  // namespace bireg_python
