// bireg_fit: fit a bi-invariant geodesic to a trajectory file.
//
//   bireg_fit --group SO2|SO3|SE2|SE3|Sim3|SL3|GLp3|auto [--format matrix|tum|euroc|kitti]
//             [--times FILE] [--project]
//             [--method exact|series|series_adaptive] [--order M]
//             [--solver paper|optimal_linear|preconditioned|gauss_newton]
//             [--step LAMBDA] [--tol X] [--max-iter K]
//             [--loss huber|cauchy|tukey [--loss-scale C]]
//             [--confidence LEVEL] [--permutations B [--seed S]] [--output-band FILE]
//             [--output-trajectory FILE [--output-format matrix|tum|euroc|kitti]]
//             [--threads N] FILE|-
//
// The formats, their detection when --format is omitted, --times and
// --project are described in include/bireg/io/formats.hpp and README.md.
// SL3 and GLp3 (3x3) read the matrix format only; Sim3 (4x4 [s R t; 0 1])
// also reads the pose formats as scale 1 and writes the matrix format only.
// --group auto reads SE(3) or Sim(3) poses and chooses the motion model they
// need (tools/fit_auto.hpp); it takes the input options and
// --output-trajectory / --output-format only.
// The long spellings of the library's option names are accepted as well:
// --series-order, --step-size, --tolerance, --max-iterations.
//
// --loss fits robustly (bireg/statistics/robust.hpp: reweighting on the
// residuals' Mahalanobis distances, C defaulting to 95% Gaussian
// efficiency); the JSON then has a "robust" object with the flagged
// outliers' input line numbers, and exit code 3 when it did not converge.
//
// For SO3 and SE3 (refused for the other groups, with a message):
// --confidence LEVEL (0 < LEVEL < 1) adds a "confidence" object: the body
// velocity and its standard errors (per covariate unit, i.e. per second),
// the 2d x 2d covariance of the left-trivialised endpoint perturbations in
// both flavours ("homoscedastic": one residual covariance for all
// observations; "heteroscedasticity_robust": the HC2 sandwich), their
// degrees of freedom, and the explained variances against the bi-invariant
// mean (R^2 and Wilks' form); bireg/statistics/covariance.hpp,
// confidence.hpp and explained_variance.hpp. --permutations B (B >= 1)
// [--seed S] (default 0) adds a "trend_test" object: Wilks' Lambda and the
// permutation p-value of "f does not depend on t" (trend_test.hpp).
// --output-band FILE writes a CSV (tools/fit_report.hpp documents the
// columns) of the fitted pose and its homoscedastic confidence
// half-widths at every input timestamp, at the --confidence level (0.95
// if not given). With --loss the covariance treats the final robust
// weights as fixed design weights: a flagged outlier then inflates
// neither the fit nor its covariance (the weights' own dependence on the
// data is ignored, as in the usual IRLS sandwich); the trend test permutes
// the plain fit (the robust weights depend on the covariates, so
// permuting them with fixed weights would not be exchangeable).
// --threads N (default: every core) runs the permuted fits of the trend
// test, the candidates' and cross-validation folds' fits of --group auto,
// and the force of fits of 8192 observations or more, on N threads; the
// output does not depend on N.
// Statistics that are undefined (N = 2, zero residuals, ...) are reported
// in the JSON by "covariance_defined": false (or "defined": false) and a
// "message", never by NaN or null, and give exit code 5
// (the band file is then not written).
//
// Prints one JSON object on stdout. Exit codes: 0 converged, 2 invalid input
// or usage (one line on stderr naming file, line and problem), 3 the fit did
// not converge (the JSON is still printed, with its status), 4 the output
// could not be written (disk full, closed pipe, ...), 5 the fit converged
// but a requested statistic is undefined (the JSON says why).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/robust.hpp"
#include "cli_common.hpp"
#include "entry_points.hpp"
#include "fit_auto.hpp"
#include "fit_report.hpp"

