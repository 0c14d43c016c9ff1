// Explicit instantiation declarations of trend_test() from
// bireg/statistics/inference/trend_test.hpp, for the groups and scalars that the compiled
// part holds (bireg::bireg_precompiled; what it covers and why, in
// bireg/regression/precompiled.hpp). Included at the end of that header when
// BIREG_PRECOMPILED is defined; it needs nothing the header has not
// declared, so that the headers may include one another in any order.
#pragma once

#include <vector>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/inference/trend_test.hpp"

namespace bireg {

// SO(3), double
extern template TrendTestResult<SO3d> trend_test(const GeodesicRegression<SO3d>&,
                                                 const std::vector<SO3d::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<double>&,
                                                 const TrendTestOptions&);

// SE(3), double
extern template TrendTestResult<SE3d> trend_test(const GeodesicRegression<SE3d>&,
                                                 const std::vector<SE3d::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<double>&,
                                                 const TrendTestOptions&);

// SE(2), double
extern template TrendTestResult<SE2d> trend_test(const GeodesicRegression<SE2d>&,
                                                 const std::vector<SE2d::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<double>&,
                                                 const TrendTestOptions&);

// Sim(3), double
extern template TrendTestResult<Sim3d> trend_test(const GeodesicRegression<Sim3d>&,
                                                  const std::vector<Sim3d::Element>&,
                                                  const std::vector<double>&,
                                                  const std::vector<double>&,
                                                  const TrendTestOptions&);

// SO(3), float
extern template TrendTestResult<SO3f> trend_test(const GeodesicRegression<SO3f>&,
                                                 const std::vector<SO3f::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<float>&,
                                                 const TrendTestOptions&);

// SE(3), float
extern template TrendTestResult<SE3f> trend_test(const GeodesicRegression<SE3f>&,
                                                 const std::vector<SE3f::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<float>&,
                                                 const TrendTestOptions&);

// SE(2), float
extern template TrendTestResult<SE2f> trend_test(const GeodesicRegression<SE2f>&,
                                                 const std::vector<SE2f::Element>&,
                                                 const std::vector<double>&,
                                                 const std::vector<float>&,
                                                 const TrendTestOptions&);

// Sim(3), float
extern template TrendTestResult<Sim3f> trend_test(const GeodesicRegression<Sim3f>&,
                                                  const std::vector<Sim3f::Element>&,
                                                  const std::vector<double>&,
                                                  const std::vector<float>&,
                                                  const TrendTestOptions&);

}  // namespace bireg
