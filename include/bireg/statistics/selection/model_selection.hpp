// bireg: model selection, three questions: which motion model a pose
// sequence requires (selection/motion_models.hpp) and whether an element
// moves along its covariate at all (selection/static_or_geodesic.hpp),
// and which curve the data need along it, geodesic, piecewise geodesic or
// cubic spline (selection/curve_selection.hpp), with the criterion they
// share (selection/criteria.hpp).
#pragma once

#include "bireg/statistics/selection/criteria.hpp"
#include "bireg/statistics/selection/curve_selection.hpp"
#include "bireg/statistics/selection/motion_models.hpp"
#include "bireg/statistics/selection/static_or_geodesic.hpp"
