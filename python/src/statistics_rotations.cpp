// The statistics layer's work for the groups with a rotation (statistics_impl.hpp): one
// of two halves of about equal compile time, compiled side by side.
#include "statistics_impl.hpp"

namespace bireg_python {

template struct GroupStatistics<bireg::SO2d>;
template struct GroupStatistics<bireg::SO3d>;
template struct GroupStatistics<bireg::SE2d>;
template struct GroupStatistics<bireg::SE3d>;
template struct GroupStatistics<bireg::Sim3d>;

}  // namespace bireg_python
