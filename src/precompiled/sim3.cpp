// libbireg_precompiled: the explicit instantiation definitions for Sim(3)
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

template RegressionResult<Sim3d> GeodesicRegression<Sim3d>::run(
    const std::vector<Sim3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<Sim3d::Element, Sim3d::Element>*) const;

template Sim3d::AdMatrix velocity_covariance(const FitCovariance<Sim3d>&);
template Sim3d::AdMatrix pose_covariance(const FitCovariance<Sim3d>&, double);
template Sim3d::AdMatrix prediction_covariance(const FitCovariance<Sim3d>&, double);
template std::optional<double> endpoint_quantile(const FitCovariance<Sim3d>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<Sim3d>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<Sim3d>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<Sim3d>&, double,
                                                   QuantileRule);

template FitCovariance<Sim3d> covariance(const RegressionResult<Sim3d>&, const std::vector<double>&,
                                         const std::vector<double>&, CovarianceFlavour);
template FitCovariance<Sim3d> covariance_of(const Geodesic<Sim3d>&,
                                            const std::vector<Sim3d::Tangent>&,
                                            const Problem<double>&, CovarianceFlavour);

template ExplainedVariance<double> explained_variance(const RegressionResult<Sim3d>&,
                                                      const MeanResult<Sim3d>&,
                                                      const std::vector<double>&);

template MeanResult<Sim3d> mean<Sim3d>(const std::vector<Sim3d::Element>&,
                                       const std::vector<double>&, const MeanOptions<double>&);

template TrendTestResult<Sim3d> trend_test(const GeodesicRegression<Sim3d>&,
                                           const std::vector<Sim3d::Element>&,
                                           const std::vector<double>&, const std::vector<double>&,
                                           const TrendTestOptions&);

template RegressionResult<Sim3f> GeodesicRegression<Sim3f>::run(
    const std::vector<Sim3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<Sim3f::Element, Sim3f::Element>*) const;

template Sim3f::AdMatrix velocity_covariance(const FitCovariance<Sim3f>&);
template Sim3f::AdMatrix pose_covariance(const FitCovariance<Sim3f>&, float);
template Sim3f::AdMatrix prediction_covariance(const FitCovariance<Sim3f>&, float);
template std::optional<double> endpoint_quantile(const FitCovariance<Sim3f>&, double, QuantileRule);
template std::optional<double> velocity_quantile(const FitCovariance<Sim3f>&, double, QuantileRule);
template std::optional<double> pose_quantile(const FitCovariance<Sim3f>&, double, QuantileRule);
template std::optional<double> prediction_quantile(const FitCovariance<Sim3f>&, double,
                                                   QuantileRule);

template FitCovariance<Sim3f> covariance(const RegressionResult<Sim3f>&, const std::vector<double>&,
                                         const std::vector<float>&, CovarianceFlavour);
template FitCovariance<Sim3f> covariance_of(const Geodesic<Sim3f>&,
                                            const std::vector<Sim3f::Tangent>&,
                                            const Problem<float>&, CovarianceFlavour);

template ExplainedVariance<float> explained_variance(const RegressionResult<Sim3f>&,
                                                     const MeanResult<Sim3f>&,
                                                     const std::vector<float>&);

template MeanResult<Sim3f> mean<Sim3f>(const std::vector<Sim3f::Element>&,
                                       const std::vector<float>&, const MeanOptions<float>&);

template TrendTestResult<Sim3f> trend_test(const GeodesicRegression<Sim3f>&,
                                           const std::vector<Sim3f::Element>&,
                                           const std::vector<double>&, const std::vector<float>&,
                                           const TrendTestOptions&);

}  // namespace bireg
