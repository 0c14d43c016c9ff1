// libbireg_precompiled: the explicit instantiation definitions for SO(3)
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

template RegressionResult<SO3d> GeodesicRegression<SO3d>::run(
    const std::vector<SO3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SO3d::Element, SO3d::Element>*) const;

template SO3d::AdMatrix velocity_covariance(const FitCovariance<SO3d>&);
template SO3d::AdMatrix pose_covariance(const FitCovariance<SO3d>&, double);
template SO3d::AdMatrix prediction_covariance(const FitCovariance<SO3d>&, double);
template std::optional<double> endpoint_quantile(const FitCovariance<SO3d>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SO3d>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SO3d>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SO3d>&, double,
                                                   QuantileRule);

template FitCovariance<SO3d> covariance(const RegressionResult<SO3d>&, const std::vector<double>&,
                                        const std::vector<double>&, CovarianceFlavour);
template FitCovariance<SO3d> covariance_of(const Geodesic<SO3d>&, const std::vector<SO3d::Tangent>&,
                                           const Problem<double>&, CovarianceFlavour);

template ExplainedVariance<double> explained_variance(const RegressionResult<SO3d>&,
                                                      const MeanResult<SO3d>&,
                                                      const std::vector<double>&);

template MeanResult<SO3d> mean<SO3d>(const std::vector<SO3d::Element>&, const std::vector<double>&,
                                     const MeanOptions<double>&);

template TrendTestResult<SO3d> trend_test(const GeodesicRegression<SO3d>&,
                                          const std::vector<SO3d::Element>&,
                                          const std::vector<double>&, const std::vector<double>&,
                                          const TrendTestOptions&);

template RegressionResult<SO3f> GeodesicRegression<SO3f>::run(
    const std::vector<SO3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SO3f::Element, SO3f::Element>*) const;

template SO3f::AdMatrix velocity_covariance(const FitCovariance<SO3f>&);
template SO3f::AdMatrix pose_covariance(const FitCovariance<SO3f>&, float);
template SO3f::AdMatrix prediction_covariance(const FitCovariance<SO3f>&, float);
template std::optional<double> endpoint_quantile(const FitCovariance<SO3f>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SO3f>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SO3f>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SO3f>&, double,
                                                   QuantileRule);

template FitCovariance<SO3f> covariance(const RegressionResult<SO3f>&, const std::vector<double>&,
                                        const std::vector<float>&, CovarianceFlavour);
template FitCovariance<SO3f> covariance_of(const Geodesic<SO3f>&, const std::vector<SO3f::Tangent>&,
                                           const Problem<float>&, CovarianceFlavour);

template ExplainedVariance<float> explained_variance(const RegressionResult<SO3f>&,
                                                     const MeanResult<SO3f>&,
                                                     const std::vector<float>&);

template MeanResult<SO3f> mean<SO3f>(const std::vector<SO3f::Element>&, const std::vector<float>&,
                                     const MeanOptions<float>&);

template TrendTestResult<SO3f> trend_test(const GeodesicRegression<SO3f>&,
                                          const std::vector<SO3f::Element>&,
                                          const std::vector<double>&, const std::vector<float>&,
                                          const TrendTestOptions&);

}  // namespace bireg
