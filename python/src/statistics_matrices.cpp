// The statistics layer's work for the general matrix groups (statistics_impl.hpp): one
// of two halves of about equal compile time, compiled side by side.
#include "statistics_impl.hpp"

namespace bireg_python {

template struct GroupStatistics<bireg::SL3<double>>;
template struct GroupStatistics<bireg::GLp<3, double>>;

}  // namespace bireg_python
