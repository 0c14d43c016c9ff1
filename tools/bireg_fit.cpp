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
//   bireg_fit --group SO2|SO3|SE2|SE3 --model spline [--degree 1|2|3]
//             [--knot-spacing S|auto] [--roughness-penalty LAMBDA|auto]
//             [--cv-table FILE] [input and output options]
//             [--tol X] [--max-iter K] [--threads N] FILE|-
//   bireg_fit --help | --version
//
// --model spline fits one bi-invariant cumulative B-spline of --degree
// (default 3) through the whole trajectory instead of one geodesic
// (bireg/spline_regression.hpp), with uniform knots at most --knot-spacing
// seconds apart, auto (the default) choosing the spacing by
// cross-validation as bireg_smooth --method spline does (--cv-table FILE
// writes that curve). The JSON then holds the curve: "degree",
// "knot_spacing", "knots" (covariates after t_min), "control_points" (one
// matrix each), the status and diagnostics and, for auto, a
// "knot_selection" object with every spacing tried. --roughness-penalty
// LAMBDA|auto (default 0: none; degree 2 or 3) adds the second-difference
// penalty of SplineOptions::roughness_penalty; auto chooses lambda by
// cross-validation at the knot spacing given, or at 1.5 median sample
// spacings with --knot-spacing auto (then "knot_spacing_source" is
// "fine"), and adds "roughness_selection";
// "roughness_penalty" and its "roughness_penalty_source" are always
// there. --output-trajectory
// writes the spline at every input time. The geodesic's solver, series,
// robust and statistics options are refused with it.
//
// --help prints the usage, every option with its default and meaning, and
// the exit codes on stdout; --version prints "bireg_fit <version>"
// (bireg/version.hpp); both exit 0. An option given twice (or under both
// of its spellings, --tol and --tolerance) is refused with exit code 2.
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
// --loss fits robustly (bireg/statistics/robust/regression.hpp: reweighting on the
// residuals' Mahalanobis distances, C defaulting to 95% Gaussian
// efficiency); the JSON then has a "robust" object with the flagged
// outliers' input line numbers and the last weighted fit's "fit_status",
// and exit code 3 when it did not converge: the top-level "status" is then
// the robust one (max_rounds, too_few_good, singular_scatter) if the last
// weighted fit itself converged.
//
// For SO3 and SE3 (refused for the other groups, with a message):
// --confidence LEVEL (0 < LEVEL < 1) adds a "confidence" object: the body
// velocity and its standard errors (per covariate unit, i.e. per second),
// the 2d x 2d covariance of the left-trivialised endpoint perturbations in
// both flavours ("homoscedastic": one residual covariance for all
// observations; "heteroscedasticity_robust": the HC2 sandwich), their
// degrees of freedom, and the explained variances against the bi-invariant
// mean (R^2 and Wilks' form); bireg/statistics/inference/covariance.hpp,
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
// not converge (the JSON is still printed, with the status that decided the
// exit code as its top-level "status", and one line on stderr says why), 4 the output
// could not be written (disk full, closed pipe, ...), 5 the fit converged
// but a requested statistic is undefined (the JSON says why).
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <string>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression/options.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/version.hpp"
#include "cli_common.hpp"
#include "entry_points.hpp"
#include "fit_auto.hpp"
#include "fit_command.hpp"

