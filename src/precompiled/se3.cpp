// libbireg_precompiled: the explicit instantiation definitions for SE(3)
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

template RegressionResult<SE3d> GeodesicRegression<SE3d>::run(
    const std::vector<SE3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SE3d::Element, SE3d::Element>*) const;

template SE3d::AdMatrix velocity_covariance(const FitCovariance<SE3d>&);
template SE3d::AdMatrix pose_covariance(const FitCovariance<SE3d>&, double);
template SE3d::AdMatrix prediction_covariance(const FitCovariance<SE3d>&, double);
template std::optional<double> endpoint_quantile(const FitCovariance<SE3d>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SE3d>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SE3d>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SE3d>&, double,
                                                   QuantileRule);

template FitCovariance<SE3d> covariance(const RegressionResult<SE3d>&, const std::vector<double>&,
                                        const std::vector<double>&, CovarianceFlavour);
template FitCovariance<SE3d> covariance_of(const Geodesic<SE3d>&, const std::vector<SE3d::Tangent>&,
                                           const Problem<double>&, CovarianceFlavour);

template ExplainedVariance<double> explained_variance(const RegressionResult<SE3d>&,
                                                      const MeanResult<SE3d>&,
                                                      const std::vector<double>&);

template MeanResult<SE3d> mean<SE3d>(const std::vector<SE3d::Element>&, const std::vector<double>&,
                                     const MeanOptions<double>&);

template TrendTestResult<SE3d> trend_test(const GeodesicRegression<SE3d>&,
                                          const std::vector<SE3d::Element>&,
                                          const std::vector<double>&, const std::vector<double>&,
                                          const TrendTestOptions&);

template RegressionResult<SE3f> GeodesicRegression<SE3f>::run(
    const std::vector<SE3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SE3f::Element, SE3f::Element>*) const;

template SE3f::AdMatrix velocity_covariance(const FitCovariance<SE3f>&);
template SE3f::AdMatrix pose_covariance(const FitCovariance<SE3f>&, float);
template SE3f::AdMatrix prediction_covariance(const FitCovariance<SE3f>&, float);
template std::optional<double> endpoint_quantile(const FitCovariance<SE3f>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<SE3f>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<SE3f>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<SE3f>&, double,
                                                   QuantileRule);

template FitCovariance<SE3f> covariance(const RegressionResult<SE3f>&, const std::vector<double>&,
                                        const std::vector<float>&, CovarianceFlavour);
template FitCovariance<SE3f> covariance_of(const Geodesic<SE3f>&, const std::vector<SE3f::Tangent>&,
                                           const Problem<float>&, CovarianceFlavour);

template ExplainedVariance<float> explained_variance(const RegressionResult<SE3f>&,
                                                     const MeanResult<SE3f>&,
                                                     const std::vector<float>&);

template MeanResult<SE3f> mean<SE3f>(const std::vector<SE3f::Element>&, const std::vector<float>&,
                                     const MeanOptions<float>&);

template TrendTestResult<SE3f> trend_test(const GeodesicRegression<SE3f>&,
                                          const std::vector<SE3f::Element>&,
                                          const std::vector<double>&, const std::vector<float>&,
                                          const TrendTestOptions&);

}  // namespace bireg
