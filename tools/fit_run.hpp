// The definition of bireg_cli::run_fit (fit_command.hpp), included by the
// three translation units that instantiate it, one per group family.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "cli_common.hpp"
#include "fit_command.hpp"
#include "fit_report.hpp"

namespace bireg_cli {
namespace fit_run_detail {

using bireg::io::json_number;

inline int fail(const std::string& message) {
  std::fprintf(stderr, "bireg_fit: %s\n", message.c_str());
  return kExitInvalid;
}

// Why a fit that did not converge stopped: the status named and explained,
// for the line on stderr that goes with exit code 3.
inline std::string not_converged_reason(bireg::Status status) {
  switch (status) {
    case bireg::Status::max_iterations:
      return "the iteration limit (--max-iter) was reached first";
    case bireg::Status::diverged:
      return "the steps grew without bound";
    case bireg::Status::series_diverged:
      return "a step would leave the region where the series of --method series converges";
    case bireg::Status::no_descent:
      return "no step reduces the estimating equations: the data lie outside the region "
             "where the estimator is defined (e.g. a turn of more than pi)";
    case bireg::Status::converged:
    case bireg::Status::rounding_floor:
    case bireg::Status::invalid_input:
      break;
  }
  return "the fit did not converge";
}

// The groups whose fits get --confidence, --permutations and --output-band.
template <class G>
constexpr bool kHasStatistics =
    std::is_same_v<G, bireg::SO3<double>> || std::is_same_v<G, bireg::SE3<double>>;

// Computes the statistics asked for, writes the band file and fills the
// JSON sections; returns 0, kExitUndefined (a statistic is undefined: the
// JSON says why) or kExitWriteError (the band file could not be written).
template <class G>
int statistics(const FitCommand& command,
               const typename bireg::GeodesicRegression<G>::Options& options,
               const bireg::io::Trajectory<G>& trajectory, const bireg::RegressionResult<G>& result,
               const std::optional<bireg::RobustResult<G>>& robust, std::string& confidence_json,
               std::string& trend_json) {
  using Regression = bireg::GeodesicRegression<G>;
  bool undefined = false;
  const std::vector<double> weights = robust ? robust->robust_weights : std::vector<double>();
  const bool wants_covariance = command.confidence || !command.output_band.empty();
  const double level = command.confidence.value_or(0.95);
  if (wants_covariance) {
    const auto covariances =
        bireg_fit_report::covariances<G>(result, trajectory.covariates, weights);
    if (command.confidence) {
      const auto mean = bireg::mean<G>(trajectory.observations, weights);
      bool defined = false;
      confidence_json = bireg_fit_report::confidence_json(covariances, result, mean, weights, level,
                                                          robust.has_value(), defined);
      undefined = undefined || !defined;
    }
    if (!command.output_band.empty()) {
      std::string problem;
      const std::optional<double> quantile =
          bireg_fit_report::band_quantile(covariances, level, problem);
      if (!quantile) {
        std::fprintf(stderr, "bireg_fit: %s: not written: %s\n", command.output_band.c_str(),
                     problem.c_str());
        undefined = true;
      } else if (auto error = bireg_fit_report::write_band(command.output_band, trajectory,
                                                           covariances.homoscedastic, *quantile)) {
        std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
        return kExitWriteError;
      }
    }
  }
  if (command.permutations > 0) {
    bireg::TrendTestOptions test_options;
    test_options.permutations = command.permutations;
    test_options.seed = static_cast<std::uint64_t>(command.seed.value_or(0));
    test_options.threads = command.threads;
    const auto test = bireg::trend_test(Regression(options), trajectory.observations,
                                        trajectory.covariates, {}, test_options);
    bool defined = false;
    trend_json =
        bireg_fit_report::trend_test_json(test, command.permutations, test_options.seed, defined);
    undefined = undefined || !defined;
  }

  return undefined ? kExitUndefined : 0;
}

template <class G>
int run(const FitCommand& command) {
  using Regression = bireg::GeodesicRegression<G>;
  namespace io = bireg::io;
  const std::string name = bireg_cli::display_name(command.input.path);
  io::Trajectory<G> trajectory;
  if (auto problem = bireg_cli::read_input_for_output<G>(
          command.input, command.output_format, !command.output_trajectory.empty(), trajectory)) {
    return fail(*problem);
  }

  typename Regression::Options options;
  options.method = command.method;
  options.series_order = command.order;
  options.solver = command.solver;
  options.step_size = command.step;
  if (command.tolerance) options.tolerance = *command.tolerance;
  options.max_iterations = command.max_iterations;
  options.threads = command.threads;
  std::optional<bireg::RobustResult<G>> robust;
  typename Regression::Result plain;
  if (command.loss) {
    bireg::RobustOptions<double> robust_options;
    robust_options.loss = *command.loss;
    robust_options.loss_scale = command.loss_scale;
    robust = bireg::RobustGeodesicRegression<G>(robust_options, options)
                 .fit(trajectory.observations, trajectory.covariates);
    if (robust->status == bireg::RobustStatus::invalid_input) {
      return fail(name + ": " + robust->message);
    }
  } else {
    plain = Regression(options).fit(trajectory.observations, trajectory.covariates);
  }
  const auto& result = robust ? robust->fit : plain;
  if (result.status == bireg::Status::invalid_input) {
    const std::uint64_t line = bireg_cli::line_of(trajectory.lines, result.bad_index);
    return fail(bireg_cli::where(name, line) + ": " + result.message);
  }

  if (!command.output_trajectory.empty()) {
    const io::Format format = command.output_format.value_or(trajectory.format);
    std::vector<typename G::Element> fitted;
    fitted.reserve(trajectory.covariates.size());
    for (double t : trajectory.covariates)
      fitted.push_back((*result.geodesic)(t));
    if (auto error = bireg_cli::write_output<G>(command.output_trajectory, format,
                                                trajectory.format, trajectory.timestamps, fitted)) {
      std::fprintf(stderr, "bireg_fit: %s\n", error->c_str());
      return kExitWriteError;
    }
  }

  // The statistics, computed before anything is printed so that the band
  // file and the JSON agree; for the pose and orientation groups only, as
  // each group instantiates the whole statistics layer (minutes of compile
  // time per group).
  const bool wants_statistics =
      command.confidence || command.permutations > 0 || !command.output_band.empty();
  bool undefined = false;
  std::string confidence_json, trend_json;
  if constexpr (kHasStatistics<G>) {
    if (wants_statistics && result.ok()) {
      const int outcome =
          statistics(command, options, trajectory, result, robust, confidence_json, trend_json);
      if (outcome == kExitWriteError) return kExitWriteError;
      undefined = outcome == kExitUndefined;
    }
  } else if (wants_statistics) {
    return fail(std::string("--confidence, --permutations and --output-band are available for "
                            "SO3 and SE3, not ") +
                G::name);
  }
  const auto& d = result.diagnostics;
  // A converged fit whose residuals reach near the log's cut locus answers
  // nothing (regression/diagnostics.hpp): say so on stderr, with the line,
  // unless the robust fit has already set that observation aside.
  const std::uint64_t farthest_line =
      d.largest_residual_observation >= 0
          ? trajectory.lines[static_cast<std::size_t>(d.largest_residual_observation)]
          : 0;
  const bool farthest_is_outlier =
      robust &&
      std::find(robust->outliers.begin(), robust->outliers.end(),
                static_cast<std::size_t>(d.largest_residual_observation)) != robust->outliers.end();
  if (d.beyond_domain && result.ok() && !farthest_is_outlier) {
    std::fprintf(stderr,
                 "bireg_fit: %s: warning: this observation lies %.3g rad from the fitted "
                 "geodesic, beyond 3 pi/4: the data turn by more than pi along the covariate "
                 "(or it is a gross outlier), outside the estimator's domain\n",
                 bireg_cli::where(name, farthest_line).c_str(), double(d.largest_residual_angle));
  }
  // The status that decides the exit code is the top-level "status": the
  // fit's own when it did not converge; else, with --loss, the robust
  // reweighting's (max_rounds, too_few_good, singular_scatter, ...), whose
  // last weighted fit may well have converged ("robust": "fit_status").
  const bool robust_failed = robust && !robust->ok() && result.ok();
  const char* status =
      robust_failed ? bireg::to_string(robust->status) : bireg::to_string(result.status);
  const double final_step = result.step_norms.empty() ? 0.0 : result.step_norms.back();
  const std::string projection =
      bireg_cli::projection_json(command.input.project, trajectory.projection_correction);
  std::printf(
      "{\"group\": \"%s\", \"format\": \"%s\", \"n\": %zu%s,\n \"g0\": %s,\n \"g1\": %s,\n"
      " \"t_min\": %s, \"t_max\": %s,\n"
      " \"status\": \"%s\", \"iterations\": %d, \"final_step_norm\": %s,\n"
      " \"diagnostics\": {\"mu_min\": %s, \"mu_max\": %s, \"step_size\": %s, "
      "\"contraction_factor\": %s, \"method\": \"%s\", \"series_order\": %d, \"solver\": \"%s\", "
      "\"backtracks\": %d, "
      "\"force_norm\": %s, "
      "\"residual_rms\": %s, \"residual_rms_about_mean\": %s, \"explained_variance\": %s, "
      "\"largest_residual_angle\": %s, \"largest_residual_line\": %llu, "
      "\"beyond_domain\": %s}",
      G::name, io::to_string(trajectory.format), trajectory.observations.size(), projection.c_str(),
      io::json_matrix(result.geodesic->start()).c_str(),
      io::json_matrix(result.geodesic->end()).c_str(),
      io::render_timestamp(trajectory.origin, io::TimeUnit::seconds).c_str(),
      io::render_timestamp(trajectory.last, io::TimeUnit::seconds).c_str(), status,
      result.iterations, json_number(final_step).c_str(), json_number(d.mu_min).c_str(),
      json_number(d.mu_max).c_str(), json_number(d.step_size).c_str(),
      json_number(d.contraction_factor).c_str(), bireg::to_string(command.method), d.series_order,
      bireg::to_string(command.solver), d.backtracks, json_number(d.force_norm).c_str(),
      json_number(d.residual_rms).c_str(), json_number(d.residual_rms_about_mean).c_str(),
      json_number(d.explained_variance).c_str(), json_number(d.largest_residual_angle).c_str(),
      static_cast<unsigned long long>(farthest_line), d.beyond_domain ? "true" : "false");
  if (robust) {
    std::string lines;  // the flagged observations' line numbers in the input
    for (std::size_t i : robust->outliers) {
      lines += (lines.empty() ? "" : ", ") + std::to_string(trajectory.lines[i]);
    }
    std::printf(
        ",\n \"robust\": {\"loss\": \"%s\", \"loss_scale\": %s, \"status\": \"%s\", "
        "\"fit_status\": \"%s\", \"rounds\": %d, \"outlier_lines\": [%s]}",
        bireg::to_string(robust->loss), json_number(robust->loss_scale).c_str(),
        bireg::to_string(robust->status), bireg::to_string(result.status), robust->rounds,
        lines.c_str());
  }
  if (!confidence_json.empty()) std::printf(",\n \"confidence\": %s", confidence_json.c_str());
  if (!trend_json.empty()) std::printf(",\n \"trend_test\": %s", trend_json.c_str());
  std::printf("}\n");
  if (!stdout_written("bireg_fit")) return kExitWriteError;
  if (!result.ok() || (robust && !robust->ok())) {
    // Exit code 3 says why on stderr, in the top-level status's words.
    const std::string why = robust_failed ? "the robust fit did not converge (" +
                                                std::string(status) + "): " + robust->message
                                          : "the fit did not converge (" + std::string(status) +
                                                "): " + not_converged_reason(result.status);
    std::fprintf(stderr, "bireg_fit: %s: %s; exit code 3\n", name.c_str(), why.c_str());
    return kExitNotConverged;
  }
  return undefined ? kExitUndefined : 0;
}

}  // namespace fit_run_detail

template <class G>
int run_fit(const FitCommand& command) {
  return fit_run_detail::run<G>(command);
}

}  // namespace bireg_cli
