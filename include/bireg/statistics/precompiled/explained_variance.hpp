// Explicit instantiation declarations of explained_variance() from
// bireg/statistics/inference/explained_variance.hpp, for the groups and scalars that the compiled
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
#include "bireg/statistics/inference/explained_variance.hpp"

namespace bireg {

// SO(3), double
extern template ExplainedVariance<double> explained_variance(const RegressionResult<SO3d>&,
                                                             const MeanResult<SO3d>&,
                                                             const std::vector<double>&);

// SE(3), double
extern template ExplainedVariance<double> explained_variance(const RegressionResult<SE3d>&,
                                                             const MeanResult<SE3d>&,
                                                             const std::vector<double>&);

// SE(2), double
extern template ExplainedVariance<double> explained_variance(const RegressionResult<SE2d>&,
                                                             const MeanResult<SE2d>&,
                                                             const std::vector<double>&);

// Sim(3), double
extern template ExplainedVariance<double> explained_variance(const RegressionResult<Sim3d>&,
                                                             const MeanResult<Sim3d>&,
                                                             const std::vector<double>&);

// SO(3), float
extern template ExplainedVariance<float> explained_variance(const RegressionResult<SO3f>&,
                                                            const MeanResult<SO3f>&,
                                                            const std::vector<float>&);

// SE(3), float
extern template ExplainedVariance<float> explained_variance(const RegressionResult<SE3f>&,
                                                            const MeanResult<SE3f>&,
                                                            const std::vector<float>&);

// SE(2), float
extern template ExplainedVariance<float> explained_variance(const RegressionResult<SE2f>&,
                                                            const MeanResult<SE2f>&,
                                                            const std::vector<float>&);

// Sim(3), float
extern template ExplainedVariance<float> explained_variance(const RegressionResult<Sim3f>&,
                                                            const MeanResult<Sim3f>&,
                                                            const std::vector<float>&);

}  // namespace bireg