namespace {

using bireg_cli::kExitInvalid;
using bireg_cli::kExitNotConverged;
using bireg_cli::kExitWriteError;
using bireg_cli::parse_count;
using bireg_cli::parse_number;

// The fit converged but a statistic asked for is undefined.
constexpr int kExitUndefined = 5;

constexpr const char* kUsage =
    "usage: bireg_fit --group SO2|SO3|SE2|SE3|Sim3|SL3|GLp3|auto [--format "
    "matrix|tum|euroc|kitti]\n"
    "                 [--times FILE] [--project]\n"
    "                 [--method exact|series|series_adaptive] [--order M]\n"
    "                 [--solver paper|optimal_linear|preconditioned|gauss_newton]\n"
    "                 [--step LAMBDA] [--tol X] [--max-iter K]\n"
    "                 [--loss huber|cauchy|tukey [--loss-scale C]]\n"
    "                 [--confidence LEVEL] [--permutations B [--seed S]] [--output-band FILE]\n"
    "                 [--output-trajectory FILE [--output-format matrix|tum|euroc|kitti]]\n"
    "                 [--threads N] FILE|-\n";

struct Command {
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
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bireg_fit: %s\n", message.c_str());
  return kExitInvalid;
}

// Parses argv into `command`; returns an error message or nothing.
std::optional<std::string> parse_command(int argc, char** argv, Command& command) {
  bool order_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> std::optional<std::string> {
      if (i + 1 >= argc) return std::nullopt;
      return std::string(argv[++i]);
    };
    if (arg == "-" || arg.empty() || arg[0] != '-') {
      if (!command.input.path.empty()) return "more than one input file";
      command.input.path = arg;
      continue;
    }
    if (arg == "--project") {
      command.input.project = true;
      continue;
    }
    const std::optional<std::string> v = value();
    if (!v) return "option " + arg + " needs a value";
    if (arg == "--group") {
      command.group = *v;
    } else if (arg == "--format" || arg == "--output-format") {
      if (auto error = bireg_cli::parse_format(
              *v, arg == "--format" ? command.input.format : command.output_format)) {
        return error;
      }
    } else if (arg == "--times") {
      command.input.times = *v;
    } else if (arg == "--method") {
      bool known = false;
      for (bireg::Method method :
           {bireg::Method::exact, bireg::Method::series, bireg::Method::series_adaptive}) {
        if (*v == bireg::to_string(method)) {
          command.method = method;
          known = true;
        }
      }
      if (!known) return "unknown method '" + *v + "' (exact, series or series_adaptive)";
    } else if (arg == "--order" || arg == "--series-order") {
      if (!parse_count(*v, command.order) || command.order < 1 ||
          command.order > bireg::kMaxSeriesOrder) {
        return "--order needs an integer in [1, " + std::to_string(bireg::kMaxSeriesOrder) + "]";
      }
      order_given = true;
    } else if (arg == "--solver") {
      bool known = false;
      for (bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::optimal_linear,
                                   bireg::Solver::preconditioned, bireg::Solver::gauss_newton}) {
        if (*v == bireg::to_string(solver)) {
          command.solver = solver;
          known = true;
        }
      }
      if (!known) {
        return "unknown solver '" + *v + "' (paper, optimal_linear, preconditioned, gauss_newton)";
      }
    } else if (arg == "--step" || arg == "--step-size") {
      if (!parse_number(*v, command.step) || command.step <= 0) {
        return "--step needs a positive number";
      }
    } else if (arg == "--tol" || arg == "--tolerance") {
      double tol = 0;
      if (!parse_number(*v, tol) || tol < 0) return "--tol needs a non-negative number";
      command.tolerance = tol;
    } else if (arg == "--max-iter" || arg == "--max-iterations") {
      if (!parse_count(*v, command.max_iterations) || command.max_iterations < 1) {
        return "--max-iter needs a positive integer";
      }
    } else if (arg == "--loss") {
      for (bireg::Loss loss : {bireg::Loss::huber, bireg::Loss::cauchy, bireg::Loss::tukey}) {
        if (*v == bireg::to_string(loss)) command.loss = loss;
      }
      if (!command.loss) return "unknown loss '" + *v + "' (huber, cauchy or tukey)";
    } else if (arg == "--loss-scale") {
      if (!parse_number(*v, command.loss_scale) || !(command.loss_scale > 0)) {
        return "--loss-scale needs a positive number";
      }
    } else if (arg == "--confidence") {
      double level = 0;
      if (!parse_number(*v, level) || !(level > 0 && level < 1)) {
        return "--confidence needs a level strictly between 0 and 1, got '" + *v + "'";
      }
      command.confidence = level;
    } else if (arg == "--permutations") {
      double count = 0;
      if (!parse_number(*v, count) || count != std::floor(count) || count < 1 || count > 1e9) {
        return "--permutations needs an integer B >= 1, got '" + *v + "'";
      }
      command.permutations = static_cast<int>(count);
    } else if (arg == "--seed") {
      int seed = 0;
      if (!parse_count(*v, seed)) return "--seed needs an integer in [0, 1e9], got '" + *v + "'";
      command.seed = seed;
    } else if (arg == "--threads") {
      if (auto error = bireg_cli::parse_threads(*v, command.threads)) return error;
    } else if (arg == "--output-band") {
      command.output_band = *v;
    } else if (arg == "--output-trajectory") {
      command.output_trajectory = *v;
    } else {
      return "unknown option " + arg;
    }
  }
  if (command.group.empty()) return "--group is required";
  if (command.output_format && command.output_trajectory.empty()) {
    return "--output-format goes with --output-trajectory FILE";
  }
  if (auto error = bireg_cli::check_input_options(command.input)) return error;
  if (command.method == bireg::Method::series && !order_given)
    return "--method series needs --order M";
  if (command.method != bireg::Method::series && order_given) {
    return "--order applies to --method series only";
  }
  if (command.loss_scale > 0 && !command.loss) return "--loss-scale applies to --loss only";
  if (command.seed && command.permutations == 0) return "--seed goes with --permutations B";
  return std::nullopt;
}

