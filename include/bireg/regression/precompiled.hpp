// The fits that the optional compiled part, libbireg_precompiled
// (src/precompiled/, CMake target bireg::bireg_precompiled), holds
// instantiated: GeodesicRegression<G>::fit and fit_from with the
// observations in a std::vector<G::Element> and the covariates in a
// std::vector<double> (what the io/ readers return), for SO(3), SE(3), SE(2)
// and Sim(3) in double and float.
//
// Included at the end of bireg/regression.hpp when BIREG_PRECOMPILED is
// defined (linking bireg::bireg_precompiled defines it). The declarations
// below are explicit instantiation declarations ([temp.explicit]): a
// translation unit that sees them does not instantiate or optimise these
// fits again but calls the library's copy. Every other use (another group,
// another container, a step rule of your own) is instantiated in place as
// without the library. bireg/statistics/precompiled/ does the same for
// the statistics of README "How sure is the fit", and README "Compile time"
// gives what it saves.
#pragma once

#include <utility>
#include <vector>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"

namespace bireg {

// fit() and fit_from() call run(), which is defined outside the class so
// that these declarations can keep it from being instantiated inline.
extern template RegressionResult<SO3d> GeodesicRegression<SO3d>::run(
    const std::vector<SO3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SO3d::Element, SO3d::Element>*) const;
extern template RegressionResult<SE3d> GeodesicRegression<SE3d>::run(
    const std::vector<SE3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SE3d::Element, SE3d::Element>*) const;
extern template RegressionResult<SE2d> GeodesicRegression<SE2d>::run(
    const std::vector<SE2d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<SE2d::Element, SE2d::Element>*) const;
extern template RegressionResult<Sim3d> GeodesicRegression<Sim3d>::run(
    const std::vector<Sim3d::Element>&, const std::vector<double>&, const std::vector<double>&,
    const std::pair<Sim3d::Element, Sim3d::Element>*) const;

extern template RegressionResult<SO3f> GeodesicRegression<SO3f>::run(
    const std::vector<SO3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SO3f::Element, SO3f::Element>*) const;
extern template RegressionResult<SE3f> GeodesicRegression<SE3f>::run(
    const std::vector<SE3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SE3f::Element, SE3f::Element>*) const;
extern template RegressionResult<SE2f> GeodesicRegression<SE2f>::run(
    const std::vector<SE2f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<SE2f::Element, SE2f::Element>*) const;
extern template RegressionResult<Sim3f> GeodesicRegression<Sim3f>::run(
    const std::vector<Sim3f::Element>&, const std::vector<double>&, const std::vector<float>&,
    const std::pair<Sim3f::Element, Sim3f::Element>*) const;

}  // namespace bireg
