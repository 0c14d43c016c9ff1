// SE(2)'s trend functions, compiled alone (cohorts.hpp says why).
#include "trend_group.hpp"

template struct bireg_python::TrendFunctions<bireg::SE2d>;
