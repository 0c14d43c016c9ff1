// bireg_fit for Sim(3), SL(3) and GL+(3) (fit_command.hpp says why the groups are split).
#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/sim3.hpp"
#include "fit_run.hpp"

template int bireg_cli::run_fit<bireg::Sim3<double>>(const bireg_cli::FitCommand&);
template int bireg_cli::run_fit<bireg::SL3<double>>(const bireg_cli::FitCommand&);
template int bireg_cli::run_fit<bireg::GLp<3, double>>(const bireg_cli::FitCommand&);