using bireg::io::json_number;

// The groups whose fits get --confidence, --permutations and --output-band.
template <class G>
constexpr bool kHasStatistics =
    std::is_same_v<G, bireg::SO3<double>> || std::is_same_v<G, bireg::SE3<double>>;

// Computes the statistics asked for, writes the band file and fills the
// JSON sections; returns 0, kExitUndefined (a statistic is undefined: the
// JSON says why) or kExitWriteError (the band file could not be written).
template <class G>
int statistics(const Command& command,
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
int run(const Command& command) {
  using Regression = bireg::GeodesicRegression<G>;
  namespace io = bireg::io;
  const std::string name = bireg_cli::display_name(command.input.path);
  if (command.output_format) {
    if (auto problem =
            bireg_cli::output_format_problem<G>(command.output_format, io::Format::matrix))
      return fail(*problem);
  }

  io::Trajectory<G> trajectory;
  if (auto error = bireg_cli::read_input<G>(command.input, trajectory)) return fail(*error);
  if (!command.output_trajectory.empty()) {
    if (auto problem =
            bireg_cli::output_format_problem<G>(command.output_format, trajectory.format))
      return fail(name + ": " + *problem);
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
    const std::uint64_t line =
        result.bad_index >= 0 ? trajectory.lines[static_cast<std::size_t>(result.bad_index)] : 0;
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
      io::render_timestamp(trajectory.last, io::TimeUnit::seconds).c_str(),
      bireg::to_string(result.status), result.iterations, json_number(final_step).c_str(),
      json_number(d.mu_min).c_str(), json_number(d.mu_max).c_str(),
      json_number(d.step_size).c_str(), json_number(d.contraction_factor).c_str(),
      bireg::to_string(command.method), d.series_order, bireg::to_string(command.solver),
      d.backtracks, json_number(d.force_norm).c_str(), json_number(d.residual_rms).c_str(),
      json_number(d.residual_rms_about_mean).c_str(), json_number(d.explained_variance).c_str(),
      json_number(d.largest_residual_angle).c_str(), static_cast<unsigned long long>(farthest_line),
      d.beyond_domain ? "true" : "false");
  if (robust) {
    std::string lines;  // the flagged observations' line numbers in the input
    for (std::size_t i : robust->outliers) {
      lines += (lines.empty() ? "" : ", ") + std::to_string(trajectory.lines[i]);
    }
    std::printf(
        ",\n \"robust\": {\"loss\": \"%s\", \"loss_scale\": %s, \"status\": \"%s\", "
        "\"rounds\": %d, \"outlier_lines\": [%s]}",
        bireg::to_string(robust->loss), json_number(robust->loss_scale).c_str(),
        bireg::to_string(robust->status), robust->rounds, lines.c_str());
  }
  if (!confidence_json.empty()) std::printf(",\n \"confidence\": %s", confidence_json.c_str());
  if (!trend_json.empty()) std::printf(",\n \"trend_test\": %s", trend_json.c_str());
  std::printf("}\n");
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "bireg_fit: <stdout>: write error: %s\n",
                 errno != 0 ? std::strerror(errno) : "unknown");
    return kExitWriteError;
  }
  if (!result.ok() || (robust && !robust->ok())) return kExitNotConverged;
  return undefined ? kExitUndefined : 0;
}

}  // namespace

int bireg_cli::fit_main(int argc, char** argv) {
  Command command;
  if (const auto error = parse_command(argc, argv, command)) {
    std::fprintf(stderr, "bireg_fit: %s\n%s", error->c_str(), kUsage);
    return kExitInvalid;
  }
  if (command.group == "auto") {
    const bool fit_options = command.loss || command.confidence || command.permutations > 0 ||
                             !command.output_band.empty();
    if (fit_options) {
      std::fprintf(stderr,
                   "bireg_fit: --group auto takes the input options and --output-trajectory "
                   "only (--loss, --confidence, --permutations and --output-band need an "
                   "explicit group)\n%s",
                   kUsage);
      return kExitInvalid;
    }
    return bireg_cli::run_auto(
        {command.input, command.output_trajectory, command.output_format, command.threads});
  }
  if (command.group == "SO2") return run<bireg::SO2<double>>(command);
  if (command.group == "SO3") return run<bireg::SO3<double>>(command);
  if (command.group == "SE2") return run<bireg::SE2<double>>(command);
  if (command.group == "SE3") return run<bireg::SE3<double>>(command);
  if (command.group == "Sim3") return run<bireg::Sim3<double>>(command);
  if (command.group == "SL3") return run<bireg::SL3<double>>(command);
  if (command.group == "GLp3") return run<bireg::GLp<3, double>>(command);
  std::fprintf(stderr,
               "bireg_fit: unknown group '%s' (SO2, SO3, SE2, SE3, Sim3, SL3, GLp3 or auto)\n%s",
               command.group.c_str(), kUsage);
  return kExitInvalid;
}
