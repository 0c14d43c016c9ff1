// The spline fit both tools run: bireg_smooth --method spline reads poses
// and velocities off it at its queries, bireg_fit --model spline prints
// the curve itself. One translation unit (spline_fit.cpp) instantiates it
// for SO2, SO3, SE2 and SE3, so that the two tools do not compile the
// spline fit and its knot selection twice.
#pragma once

#include <optional>
#include <string>

#include "bireg/io/formats.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
#include "bireg/statistics/smoothing/spline_roughness.hpp"

namespace bireg_cli {

struct SplineRequest {
  int degree = 3;
  std::optional<double> knot_spacing;  // the largest spacing in seconds; empty: auto
  // lambda of the roughness penalty (SplineOptions::roughness_penalty);
  // empty: auto, by cross-validation at the knot spacing given or, with
  // none, at fine_knot_spacing.
  std::optional<double> roughness_penalty = 0.0;
  std::optional<double> tolerance;    // empty: SplineOptions' default
  std::optional<int> max_iterations;  // empty: SplineOptions' default
  int threads = 1;
  // Progress of an automatic choice on stderr even when it is not a
  // terminal (bireg_cli::Progress; on a terminal it is always shown).
  bool progress = false;
  // An automatic knot spacing or penalty only: where to write its
  // cross-validation table (empty: nowhere).
  std::string cv_table;
};

template <class G>
struct SplineFit {
  bireg::SplineResult<G> fit;
  // With an automatic knot spacing: the cross-validation that chose it.
  std::optional<bireg::KnotSpacingSelection<double>> selection;
  // With an automatic roughness penalty: the cross-validation that chose it.
  std::optional<bireg::RoughnessPenaltySelection<double>> roughness_selection;
};

// Chooses the knot spacing (the one given, or by cross-validation over
// auto_knot_spacing_grid, the choice said on one line of stderr) and the
// roughness penalty (the one given, or by cross-validation over
// auto_roughness_penalty_grid at the knot spacing given or at
// fine_knot_spacing, said on stderr likewise), fits one
// spline to the trajectory and warns on stderr where it comes near the
// principal log's cut locus; every line on stderr starts with "<tool>: ".
// Returns an exit code when the tool cannot go on, its reason printed:
// kExitInvalid for input the fit refuses or an automatic spacing that
// could not be chosen, kExitWriteError when the table was not written. A
// fit that ran but did not converge is the caller's to report (out.fit).
template <class G>
std::optional<int> fit_spline(const char* tool, const SplineRequest& request,
                              const std::string& name, const bireg::io::Trajectory<G>& trajectory,
                              SplineFit<G>& out);

}  // namespace bireg_cli
