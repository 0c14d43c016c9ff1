// Explicit instantiation declarations of covariance() and covariance_of() from
// bireg/statistics/inference/covariance.hpp, for the groups and scalars that the compiled
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
#include "bireg/statistics/inference/covariance.hpp"

namespace bireg {

// SO(3), double
extern template FitCovariance<SO3d> covariance(const RegressionResult<SO3d>&,
                                               const std::vector<double>&,
                                               const std::vector<double>&, CovarianceFlavour);
extern template FitCovariance<SO3d> covariance_of(const Geodesic<SO3d>&,
                                                  const std::vector<SO3d::Tangent>&,
                                                  const Problem<double>&, CovarianceFlavour);

// SE(3), double
extern template FitCovariance<SE3d> covariance(const RegressionResult<SE3d>&,
                                               const std::vector<double>&,
                                               const std::vector<double>&, CovarianceFlavour);
extern template FitCovariance<SE3d> covariance_of(const Geodesic<SE3d>&,
                                                  const std::vector<SE3d::Tangent>&,
                                                  const Problem<double>&, CovarianceFlavour);

// SE(2), double
extern template FitCovariance<SE2d> covariance(const RegressionResult<SE2d>&,
                                               const std::vector<double>&,
                                               const std::vector<double>&, CovarianceFlavour);
extern template FitCovariance<SE2d> covariance_of(const Geodesic<SE2d>&,
                                                  const std::vector<SE2d::Tangent>&,
                                                  const Problem<double>&, CovarianceFlavour);

// Sim(3), double
extern template FitCovariance<Sim3d> covariance(const RegressionResult<Sim3d>&,
                                                const std::vector<double>&,
                                                const std::vector<double>&, CovarianceFlavour);
extern template FitCovariance<Sim3d> covariance_of(const Geodesic<Sim3d>&,
                                                   const std::vector<Sim3d::Tangent>&,
                                                   const Problem<double>&, CovarianceFlavour);

// SO(3), float
extern template FitCovariance<SO3f> covariance(const RegressionResult<SO3f>&,
                                               const std::vector<double>&,
                                               const std::vector<float>&, CovarianceFlavour);
extern template FitCovariance<SO3f> covariance_of(const Geodesic<SO3f>&,
                                                  const std::vector<SO3f::Tangent>&,
                                                  const Problem<float>&, CovarianceFlavour);

// SE(3), float
extern template FitCovariance<SE3f> covariance(const RegressionResult<SE3f>&,
                                               const std::vector<double>&,
                                               const std::vector<float>&, CovarianceFlavour);
extern template FitCovariance<SE3f> covariance_of(const Geodesic<SE3f>&,
                                                  const std::vector<SE3f::Tangent>&,
                                                  const Problem<float>&, CovarianceFlavour);

// SE(2), float
extern template FitCovariance<SE2f> covariance(const RegressionResult<SE2f>&,
                                               const std::vector<double>&,
                                               const std::vector<float>&, CovarianceFlavour);
extern template FitCovariance<SE2f> covariance_of(const Geodesic<SE2f>&,
                                                  const std::vector<SE2f::Tangent>&,
                                                  const Problem<float>&, CovarianceFlavour);

// Sim(3), float
extern template FitCovariance<Sim3f> covariance(const RegressionResult<Sim3f>&,
                                                const std::vector<double>&,
                                                const std::vector<float>&, CovarianceFlavour);
extern template FitCovariance<Sim3f> covariance_of(const Geodesic<Sim3f>&,
                                                   const std::vector<Sim3f::Tangent>&,
                                                   const Problem<float>&, CovarianceFlavour);

}  // namespace bireg
