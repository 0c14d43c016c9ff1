// bireg_fit's parsed command line, and the fit of one group it runs
// (fit_run.hpp defines run_fit; fit_spline_run.cpp run_spline). run_fit is explicitly instantiated
// per group family in three translation units (fit_run_rotations.cpp: SO2, SO3; fit_run_poses.cpp:
// SE2, SE3; fit_run_matrix.cpp: Sim3, SL3, GLp3): each group instantiates the fit, the robust fit,
// the readers and the writers, and SO(3) and SE(3) the statistics as well. GCC's compile time grows
// faster than linearly with the template instantiations in one translation
// unit, so three units compile in less CPU time than one, and in parallel.
#pragma once

#include <optional>
#include <string>

#include "bireg/io/formats.hpp"
#include "bireg/regression/solver.hpp"
#include "bireg/regression/status.hpp"
#include "bireg/statistics/robust/loss.hpp"
#include "cli_common.hpp"

namespace bireg_cli {

// The fit converged but a statistic asked for is undefined.
constexpr int kExitUndefined = 5;

struct FitCommand {
  std::string group;
  bireg_cli::InputOptions input;
  bireg::Method method = bireg::Method::exact;
  int order = 0;
  bireg::Solver solver = bireg::Solver::gauss_newton;
  double step = 0;
  std::optional<double> tolerance;
  int max_iterations = 1000;
  std::string output_trajectory;
  std::optional<bireg::io::Format> output_format;  // empty: the input's
  std::optional<bireg::Loss> loss;
  double loss_scale = 0;  // 0: the 95%-efficiency default
  std::optional<double> confidence;
  int permutations = 0;  // 0: no trend test
  std::optional<int> seed;
  std::string output_band;
  int threads = bireg_cli::default_threads();
  // --model spline: one cumulative B-spline of `degree` (fit_spline_run.cpp).
  bool spline = false;
  int degree = 3;
  std::optional<double> knot_spacing;             // the largest, in seconds; empty: auto
  std::optional<double> roughness_penalty = 0.0;  // lambda; empty: auto
  std::string cv_table;                           // --cv-table: the knot spacings' cross-validation
  bool max_iterations_given = false;              // else the spline keeps SplineOptions' default
};

// Reads the input as G, fits it (robustly with --loss), writes
// --output-trajectory, computes the statistics asked for and prints the
// JSON on stdout; returns bireg_fit's exit code (tools/bireg_fit.cpp).
template <class G>
int run_fit(const FitCommand& command);

// --model spline: reads the input as command.group (SO2, SO3, SE2 or SE3),
// fits one spline, writes --output-trajectory and prints the curve's JSON
// (its control points and knots); returns bireg_fit's exit code.
int run_spline(const FitCommand& command);

}  // namespace bireg_cli