namespace {

using bireg_cli::kExitInvalid;
using bireg_cli::parse_count;
using bireg_cli::parse_number;

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
    "                 [--threads N] FILE|-\n"
    "       bireg_fit --group SO2|SO3|SE2|SE3 --model spline [--degree 1|2|3]\n"
    "                 [--knot-spacing S|auto] [--roughness-penalty LAMBDA|auto]\n"
    "                 [--cv-table FILE] [--tol X] [--max-iter K] ... FILE|-\n"
    "       bireg_fit --help | --version\n";

// --help: the usage, every option on one line with its meaning and default
// (the defaults shown are the ones the tool uses), and the exit codes.
std::string help_text() {
  const bireg_cli::FitCommand defaults;
  const std::string tolerance =
      bireg::io::format_double(bireg::RegressionOptions<double>().tolerance);
  std::string text = kUsage;
  text +=
      "\nFits a bi-invariant geodesic (or, with --model spline, a spline) to the trajectory in\n"
      "FILE (- for standard input) and prints one JSON object on stdout (README.md,\n"
      "\"bireg_fit\").\n"
      "\nOptions (each at most once):\n"
      "  --group G                 SO2 SO3 SE2 SE3 Sim3 SL3 GLp3, or auto: model of SE3/Sim3 poses "
      "(required)\n"
      "  --format F                input format: matrix, tum, euroc, kitti (default detected from "
      "the content)\n"
      "  --times FILE              KITTI timestamps, one line per pose (default the frame index)\n"
      "  --project                 normalise quaternions, re-orthonormalise rotations (default "
      "off)\n"
      "  --method M                exact, series, series_adaptive: the inverse differentials "
      "(default " +
      std::string(bireg::to_string(defaults.method)) +
      ")\n"
      "  --order M                 series order 1.." +
      std::to_string(bireg::kMaxSeriesOrder) +
      ", needed by --method series only (default none)\n"
      "  --solver S                paper, optimal_linear, preconditioned, gauss_newton: step rule "
      "(default " +
      std::string(bireg::to_string(defaults.solver)) +
      ")\n"
      "  --step LAMBDA             step size of --solver paper, below 2/mu_max (default 1/mu_max)\n"
      "  --tol X                   stop at a step norm <= X; 0: run --max-iter; or --tolerance "
      "(default " +
      tolerance +
      ")\n"
      "  --max-iter K              iteration limit; also spelt --max-iterations (default " +
      std::to_string(defaults.max_iterations) + "; " +
      std::to_string(bireg::SplineOptions<double>().max_iterations) +
      " with --model spline)\n"
      "  --loss L                  huber, cauchy, tukey: fit robustly and flag outliers (default "
      "none)\n"
      "  --loss-scale C            the loss's constant, Mahalanobis units (default 95% "
      "efficiency)\n"
      "  --confidence LEVEL        add velocity, standard errors, covariances, R^2; SO3, SE3 "
      "(default none)\n"
      "  --permutations B          add the permutation trend test, B >= 1; SO3, SE3 (default "
      "none)\n"
      "  --seed S                  the trend test's random seed, with --permutations (default 0)\n"
      "  --output-band FILE        CSV of fitted poses and confidence half-widths; SO3, SE3 "
      "(default none)\n"
      "  --model M                 geodesic, or spline: one cumulative B-spline; SO2 SO3 SE2 SE3 "
      "(default geodesic)\n"
      "  --degree K                the spline's degree, 1, 2 or 3 (default 3)\n"
      "  --knot-spacing S|auto     the spline's largest knot spacing in seconds, or auto: "
      "cross-validated (default auto)\n"
      "  --roughness-penalty L|auto  the spline's second-difference penalty, >= 0, degree 2 "
      "or 3; auto: cross-validated at fine knots (default 0: none)\n"
      "  --cv-table FILE           CSV of the knot spacings (or penalties) tried by auto "
      "(default none)\n"
      "  --output-trajectory FILE  write the fitted curve at every input time (default none)\n"
      "  --output-format F         the format of --output-trajectory (default the input's)\n"
      "  --threads N               threads; the output does not depend on N (default every core: " +
      std::to_string(defaults.threads) +
      ")\n"
      "  --help, -h                print this help on stdout and exit 0\n"
      "  --version                 print \"bireg_fit <version>\" on stdout and exit 0\n"
      "\nExit codes:\n"
      "  0  the fit converged (and every statistic asked for is defined)\n"
      "  2  invalid input or usage: one line on stderr names the file, line and problem\n"
      "  3  the fit, or with --loss the robust reweighting, did not converge: the JSON is\n"
      "     still printed, its \"status\" says which, and one line on stderr says why\n"
      "  4  the output could not be written (disk full, closed pipe, ...)\n"
      "  5  the fit converged but a statistic asked for is undefined (the JSON says why)\n";
  return text;
}

// The option an argument spells, its library alias mapped to the short
// name, so that --tol and --tolerance count as one option.
std::string canonical_option(const std::string& arg) {
  if (arg == "--series-order") return "--order";
  if (arg == "--step-size") return "--step";
  if (arg == "--tolerance") return "--tol";
  if (arg == "--max-iterations") return "--max-iter";
  return arg;
}

// What the command line asks for besides a fit.
enum class Request { fit, help, version };

// Parses argv into `command`; returns an error message or nothing. --help
// and --version, where an option may stand, end the parsing and set
// `request` (the options before them must be valid).
std::optional<std::string> parse_command(int argc, char** argv, bireg_cli::FitCommand& command,
                                         Request& request) {
  bool order_given = false;
  std::set<std::string> given;
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
    if (arg == "--help" || arg == "-h" || arg == "--version") {
      request = arg == "--version" ? Request::version : Request::help;
      return std::nullopt;
    }
    const std::string option = canonical_option(arg);
    if (!given.insert(option).second) {
      return "option " + option + " given more than once" +
             (option != arg ? " (" + arg + " is another spelling of it)" : std::string());
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
      command.max_iterations_given = true;
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
    } else if (arg == "--model") {
      if (*v != "geodesic" && *v != "spline") {
        return "unknown model '" + *v + "' (geodesic or spline)";
      }
      command.spline = *v == "spline";
    } else if (arg == "--degree") {
      if (*v != "1" && *v != "2" && *v != "3") return "--degree needs 1, 2 or 3";
      command.degree = (*v)[0] - '0';
    } else if (arg == "--knot-spacing") {
      if (auto error = bireg_cli::parse_knot_spacing(*v, command.knot_spacing)) return error;
    } else if (arg == "--roughness-penalty") {
      if (auto error = bireg_cli::parse_roughness_penalty(*v, command.roughness_penalty)) {
        return error;
      }
    } else if (arg == "--cv-table") {
      command.cv_table = *v;
    } else {
      return "unknown option " + arg;
    }
  }
  if (command.group.empty()) return "--group is required";
  if (command.output_format && command.output_trajectory.empty()) {
    return "--output-format goes with --output-trajectory FILE";
  }
  if (auto error = bireg_cli::check_input_options(command.input)) return error;
  // Each model's own options, refused with the other.
  for (const char* option : {"--degree", "--knot-spacing", "--roughness-penalty", "--cv-table"}) {
    if (!command.spline && given.count(option)) {
      return std::string(option) + " applies to --model spline only";
    }
  }
  for (const char* option : {"--method", "--order", "--solver", "--step", "--loss", "--loss-scale",
                             "--confidence", "--permutations", "--seed", "--output-band"}) {
    if (command.spline && given.count(option)) {
      return std::string(option) + " applies to --model geodesic only";
    }
  }
  if (command.spline && command.group == "auto") {
    return "--group auto chooses among geodesic motion models: give the group with --model "
           "spline";
  }
  if (command.method == bireg::Method::series && !order_given)
    return "--method series needs --order M";
  if (command.method != bireg::Method::series && order_given) {
    return "--order applies to --method series only";
  }
  if (command.loss_scale > 0 && !command.loss) return "--loss-scale applies to --loss only";
  if (command.seed && command.permutations == 0) return "--seed goes with --permutations B";
  if (command.degree == 1 && command.roughness_penalty != 0.0) {
    return "--roughness-penalty needs --degree 2 or 3 (the penalty couples control points two "
           "apart)";
  }
  if (command.cv_table.size() && command.knot_spacing && command.roughness_penalty) {
    return "--cv-table goes with --knot-spacing auto or --roughness-penalty auto";
  }
  return std::nullopt;
}

}  // namespace

