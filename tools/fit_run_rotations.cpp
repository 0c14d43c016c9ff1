// bireg_fit for SO(2) and SO(3), the latter with its statistics (fit_command.hpp says why the
// groups are split).
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "fit_run.hpp"

template int bireg_cli::run_fit<bireg::SO2<double>>(const bireg_cli::FitCommand&);
template int bireg_cli::run_fit<bireg::SO3<double>>(const bireg_cli::FitCommand&);
