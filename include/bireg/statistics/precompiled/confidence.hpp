// Explicit instantiation declarations of the covariances and quantiles derived from a FitCovariance
// from bireg/statistics/inference/confidence.hpp, for the groups and scalars that the compiled part
// holds (bireg::bireg_precompiled; what it covers and why, in bireg/regression/precompiled.hpp).
// Included at the end of that header when BIREG_PRECOMPILED is defined; it needs nothing the header
// has not declared, so that the headers may include one another in any order.
#pragma once

#include <optional>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/inference/confidence.hpp"

namespace bireg {

// SO(3), double
extern template SO3d::AdMatrix velocity_covariance(const FitCovariance<SO3d>&);
extern template SO3d::AdMatrix pose_covariance(const FitCovariance<SO3d>&, double);
extern template SO3d::AdMatrix prediction_covariance(const FitCovariance<SO3d>&, double);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SO3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SO3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SO3d>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SO3d>&, double,
                                                          QuantileRule);

// SE(3), double
extern template SE3d::AdMatrix velocity_covariance(const FitCovariance<SE3d>&);
extern template SE3d::AdMatrix pose_covariance(const FitCovariance<SE3d>&, double);
extern template SE3d::AdMatrix prediction_covariance(const FitCovariance<SE3d>&, double);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SE3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SE3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SE3d>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SE3d>&, double,
                                                          QuantileRule);

// SE(2), double
extern template SE2d::AdMatrix velocity_covariance(const FitCovariance<SE2d>&);
extern template SE2d::AdMatrix pose_covariance(const FitCovariance<SE2d>&, double);
extern template SE2d::AdMatrix prediction_covariance(const FitCovariance<SE2d>&, double);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SE2d>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SE2d>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SE2d>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SE2d>&, double,
                                                          QuantileRule);

// Sim(3), double
extern template Sim3d::AdMatrix velocity_covariance(const FitCovariance<Sim3d>&);
extern template Sim3d::AdMatrix pose_covariance(const FitCovariance<Sim3d>&, double);
extern template Sim3d::AdMatrix prediction_covariance(const FitCovariance<Sim3d>&, double);
extern template std::optional<double> endpoint_quantile(const FitCovariance<Sim3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<Sim3d>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<Sim3d>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<Sim3d>&, double,
                                                          QuantileRule);

// SO(3), float
extern template SO3f::AdMatrix velocity_covariance(const FitCovariance<SO3f>&);
extern template SO3f::AdMatrix pose_covariance(const FitCovariance<SO3f>&, float);
extern template SO3f::AdMatrix prediction_covariance(const FitCovariance<SO3f>&, float);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SO3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SO3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SO3f>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SO3f>&, double,
                                                          QuantileRule);

// SE(3), float
extern template SE3f::AdMatrix velocity_covariance(const FitCovariance<SE3f>&);
extern template SE3f::AdMatrix pose_covariance(const FitCovariance<SE3f>&, float);
extern template SE3f::AdMatrix prediction_covariance(const FitCovariance<SE3f>&, float);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SE3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SE3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SE3f>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SE3f>&, double,
                                                          QuantileRule);

// SE(2), float
extern template SE2f::AdMatrix velocity_covariance(const FitCovariance<SE2f>&);
extern template SE2f::AdMatrix pose_covariance(const FitCovariance<SE2f>&, float);
extern template SE2f::AdMatrix prediction_covariance(const FitCovariance<SE2f>&, float);
extern template std::optional<double> endpoint_quantile(const FitCovariance<SE2f>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<SE2f>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<SE2f>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<SE2f>&, double,
                                                          QuantileRule);

// Sim(3), float
extern template Sim3f::AdMatrix velocity_covariance(const FitCovariance<Sim3f>&);
extern template Sim3f::AdMatrix pose_covariance(const FitCovariance<Sim3f>&, float);
extern template Sim3f::AdMatrix prediction_covariance(const FitCovariance<Sim3f>&, float);
extern template std::optional<double> endpoint_quantile(const FitCovariance<Sim3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> velocity_quantile(const FitCovariance<Sim3f>&, double,
                                                        QuantileRule);
extern template std::optional<double> pose_quantile(const FitCovariance<Sim3f>&, double,
                                                    QuantileRule);
extern template std::optional<double> prediction_quantile(const FitCovariance<Sim3f>&, double,
                                                          QuantileRule);

}  // namespace bireg
