// bireg_fit for SE(2) and SE(3), the latter with its statistics (fit_command.hpp says why the
// groups are split).
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "fit_run.hpp"

template int bireg_cli::run_fit<bireg::SE2<double>>(const bireg_cli::FitCommand&);
template int bireg_cli::run_fit<bireg::SE3<double>>(const bireg_cli::FitCommand&);
