// bireg_fit --model spline: one bi-invariant cumulative B-spline through the
// whole trajectory (bireg/spline_regression.hpp), fitted by the code
// bireg_smooth --method spline runs (spline_fit.hpp), printed as JSON: the
// control points and knots that define the curve, its status and
// diagnostics and, with an automatic knot spacing, the cross-validation
// that chose it.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/writers.hpp"
#include "cli_common.hpp"
#include "fit_command.hpp"
#include "spline_fit.hpp"

namespace bireg_cli {
namespace {

using bireg::io::json_number;

int fail(const std::string& message) {
  std::fprintf(stderr, "bireg_fit: %s\n", message.c_str());
  return kExitInvalid;
}

// "candidates": one object per knot spacing (or lambda) on the grid, with
// its criterion or the reason it was refused (never a NaN or null).
// `key` names the grid's value ("knot_spacing" or "roughness_penalty").
template <class Selection>
std::string selection_json(const Selection& selection, double chosen, const char* key) {
  std::string text = "{\"chosen\": " + json_number(chosen) +
                     ", \"at_edge\": " + (selection.at_edge ? "true" : "false") +
                     ", \"candidates\": [";
  for (std::size_t k = 0; k < selection.grid.size(); ++k) {
    text +=
        std::string(k ? ",\n   " : "\n   ") + "{\"" + key + "\": " + json_number(selection.grid[k]);
    if (selection.refusals[k].empty()) {
      text += ", \"criterion\": " + json_number(selection.criterion[k]);
    } else {
      text += ", \"refused\": " + json_text(selection.refusals[k]);
    }
    text += ", \"failures\": " + std::to_string(selection.failures[k]) + "}";
  }
  return text + "]}";
}

template <class G>
int run(const FitCommand& command) {
  namespace io = bireg::io;
  const std::string name = display_name(command.input.path);
  io::Trajectory<G> trajectory;
  if (auto problem = read_input_for_output<G>(command.input, command.output_format,
                                              !command.output_trajectory.empty(), trajectory)) {
    return fail(*problem);
  }
  SplineRequest request;
  request.degree = command.degree;
  request.knot_spacing = command.knot_spacing;
  request.roughness_penalty = command.roughness_penalty;
  request.tolerance = command.tolerance;
  if (command.max_iterations_given) request.max_iterations = command.max_iterations;
  request.threads = command.threads;
  request.cv_table = command.cv_table;
  SplineFit<G> spline_fit;
  if (auto code = fit_spline<G>("bireg_fit", request, name, trajectory, spline_fit)) return *code;
  const bireg::SplineResult<G>& fit = spline_fit.fit;
  const bireg::Spline<G>& spline = *fit.spline;

  if (!command.output_trajectory.empty()) {
    const io::Format format = command.output_format.value_or(trajectory.format);
    std::vector<typename G::Element> fitted;
    fitted.reserve(trajectory.covariates.size());
    for (double t : trajectory.covariates)
      fitted.push_back(spline(t));
    if (auto error = write_output<G>(command.output_trajectory, format, trajectory.format,
                                     trajectory.timestamps, fitted)) {
      std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
      return kExitWriteError;
    }
  }

  // The knots in the covariate's unit (seconds for the time formats) after
  // t_min, the input's earliest covariate, as the fit saw them; the curve is
  // defined between the first and the last.
  std::string knots, points;
  for (std::size_t k = 0; k <= spline.segments(); ++k) {
    knots += (k ? ", " : "") +
             json_number(spline.first_knot() + static_cast<double>(k) * spline.knot_spacing());
  }
  for (std::size_t j = 0; j < spline.control_points().size(); ++j) {
    points += (j ? ",\n   " : "\n   ") + io::json_matrix(spline.control_points()[j]);
  }
  const std::uint64_t farthest_line =
      fit.largest_residual_observation >= 0
          ? trajectory.lines[static_cast<std::size_t>(fit.largest_residual_observation)]
          : 0;
  const double final_step = fit.step_norms.empty() ? 0.0 : fit.step_norms.back();
  // "fine": --knot-spacing auto with --roughness-penalty auto
  // (fine_knot_spacing, no cross-validation of the spacing).
  const char* knot_source = spline_fit.selection ? "auto" : command.knot_spacing ? "given" : "fine";
  const std::string projection =
      projection_json(command.input.project, trajectory.projection_correction);
  std::printf(
      "{\"group\": \"%s\", \"format\": \"%s\", \"n\": %zu%s, \"model\": \"spline\",\n"
      " \"t_min\": %s, \"t_max\": %s,\n"
      " \"status\": \"%s\", \"iterations\": %d, \"final_step_norm\": %s, "
      "\"equation_norm\": %s,\n"
      " \"degree\": %d, \"knot_spacing\": %s, \"knot_spacing_source\": \"%s\",\n"
      " \"roughness_penalty\": %s, \"roughness_penalty_source\": \"%s\",\n"
      " \"knots\": [%s],\n"
      " \"control_points\": [%s],\n"
      " \"diagnostics\": {\"largest_residual_angle\": %s, \"largest_residual_line\": %llu, "
      "\"largest_increment_angle\": %s, \"largest_increment\": %td, \"beyond_domain\": %s}",
      G::name, io::to_string(trajectory.format), trajectory.observations.size(), projection.c_str(),
      io::render_timestamp(trajectory.origin, io::TimeUnit::seconds).c_str(),
      io::render_timestamp(trajectory.last, io::TimeUnit::seconds).c_str(),
      bireg::to_string(fit.status), fit.iterations, json_number(final_step).c_str(),
      json_number(fit.equation_norm).c_str(), spline.degree(),
      json_number(spline.knot_spacing()).c_str(), knot_source,
      json_number(fit.roughness_penalty).c_str(), spline_fit.roughness_selection ? "auto" : "given",
      knots.c_str(), points.c_str(), json_number(fit.largest_residual_angle).c_str(),
      static_cast<unsigned long long>(farthest_line),
      json_number(fit.largest_increment_angle).c_str(), fit.largest_increment,
      fit.beyond_domain ? "true" : "false");
  if (spline_fit.selection) {
    std::printf(
        ",\n \"knot_selection\": %s",
        selection_json(*spline_fit.selection, spline_fit.selection->knot_spacing, "knot_spacing")
            .c_str());
  }
  if (spline_fit.roughness_selection) {
    std::printf(
        ",\n \"roughness_selection\": %s",
        selection_json(*spline_fit.roughness_selection,
                       spline_fit.roughness_selection->roughness_penalty, "roughness_penalty")
            .c_str());
  }
  std::printf("}\n");
  if (!stdout_written("bireg_fit")) return kExitWriteError;
  if (!fit.ok()) {
    const std::string why = fit.status == bireg::Status::max_iterations
                                ? "the iteration limit (--max-iter) was reached first"
                            : fit.message.empty() ? "no step reduced the estimating equations"
                                                  : fit.message;
    std::fprintf(stderr, "bireg_fit: %s: the spline fit did not converge (%s): %s; exit code 3\n",
                 name.c_str(), bireg::to_string(fit.status), why.c_str());
    return kExitNotConverged;
  }
  return 0;
}

}  // namespace

int run_spline(const FitCommand& command) {
  if (command.group == "SO2") return run<bireg::SO2<double>>(command);
  if (command.group == "SO3") return run<bireg::SO3<double>>(command);
  if (command.group == "SE2") return run<bireg::SE2<double>>(command);
  if (command.group == "SE3") return run<bireg::SE3<double>>(command);
  for (const char* other : {"Sim3", "SL3", "GLp3"}) {
    if (command.group == other) {
      return fail("--model spline fits SO2, SO3, SE2 and SE3, not " + command.group);
    }
  }
  return fail("unknown group '" + command.group + "' (--model spline fits SO2, SO3, SE2 or SE3)");
}

}  // namespace bireg_cli
