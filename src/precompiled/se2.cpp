// libbireg_precompiled: the explicit instantiation definitions for SE(2)
// in double and float, one for each declaration in bireg/regression/
// precompiled.hpp and bireg/statistics/precompiled/ (one file per group, so
// that the library builds in parallel). tests/precompiled/check_lists.cmake
// checks that the declarations and these definitions are the same list.
#include <optional>
#include <utility>
#include <vector>

#include "bireg/regression/precompiled.hpp"
#include "bireg/statistics/precompiled/confidence.hpp"
#include "bireg/statistics/precompiled/covariance.hpp"
#include "bireg/statistics/precompiled/explained_variance.hpp"
#include "bireg/statistics/precompiled/mean.hpp"
#include "bireg/statistics/precompiled/trend_test.hpp"

namespace bireg {

template RegressionResult<SE2d> GeodesicRegression<SE2d>::run(
    const std::vector<SE2d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SE2d::Element, SE2d::Element>*) const;

template SE2d::AdMatrix velocity_covariance(const FitCovariance<SE2d>&);
template SE2d::AdMatrix pose_covariance(const FitCovariance<SE2d>&, double);
template SE2d::AdMatrix prediction_covariance(const FitCovariance<SE2d>&, double);
template std::optional<double> endpoint_quantile(const FitCovariance<SE2d>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SE2d>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SE2d>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SE2d>&, double,
                                                   QuantileRule);

template FitCovariance<SE2d> covariance(const RegressionResult<SE2d>&, const std::vector<double>&,
                                        const std::vector<double>&, CovarianceFlavour);
template FitCovariance<SE2d> covariance_of(const Geodesic<SE2d>&, const std::vector<SE2d::Tangent>&,
                                           const Problem<double>&, CovarianceFlavour);

template ExplainedVariance<double> explained_variance(const RegressionResult<SE2d>&,
                                                      const MeanResult<SE2d>&,
                                                      const std::vector<double>&);

template MeanResult<SE2d> mean<SE2d>(const std::vector<SE2d::Element>&, const std::vector<double>&,
                                     const MeanOptions<double>&);

template TrendTestResult<SE2d> trend_test(const GeodesicRegression<SE2d>&,
                                          const std::vector<SE2d::Element>&,
                                          const std::vector<double>&, const std::vector<double>&,
                                          const TrendTestOptions&);

template RegressionResult<SE2f> GeodesicRegression<SE2f>::run(
    const std::vector<SE2f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SE2f::Element, SE2f::Element>*) const;

template SE2f::AdMatrix velocity_covariance(const FitCovariance<SE2f>&);
template SE2f::AdMatrix pose_covariance(const FitCovariance<SE2f>&, float);
template SE2f::AdMatrix prediction_covariance(const FitCovariance<SE2f>&, float);
template std::optional<double> endpoint_quantile(const FitCovariance<SE2f>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SE2f>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SE2f>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SE2f>&, double,
                                                   QuantileRule);

template FitCovariance<SE2f> covariance(const RegressionResult<SE2f>&, const std::vector<double>&,
                                        const std::vector<float>&, CovarianceFlavour);
template FitCovariance<SE2f> covariance_of(const Geodesic<SE2f>&, const std::vector<SE2f::Tangent>&,
                                           const Problem<float>&, CovarianceFlavour);

template ExplainedVariance<float> explained_variance(const RegressionResult<SE2f>&,
                                                     const MeanResult<SE2f>&,
                                                     const std::vector<float>&);

template MeanResult<SE2f> mean<SE2f>(const std::vector<SE2f::Element>&, const std::vector<float>&,
                                     const MeanOptions<float>&);

template TrendTestResult<SE2f> trend_test(const GeodesicRegression<SE2f>&,
                                          const std::vector<SE2f::Element>&,
                                          const std::vector<double>&, const std::vector<float>&,
                                          const TrendTestOptions&);

}  // namespace bireg
