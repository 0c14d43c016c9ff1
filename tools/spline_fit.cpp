// bireg_cli::fit_spline (spline_fit.hpp), instantiated for the groups the
// tools fit splines in.
#include "spline_fit.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/writers.hpp"
#include "cli_common.hpp"

namespace bireg_cli {
namespace {

// The cross-validation curve of --knot-spacing auto or --roughness-penalty
// auto, one row per grid value (`name`: knot_spacing or
// roughness_penalty): its criterion (empty where refused), failed fits,
// and why it was refused.
std::optional<std::string> write_curve_table(const std::string& path, const char* name,
                                             const bireg::SplineGridCurve<double>& curve) {
  std::string text = std::string(name) + ",criterion,failures,refused\n";
  for (std::size_t k = 0; k < curve.grid.size(); ++k) {
    bireg::io::append_double(text, curve.grid[k]);
    text += ',';
    if (std::isfinite(curve.criterion[k])) bireg::io::append_double(text, curve.criterion[k]);
    text += ',' + std::to_string(curve.failures[k]) + ',' +
            bireg_cli::csv_field(curve.refusals[k]) + '\n';
  }
  return bireg_cli::write_text_file(path, text);
}

int fail(const char* tool, const std::string& message) {
  std::fprintf(stderr, "%s: %s\n", tool, message.c_str());
  return kExitInvalid;
}

}  // namespace

template <class G>
std::optional<int> fit_spline(const char* tool, const SplineRequest& request,
                              const std::string& name, const bireg::io::Trajectory<G>& trajectory,
                              SplineFit<G>& out) {
  namespace io = bireg::io;
  bireg::SplineOptions<double> options;
  options.degree = request.degree;
  options.threads = request.threads;
  if (request.tolerance) options.tolerance = *request.tolerance;
  if (request.max_iterations) options.max_iterations = *request.max_iterations;
  out.selection.reset();
  out.roughness_selection.reset();
  const bool roughness_auto = !request.roughness_penalty.has_value();
  // A lambda given is the model whose knot spacing is cross-validated.
  if (!roughness_auto) options.roughness_penalty = *request.roughness_penalty;
  if (request.knot_spacing) {
    options.knot_spacing = *request.knot_spacing;
  } else if (roughness_auto) {
    // Fine knots, lambda does the smoothing: no knot spacing to choose.
    options.knot_spacing = bireg::fine_knot_spacing(trajectory.covariates);
    std::fprintf(stderr,
                 "%s: knot spacing auto with --roughness-penalty auto: %s s (1.5 median sample "
                 "spacings)\n",
                 tool, io::json_number(options.knot_spacing).c_str());
  } else {
    const std::vector<double> grid = bireg::auto_knot_spacing_grid(trajectory.covariates);
    Progress progress(tool, request.progress);
    out.selection =
        bireg::select_knot_spacing<G>(trajectory.observations, trajectory.covariates, options, grid,
                                      5, [&](std::size_t done, std::size_t total) {
                                        progress.update("knot spacing auto", done, total);
                                      });
    progress.finish();
    const bireg::KnotSpacingSelection<double>& selection = *out.selection;
    if (!request.cv_table.empty()) {
      if (auto error = write_curve_table(request.cv_table, "knot_spacing", selection)) {
        std::fprintf(stderr, "%s: %s\n", tool, error->c_str());
        return kExitWriteError;
      }
    }
    if (!selection.ok()) {
      return fail(tool,
                  name + ": knot spacing auto: " + selection.message + ": give --knot-spacing S");
    }
    options.knot_spacing = selection.knot_spacing;
    std::fprintf(stderr,
                 "%s: knot spacing auto: %s s (cross-validation over %zu values from %s to %s s)\n",
                 tool, io::json_number(selection.knot_spacing).c_str(), grid.size(),
                 io::json_number(grid.front()).c_str(), io::json_number(grid.back()).c_str());
    if (!selection.message.empty()) {
      std::fprintf(stderr, "%s: warning: knot spacing auto: %s\n", tool, selection.message.c_str());
    }
  }
  if (roughness_auto) {
    const std::vector<double> grid =
        bireg::auto_roughness_penalty_grid(trajectory.covariates, double(options.knot_spacing));
    Progress progress(tool, request.progress);
    out.roughness_selection =
        bireg::select_roughness_penalty<G>(trajectory.observations, trajectory.covariates, options,
                                           grid, 5, [&](std::size_t done, std::size_t total) {
                                             progress.update("roughness penalty auto", done, total);
                                           });
    progress.finish();
    const bireg::RoughnessPenaltySelection<double>& selection = *out.roughness_selection;
    if (!request.cv_table.empty()) {
      if (auto error = write_curve_table(request.cv_table, "roughness_penalty", selection)) {
        std::fprintf(stderr, "%s: %s\n", tool, error->c_str());
        return kExitWriteError;
      }
    }
    if (!selection.ok()) {
      return fail(tool, name + ": roughness penalty auto: " + selection.message +
                            ": give --roughness-penalty LAMBDA or a wider --knot-spacing");
    }
    options.roughness_penalty = selection.roughness_penalty;
    std::size_t tried = 0;
    for (const std::string& refusal : selection.refusals)
      tried += refusal.rfind("not tried", 0) == 0 ? 0 : 1;
    std::fprintf(stderr,
                 "%s: roughness penalty auto: %s (cross-validation over %zu of %zu values from "
                 "%s to %s)\n",
                 tool, io::json_number(selection.roughness_penalty).c_str(), tried,
                 selection.grid.size(), io::json_number(selection.grid.front()).c_str(),
                 io::json_number(selection.grid.back()).c_str());
    if (!selection.message.empty()) {
      std::fprintf(stderr, "%s: warning: roughness penalty auto: %s\n", tool,
                   selection.message.c_str());
    }
  }
  out.fit = bireg::SplineRegression<G>(options).fit(trajectory.observations, trajectory.covariates);
  const bireg::SplineResult<G>& fit = out.fit;
  if (fit.status == bireg::Status::invalid_input) {
    const std::uint64_t line = bireg_cli::line_of(trajectory.lines, fit.bad_index);
    return fail(tool, bireg_cli::where(name, line) + ": " + fit.message);
  }
  // Near the log's cut locus (SplineResult::beyond_domain): say where.
  if (fit.ok() && fit.largest_residual_angle > bireg::kBeyondDomainAngle<double>) {
    const auto observation = static_cast<std::size_t>(fit.largest_residual_observation);
    std::fprintf(stderr,
                 "%s: %s: warning: this observation lies %.3g rad from the fitted spline, "
                 "beyond 3 pi/4: a gross outlier, or motion too fast for the knots\n",
                 tool, bireg_cli::where(name, trajectory.lines[observation]).c_str(),
                 fit.largest_residual_angle);
  }
  if (fit.ok() && fit.largest_increment_angle > bireg::kBeyondDomainAngle<double>) {
    std::fprintf(stderr,
                 "%s: %s: warning: the spline turns by %.3g rad between control points %td and "
                 "%td, beyond 3 pi/4 (a half turn is where it jumps): use a narrower "
                 "--knot-spacing\n",
                 tool, name.c_str(), fit.largest_increment_angle, fit.largest_increment - 1,
                 fit.largest_increment);
  }
  return std::nullopt;
}

template std::optional<int> fit_spline(const char*, const SplineRequest&, const std::string&,
                                       const bireg::io::Trajectory<bireg::SO2<double>>&,
                                       SplineFit<bireg::SO2<double>>&);
template std::optional<int> fit_spline(const char*, const SplineRequest&, const std::string&,
                                       const bireg::io::Trajectory<bireg::SO3<double>>&,
                                       SplineFit<bireg::SO3<double>>&);
template std::optional<int> fit_spline(const char*, const SplineRequest&, const std::string&,
                                       const bireg::io::Trajectory<bireg::SE2<double>>&,
                                       SplineFit<bireg::SE2<double>>&);
template std::optional<int> fit_spline(const char*, const SplineRequest&, const std::string&,
                                       const bireg::io::Trajectory<bireg::SE3<double>>&,
                                       SplineFit<bireg::SE3<double>>&);

}  // namespace bireg_cli
