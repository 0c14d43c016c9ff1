// The trend functions of one group (TrendFunctions<G>, cohorts.hpp),
// included by that group's trends_<group>.cpp alone.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cohorts.hpp"

#include "bireg/statistics/cohorts/trends.hpp"

namespace bireg_python {
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
nb::dict TrendFunctions<G>::fit_many(const std::vector<Vector>& t, const std::vector<Stack>& y,
                                     double t0, double t1, int threads, std::size_t first_subject) {
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
nb::dict TrendFunctions<G>::compare_trends(const Trends& a, const Trends& b,
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
nb::dict TrendFunctions<G>::compare_trends_at(const Trends& a, const Trends& b, double t0,
                                              double t1, double t,
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
nb::dict TrendFunctions<G>::compare_velocities(const Trends& a, const Trends& b, double t0,
                                               double t1,
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
nb::dict TrendFunctions<G>::population_trend(const Trends& trends, double t0, double t1,
                                             double level, double outlier_level) {
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

}  // namespace bireg_python
