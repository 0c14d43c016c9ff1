// bireg: everything at once (the groups, the concept, geodesics, the
// regression and the statistics built on it: means, covariances and
// confidence regions, the trend test, robust fits, model selection and
// local regression). The trajectory file formats (bireg/io/) are not
// included. Including only what you use compiles faster.
#pragma once

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/spline.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/cohorts/elementwise.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"
#include "bireg/statistics/inference/scatter.hpp"
#include "bireg/statistics/inference/spline_covariance.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/robust/loss.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
