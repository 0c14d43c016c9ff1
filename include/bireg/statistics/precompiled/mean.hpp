// Explicit instantiation declarations of mean() from
// bireg/statistics/inference/mean.hpp, for the groups and scalars that the compiled
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
#include "bireg/statistics/inference/mean.hpp"

namespace bireg {

// SO(3), double
extern template MeanResult<SO3d> mean<SO3d>(const std::vector<SO3d::Element>&,
                                            const std::vector<double>&, const MeanOptions<double>&);

// SE(3), double
extern template MeanResult<SE3d> mean<SE3d>(const std::vector<SE3d::Element>&,
                                            const std::vector<double>&, const MeanOptions<double>&);

// SE(2), double
extern template MeanResult<SE2d> mean<SE2d>(const std::vector<SE2d::Element>&,
                                            const std::vector<double>&, const MeanOptions<double>&);

// Sim(3), double
extern template MeanResult<Sim3d> mean<Sim3d>(const std::vector<Sim3d::Element>&,
                                              const std::vector<double>&,
                                              const MeanOptions<double>&);

// SO(3), float
extern template MeanResult<SO3f> mean<SO3f>(const std::vector<SO3f::Element>&,
                                            const std::vector<float>&, const MeanOptions<float>&);

// SE(3), float
extern template MeanResult<SE3f> mean<SE3f>(const std::vector<SE3f::Element>&,
                                            const std::vector<float>&, const MeanOptions<float>&);

// SE(2), float
extern template MeanResult<SE2f> mean<SE2f>(const std::vector<SE2f::Element>&,
                                            const std::vector<float>&, const MeanOptions<float>&);

// Sim(3), float
extern template MeanResult<Sim3f> mean<Sim3f>(const std::vector<Sim3f::Element>&,
                                              const std::vector<float>&, const MeanOptions<float>&);

}  // namespace bireg
