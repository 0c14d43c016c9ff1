// SE(2)'s fit, compiled alone (fit_handle.hpp, GroupFitter, says why).
#include "fit_group.hpp"

template struct bireg_python::GroupFitter<bireg::SE2d>;