int bireg_cli::fit_main(int argc, char** argv) {
  bireg_cli::FitCommand command;
  Request request = Request::fit;
  if (const auto error = parse_command(argc, argv, command, request)) {
    std::fprintf(stderr, "bireg_fit: %s\n%s", error->c_str(), kUsage);
    return kExitInvalid;
  }
  if (request != Request::fit) {
    const std::string text =
        request == Request::help ? help_text() : std::string("bireg_fit ") + bireg::version + "\n";
    if (std::fputs(text.c_str(), stdout) == EOF || std::fflush(stdout) != 0) {
      std::fprintf(stderr, "bireg_fit: <stdout>: write error\n");
      return bireg_cli::kExitWriteError;
    }
    return 0;
  }
  if (command.spline) return bireg_cli::run_spline(command);
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
  if (command.group == "SO2") return bireg_cli::run_fit<bireg::SO2<double>>(command);
  if (command.group == "SO3") return bireg_cli::run_fit<bireg::SO3<double>>(command);
  if (command.group == "SE2") return bireg_cli::run_fit<bireg::SE2<double>>(command);
  if (command.group == "SE3") return bireg_cli::run_fit<bireg::SE3<double>>(command);
  if (command.group == "Sim3") return bireg_cli::run_fit<bireg::Sim3<double>>(command);
  if (command.group == "SL3") return bireg_cli::run_fit<bireg::SL3<double>>(command);
  if (command.group == "GLp3") return bireg_cli::run_fit<bireg::GLp<3, double>>(command);
  std::fprintf(stderr,
               "bireg_fit: unknown group '%s' (SO2, SO3, SE2, SE3, Sim3, SL3, GLp3 or auto)\n%s",
               command.group.c_str(), kUsage);
  return kExitInvalid;
}
