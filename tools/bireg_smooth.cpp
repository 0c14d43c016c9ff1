// bireg_smooth: pose and body velocity along a whole trajectory by
// kernel-weighted local geodesic regression (bireg/statistics/smoothing/local_regression.hpp)
// or by one bi-invariant spline (bireg/spline_regression.hpp).
//
//   bireg_smooth --group SO2|SO3|SE2|SE3 [--format matrix|tum|euroc|kitti]
//                [--times FILE] [--project]
//                [--bandwidth H|auto] [--kernel gaussian|epanechnikov|tricube]
//                [--method local|spline] [--degree 1|2|3] [--knot-spacing S|auto]
//                [--roughness-penalty LAMBDA|auto]
//                [--at FILE | --rate HZ] [--velocity FILE] [--cv-table FILE]
//                [--output FILE] [--output-format matrix|tum|euroc|kitti]
//                [--threads N] [--progress] FILE|-
//   bireg_smooth --help | --version
//
// Input as bireg_fit (same formats, detection, --times and --project).
// H is in seconds (frames for KITTI without --times); the kernels and the
// Gaussian's truncation at 4 H are those of the library, and so is the cut
// of every window where it would turn by more than 2.5 rad
// (LocalRegressionOptions::max_turn). "auto" (the default) chooses two
// bandwidths by cross-validation (select_bandwidth) over 20 values from
// half a median sample spacing to the whole range: the poses' by
// leave-one-out prediction, the velocity's against held-out chords, and
// prints both as one line on stderr, and a warning line when a choice is at
// the grid's edge or most values were refused; --cv-table FILE writes the
// curves (CSV: bandwidth, criterion, failures, refused, the same for the
// velocity, and the local cubic velocity's criterion: the velocity's
// degree, quadratic or cubic, is chosen with its bandwidth and printed).
// It costs up to 60 smoothing passes, each window capped in turn
// and in the kernel's support; --progress (or a terminal on stderr) shows
// how far it is after two seconds (and how far the spline's automatic knot
// spacing or roughness penalty is, in fits).
//
// Where the trajectory is evaluated:
//   default    at every input line's timestamp, in input order, each output
//              line carrying its input line's timestamp exactly as written;
//   --at FILE  at the timestamps of FILE, one per line ('#' and blank lines
//              skipped), in the input's convention (seconds; nanoseconds for
//              EuRoC; frame numbers for KITTI without --times), in FILE's
//              order, each written back exactly as FILE spells it. A
//              timestamp outside the data's range [first, last] is refused
//              (exit 2, naming FILE:line): a local fit extrapolated past its
//              data has no data behind it on one side, and its error grows
//              with the distance, so bireg_smooth does not guess;
//   --rate HZ  at first + k / HZ for k = 0, 1, ... up to the last timestamp,
//              each rounded to the nanosecond and computed exactly from the
//              first timestamp's decimal digits (no drift at 1.7e9 s).
//
// --method spline fits one cumulative B-spline of --degree (default 3) to
// the whole trajectory instead (SplineRegression) with uniform knots at
// most S seconds apart; "auto" (the default) chooses S by cross-validation
// (select_knot_spacing over auto_knot_spacing_grid: 24 values from 1.25
// median sample spacings to the whole range, 5 folds), printed on stderr,
// and --cv-table FILE writes its curve (CSV: knot_spacing, criterion,
// failures, refused). --roughness-penalty LAMBDA|auto (default 0: none;
// degree 2 or 3) adds SplineOptions::roughness_penalty; auto chooses lambda
// by the same cross-validation (select_roughness_penalty over
// auto_roughness_penalty_grid) at the knot spacing given or, with
// --knot-spacing auto, at fine_knot_spacing (1.5 median sample spacings,
// not cross-validated), and --cv-table FILE writes that curve (CSV:
// roughness_penalty, criterion, failures, refused); a penalised fit has no
// velocity standard errors (spline_covariance refuses it, said on stderr).
// Poses and velocities are the spline's at the queries,
// the velocity's standard errors from the fit's sandwich covariance
// (spline_covariance; empty fields, with the reason on stderr, where it is
// undefined: noise-free data, no degrees of freedom, or more than 4096
// control-point coordinates). A knot spacing the data cannot determine is invalid input (exit 2); a
// fit that fails marks every row failed (exit 3). --bandwidth and --kernel apply to the local
// method only, --degree, --knot-spacing and --roughness-penalty to the spline only: the other
// method's options are refused.
//
// --threads N (default: every core) shares the queries, and the
// cross-validation of --bandwidth auto, out to N threads in blocks of 1024
// queries; the output does not depend on N.
//
// Output: the smoothed poses in the input's format (or --output-format), to
// stdout or --output, one per query whose local fit succeeded. --velocity
// FILE writes CSV: a header line "t,<coordinates>,<their standard
// errors>,status", the body velocity's tangent coordinates in the group's
// order per second (SO2: w; SO3: wx,wy,wz in rad/s; SE2: vx,vy,w; SE3:
// vx,vy,vz,wx,wy,wz, translation first as in bireg/groups/se3.hpp), then
// se_<name> for each, then "ok" or "failed: <reason>"; t is the output's
// timestamp text. A standard error that is not defined (a window of two
// observations, or residuals that are all zero) is an empty field, and so
// is every number of a failed row.
//
// Exit codes as bireg_fit: 0 every query ok, 2 invalid input or usage (one
// line on stderr naming file, line and problem), 3 some queries failed
// (a window with fewer than two distinct timestamps, or a local fit that
// failed at every width: each named on stderr, the first ten, their poses
// left out -- with KITTI output, which has no timestamps, no poses are
// written -- and their velocity rows marked failed), 4 output could not be
// written. --help and --version print to stdout and exit 0.
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/inference/spline_covariance.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/version.hpp"
#include "cli_common.hpp"
#include "entry_points.hpp"
#include "spline_fit.hpp"

namespace {

using bireg_cli::fit_spline;
using bireg_cli::kExitInvalid;
using bireg_cli::kExitNotConverged;
using bireg_cli::kExitWriteError;
using bireg_cli::parse_number;
using bireg_cli::SplineFit;
using bireg_cli::SplineRequest;

constexpr const char* kUsage =
    "usage: bireg_smooth --group SO2|SO3|SE2|SE3 [--format matrix|tum|euroc|kitti]\n"
    "                    [--times FILE] [--project]\n"
    "                    [--bandwidth H|auto] [--kernel gaussian|epanechnikov|tricube]\n"
    "                    [--method local|spline] [--degree 1|2|3] [--knot-spacing S|auto]\n"
    "                    [--roughness-penalty LAMBDA|auto]\n"
    "                    [--at FILE | --rate HZ] [--velocity FILE] [--cv-table FILE]\n"
    "                    [--output FILE] [--output-format matrix|tum|euroc|kitti]\n"
    "                    [--threads N] [--progress] FILE|-\n"
    "       bireg_smooth --help | --version\n";

constexpr const char* kHelp =
    "Pose and body velocity along a trajectory by kernel-weighted local geodesic\n"
    "regression (bireg/statistics/smoothing/local_regression.hpp), or by one\n"
    "bi-invariant spline (bireg/spline_regression.hpp) with --method spline.\n"
    "\n"
    "  --group G          SO2, SO3, SE2 or SE3 (required)\n"
    "  --format F         input format: matrix, tum, euroc or kitti (default: detected)\n"
    "  --times FILE       timestamps for a KITTI file, one per line\n"
    "  --project          project near-elements onto the group instead of refusing them\n"
    "  --bandwidth H|auto kernel bandwidth in seconds (frames for KITTI without --times);\n"
    "                     auto (default): cross-validation over 20 values from half a\n"
    "                     median sample spacing to the whole range, one choice for the\n"
    "                     poses and one for the velocity, printed on stderr\n"
    "  --kernel K         gaussian (default; truncated at 4 H), epanechnikov or tricube\n"
    "  --method M         local (default): local regression at every query; spline: one\n"
    "                     cumulative B-spline through the whole trajectory\n"
    "  --degree K         the spline's degree, 1, 2 or 3 (default 3)\n"
    "  --knot-spacing S|auto  the spline's largest knot spacing in seconds; auto\n"
    "                     (default): cross-validation over 24 values from 1.25 median\n"
    "                     sample spacings to the whole range, printed on stderr; with\n"
    "                     --roughness-penalty auto: 1.5 median sample spacings\n"
    "  --roughness-penalty LAMBDA|auto  the spline's second-difference penalty, >= 0\n"
    "                     (default 0: none; degree 2 or 3); auto: cross-validation at\n"
    "                     fine knots, printed on stderr (no velocity standard errors)\n"
    "  --at FILE          evaluate at the timestamps in FILE (one per line) instead of\n"
    "                     at every input timestamp\n"
    "  --rate HZ          evaluate at first + k / HZ up to the last timestamp\n"
    "  --velocity FILE    write the body velocity (rad/s; m/s for translations) with\n"
    "                     its standard errors and a status per row, as CSV\n"
    "  --cv-table FILE    write the cross-validation curves of --bandwidth auto (or of\n"
    "                     --knot-spacing auto, or of --roughness-penalty auto) as CSV\n"
    "  --output FILE      the smoothed poses (default: standard output)\n"
    "  --output-format F  their format (default: the input's)\n"
    "  --threads N        threads, 1 to 1024 (default: every core); the output does not\n"
    "                     depend on N\n"
    "  --progress         progress on stderr for long work (default: only when stderr\n"
    "                     is a terminal), never on stdout\n"
    "  --help, --version  this text; the version\n"
    "\n"
    "Exit codes: 0 every row ok; 2 invalid input or usage (one line naming\n"
    "file:line); 3 some rows failed (stderr names them; a failed pose is left out\n"
    "of the pose output, or with KITTI output no poses are written; a failed\n"
    "velocity row says 'failed: <reason>'); 4 output could not be written.\n";

// More queries than this from --rate is a typing error, not a request.
constexpr double kMaxRateQueries = 1e8;

struct Command {
  std::string group;
  bireg_cli::InputOptions input;
  std::optional<double> bandwidth;  // empty: auto
  bireg::Kernel kernel = bireg::Kernel::gaussian;
  bool spline = false;                            // --method spline
  int degree = 3;                                 // the spline's
  std::optional<double> knot_spacing;             // empty: auto
  std::optional<double> roughness_penalty = 0.0;  // empty: auto
  // Options given that belong to one method only, for the refusal of the
  // other's.
  std::vector<std::string> local_options, spline_options;
  std::string at;
  std::optional<double> rate;
  std::string velocity;
  std::string cv_table;
  bool progress = false;
  bool help = false;
  bool version = false;
  std::string output = "-";
  std::optional<bireg::io::Format> output_format;  // empty: the input's
  int threads = bireg_cli::default_threads();
};

int fail(const std::string& message) {
  std::fprintf(stderr, "bireg_smooth: %s\n", message.c_str());
  return kExitInvalid;
}

// Parses argv into `command`; returns an error message or nothing.
std::optional<std::string> parse_command(int argc, char** argv, Command& command) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-" || arg.empty() || arg[0] != '-') {
      if (!command.input.path.empty()) return "more than one input file";
      command.input.path = arg;
      continue;
    }
    if (arg == "--project") {
      command.input.project = true;
      continue;
    }
    if (arg == "--progress") {
      command.progress = true;
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      command.help = true;
      return std::nullopt;
    }
    if (arg == "--version") {
      command.version = true;
      return std::nullopt;
    }
    if (i + 1 >= argc) return "option " + arg + " needs a value";
    const std::string v = argv[++i];
    if (arg == "--group") {
      command.group = v;
    } else if (arg == "--format" || arg == "--output-format") {
      if (auto error = bireg_cli::parse_format(
              v, arg == "--format" ? command.input.format : command.output_format)) {
        return error;
      }
    } else if (arg == "--times") {
      command.input.times = v;
    } else if (arg == "--method") {
      if (v != "local" && v != "spline") return "unknown method '" + v + "' (local or spline)";
      command.spline = v == "spline";
    } else if (arg == "--degree") {
      command.spline_options.push_back(arg);
      if (v != "1" && v != "2" && v != "3") return "--degree needs 1, 2 or 3";
      command.degree = v[0] - '0';
    } else if (arg == "--knot-spacing") {
      command.spline_options.push_back(arg);
      if (auto error = bireg_cli::parse_knot_spacing(v, command.knot_spacing)) return error;
    } else if (arg == "--roughness-penalty") {
      command.spline_options.push_back(arg);
      if (auto error = bireg_cli::parse_roughness_penalty(v, command.roughness_penalty)) {
        return error;
      }
    } else if (arg == "--bandwidth") {
      command.local_options.push_back(arg);
      double h = 0;
      if (v == "auto") {
        command.bandwidth.reset();
      } else if (!parse_number(v, h) || !(h > 0)) {
        return "--bandwidth needs a positive number or auto";
      } else {
        command.bandwidth = h;
      }
    } else if (arg == "--kernel") {
      command.local_options.push_back(arg);
      bool known = false;
      for (bireg::Kernel kernel :
           {bireg::Kernel::gaussian, bireg::Kernel::epanechnikov, bireg::Kernel::tricube}) {
        if (v == bireg::to_string(kernel)) {
          command.kernel = kernel;
          known = true;
        }
      }
      if (!known) return "unknown kernel '" + v + "' (gaussian, epanechnikov or tricube)";
    } else if (arg == "--at") {
      command.at = v;
    } else if (arg == "--rate") {
      double hz = 0;
      if (!parse_number(v, hz) || !(hz > 0)) return "--rate needs a positive number (Hz)";
      command.rate = hz;
    } else if (arg == "--velocity") {
      command.velocity = v;
    } else if (arg == "--cv-table") {
      command.cv_table = v;
    } else if (arg == "--output") {
      command.output = v;
    } else if (arg == "--threads") {
      if (auto error = bireg_cli::parse_threads(v, command.threads)) return error;
    } else {
      return "unknown option " + arg;
    }
  }
  if (command.group.empty()) return "--group is required";
  if (command.spline && !command.local_options.empty()) {
    return command.local_options.front() + " applies to --method local only";
  }
  if (!command.spline && !command.spline_options.empty()) {
    return command.spline_options.front() + " applies to --method spline only";
  }
  // --cv-table writes the curve of an automatic choice: refused without one.
  if (!command.cv_table.empty()) {
    if (command.spline && command.knot_spacing && command.roughness_penalty) {
      return "--cv-table goes with --knot-spacing auto or --roughness-penalty auto";
    }
    if (!command.spline && command.bandwidth) return "--cv-table goes with --bandwidth auto";
  }
  if (command.degree == 1 && command.roughness_penalty != 0.0) {
    return "--roughness-penalty needs --degree 2 or 3 (the penalty couples control points two "
           "apart)";
  }
  if (!command.at.empty() && command.rate) return "--at and --rate exclude each other";
  if (command.at == "-" && command.input.path == "-") {
    return "--at and the input cannot both be standard input";
  }
  return bireg_cli::check_input_options(command.input);
}

// Names of G's tangent coordinates, in the group's order.
template <class G>
std::vector<std::string> tangent_names() {
  if constexpr (std::is_same_v<G, bireg::SO2<double>>) return {"w"};
  if constexpr (std::is_same_v<G, bireg::SE2<double>>) return {"vx", "vy", "w"};
  if constexpr (std::is_same_v<G, bireg::SO3<double>>) return {"wx", "wy", "wz"};
  if constexpr (std::is_same_v<G, bireg::SE3<double>>) {
    return {"vx", "vy", "vz", "wx", "wy", "wz"};
  }
  return {};
}

// origin + k / hz rounded to the nanosecond, exactly when origin is exact.
bireg::io::Timestamp rate_timestamp(const bireg::io::Timestamp& origin, std::uint64_t k, double hz,
                                    bireg::io::TimeUnit unit) {
  namespace io = bireg::io;
  constexpr std::uint64_t kNanosecondsPerSecond = 1000000000ULL;
  constexpr std::uint64_t kFractionPerNanosecond = io::kFractionScale / kNanosecondsPerSecond;
  const double offset_seconds = static_cast<double>(k) / hz;
  const auto offset_ns = static_cast<std::uint64_t>(std::llround(offset_seconds * 1e9));
  io::Timestamp t;
  t.seconds = origin.seconds + static_cast<double>(offset_ns) * 1e-9;
  t.exact = origin.exact;
  if (origin.exact) {
    const std::uint64_t fraction =
        origin.fraction + (offset_ns % kNanosecondsPerSecond) * kFractionPerNanosecond;
    const bool carry = fraction >= io::kFractionScale;
    t.whole = origin.whole + static_cast<std::int64_t>(offset_ns / kNanosecondsPerSecond) +
              (carry ? 1 : 0);
    t.fraction = carry ? fraction - io::kFractionScale : fraction;
  }
  t.text = io::render_timestamp(t, unit);
  return t;
}

// Writes the velocity CSV (header t, the tangent coordinates, se_ of each,
// status); a failed row has empty numbers and "failed: <reason>".
// Returns "path: reason" when it cannot be written.
template <class G>
std::optional<std::string> write_velocity(const std::string& path,
                                          const std::vector<bireg::io::Timestamp>& times,
                                          const std::vector<bireg::LocalEstimate<G>>& estimates) {
  std::string text = "t";
  const std::vector<std::string> names = tangent_names<G>();
  for (const std::string& name : names)
    text += "," + name;
  for (const std::string& name : names)
    text += ",se_" + name;
  text += ",status\n";
  for (std::size_t q = 0; q < estimates.size(); ++q) {
    const bireg::LocalEstimate<G>& e = estimates[q];
    text += times[q].text;
    const bool ok = e.ok();
    for (int k = 0; k < e.velocity.size(); ++k) {
      text += ',';
      if (ok) bireg::io::append_double(text, e.velocity[k]);
    }
    for (int k = 0; k < e.velocity.size(); ++k) {
      text += ',';
      if (ok && e.velocity_error_defined) bireg::io::append_double(text, e.velocity_error[k]);
    }
    text += ',';
    text += ok ? std::string("ok") : bireg_cli::csv_field("failed: " + e.message);
    text += '\n';
  }
  return bireg_cli::write_text_file(path, text);
}

// The cross-validation curves of --bandwidth auto, one row per bandwidth:
// its criteria (empty where refused), failed held-out fits, why a value
// was refused, and the local cubic velocity's criterion (the same fits).
template <class Scalar>
std::optional<std::string> write_cv_table(const std::string& path,
                                          const bireg::BandwidthSelection<Scalar>& selection) {
  namespace io = bireg::io;
  std::string text =
      "bandwidth,criterion,failures,refused,velocity_criterion,velocity_failures,"
      "velocity_refused,cubic_velocity_criterion\n";
  const auto number = [&](Scalar x) {
    if (std::isfinite(x)) io::append_double(text, x);
  };
  for (std::size_t k = 0; k < selection.grid.size(); ++k) {
    number(selection.grid[k]);
    text += ',';
    number(selection.criterion[k]);
    text += ',' + std::to_string(selection.failures[k]) + ',' +
            bireg_cli::csv_field(selection.refusals[k]) + ',';
    number(selection.velocity_criterion[k]);
    text += ',' + std::to_string(selection.velocity_failures[k]) + ',' +
            bireg_cli::csv_field(selection.velocity_refusals[k]) + ',';
    if (k < selection.cubic_velocity_criterion.size()) {
      number(selection.cubic_velocity_criterion[k]);
    }
    text += '\n';
  }
  return bireg_cli::write_text_file(path, text);
}

// The local method: poses at the pose bandwidth and, when --velocity asks
// and the velocity's bandwidth or degree differs, velocities at their own. Returns an
// exit code when it cannot go on.
template <class G>
std::optional<int> local_estimates(const Command& command, const std::string& name,
                                   const bireg::io::Trajectory<G>& trajectory,
                                   const std::vector<double>& queries,
                                   std::vector<bireg::LocalEstimate<G>>& estimates,
                                   std::vector<bireg::LocalEstimate<G>>& velocity_estimates) {
  namespace io = bireg::io;
  bireg::LocalRegressionOptions<double> options;
  options.kernel = command.kernel;
  options.threads = command.threads;
  double velocity_bandwidth = 0;
  int velocity_degree = options.velocity_degree;
  if (command.bandwidth) {
    options.bandwidth = *command.bandwidth;
    velocity_bandwidth = options.bandwidth;
  } else {
    const std::vector<double> grid = bireg::auto_bandwidth_grid(trajectory.covariates);
    bireg_cli::Progress progress("bireg_smooth", command.progress);
    const bireg::BandwidthSelection<double> selection =
        bireg::select_bandwidth<G>(trajectory.observations, trajectory.covariates, options, grid,
                                   [&](std::size_t done, std::size_t total) {
                                     progress.update("bandwidth auto", done, total);
                                   });
    progress.finish();
    if (!command.cv_table.empty()) {
      if (auto error = write_cv_table(command.cv_table, selection)) {
        std::fprintf(stderr, "bireg_smooth: %s\n", error->c_str());
        return kExitWriteError;
      }
    }
    if (!selection.ok()) {
      return fail(name + ": bandwidth auto: " + selection.message + ": give --bandwidth H");
    }
    options.bandwidth = selection.bandwidth;
    velocity_bandwidth = selection.velocity_bandwidth;
    velocity_degree = selection.velocity_degree;
    std::fprintf(stderr,
                 "bireg_smooth: bandwidth auto: %s s for the poses, %s s for the velocity "
                 "(local %s; cross-validation over %zu values from %s to %s s)\n",
                 io::json_number(selection.bandwidth).c_str(),
                 io::json_number(selection.velocity_bandwidth).c_str(),
                 velocity_degree == 3 ? "cubic" : "quadratic", grid.size(),
                 io::json_number(grid.front()).c_str(), io::json_number(grid.back()).c_str());
    if (!selection.message.empty()) {
      std::fprintf(stderr, "bireg_smooth: warning: bandwidth auto: %s\n",
                   selection.message.c_str());
    }
  }
  estimates = bireg::LocalGeodesicRegression<G>(options).smooth_at(trajectory.observations,
                                                                   trajectory.covariates, queries);
  if (!command.velocity.empty() &&
      (velocity_bandwidth != options.bandwidth || velocity_degree != options.velocity_degree)) {
    bireg::LocalRegressionOptions<double> velocity_options = options;
    velocity_options.bandwidth = velocity_bandwidth;
    velocity_options.velocity_degree = velocity_degree;
    velocity_estimates = bireg::LocalGeodesicRegression<G>(velocity_options)
                             .smooth_at(trajectory.observations, trajectory.covariates, queries);
  }
  return std::nullopt;
}

// --method spline: one fit, every query's pose and velocity read off it (as
// LocalEstimate rows, so that the output is written as the local method's).
// Returns an exit code when it cannot go on.
template <class G>
std::optional<int> spline_estimates(const Command& command, const std::string& name,
                                    const bireg::io::Trajectory<G>& trajectory,
                                    const std::vector<double>& queries,
                                    std::vector<bireg::LocalEstimate<G>>& estimates) {
  SplineRequest request;
  request.degree = command.degree;
  request.knot_spacing = command.knot_spacing;
  request.roughness_penalty = command.roughness_penalty;
  request.threads = command.threads;
  request.progress = command.progress;
  request.cv_table = command.cv_table;
  SplineFit<G> spline_fit;
  if (auto code = fit_spline<G>("bireg_smooth", request, name, trajectory, spline_fit)) return code;
  const bireg::SplineResult<G>& fit = spline_fit.fit;
  // The standard errors go to the velocity CSV only: no covariance (up to
  // O((Md)^2) memory and time) unless it is asked for.
  std::optional<bireg::SplineCovariance<G>> covariance;
  if (fit.ok() && !command.velocity.empty()) {
    covariance = bireg::spline_covariance(fit, trajectory.observations, trajectory.covariates);
    if (!covariance->defined()) {
      std::fprintf(stderr, "bireg_smooth: %s: no velocity standard errors: %s\n", name.c_str(),
                   covariance->message.c_str());
    }
  }
  estimates.resize(queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    bireg::LocalEstimate<G>& e = estimates[q];
    e.covariate = queries[q];
    e.status = fit.status;
    e.message = fit.message;
    e.iterations = fit.iterations;
    e.window = trajectory.observations.size();
    e.pose = (*fit.spline)(queries[q]);
    e.velocity = fit.spline->body_velocity(queries[q]);
    if (covariance && covariance->defined()) {
      e.velocity_error =
          bireg::standard_errors(bireg::velocity_covariance(*covariance, queries[q]));
      e.velocity_error_defined = true;
    }
  }
  return std::nullopt;
}

// One line on stderr per failed query, the first kFailuresShown of them.
constexpr std::size_t kFailuresShown = 10;

template <class G>
int run(const Command& command) {
  namespace io = bireg::io;
  const std::string name = bireg_cli::display_name(command.input.path);
  io::Trajectory<G> trajectory;
  if (auto problem = bireg_cli::read_input_for_output<G>(command.input, command.output_format,
                                                         !command.output.empty(), trajectory)) {
    return fail(*problem);
  }
  const io::TimeUnit unit = io::time_unit(trajectory.format);
  // The same refusals, in the same words, as bireg_fit's.
  const std::size_t n = trajectory.observations.size();
  if (n < 2) return fail(name + ": need at least 2 observations, got " + std::to_string(n));
  if (!io::earlier(trajectory.origin, trajectory.last)) {
    return fail(name + ": all covariates are equal: no velocity to estimate");
  }

  // The queries: their timestamps, covariates, and where each came from
  // (for messages).
  std::vector<io::Timestamp> query_times;
  std::vector<double> queries;
  std::vector<std::string> query_places;
  if (!command.at.empty()) {
    std::vector<std::uint64_t> lines;
    if (auto error = bireg_cli::read_query_times(command.at, unit, query_times, lines)) {
      return fail(*error);
    }
    const std::string at_name = bireg_cli::display_name(command.at);
    for (std::size_t q = 0; q < query_times.size(); ++q) {
      const io::Timestamp& t = query_times[q];
      query_places.push_back(bireg_cli::where(at_name, lines[q]));
      if (io::earlier(t, trajectory.origin) || io::earlier(trajectory.last, t)) {
        return fail(query_places.back() + ": timestamp " + io::quote_excerpt(t.text) +
                    " is outside the data's range [" +
                    io::render_timestamp(trajectory.origin, unit) + ", " +
                    io::render_timestamp(trajectory.last, unit) +
                    "]: bireg_smooth does not extrapolate");
      }
      queries.push_back(io::seconds_between(t, trajectory.origin));
    }
  } else if (command.rate) {
    const double span = io::seconds_between(trajectory.last, trajectory.origin);
    const double count = std::floor(span * *command.rate) + 1;
    if (!(count <= kMaxRateQueries)) {
      return fail("--rate " + io::json_number(*command.rate) + " over " + io::json_number(span) +
                  " s asks for more than 1e8 queries");
    }
    for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(count); ++k) {
      io::Timestamp t = rate_timestamp(trajectory.origin, k, *command.rate, unit);
      if (io::earlier(trajectory.last, t)) break;  // the rounding to the nanosecond
      queries.push_back(io::seconds_between(t, trajectory.origin));
      query_places.push_back(name + ": --rate query at " + t.text);
      query_times.push_back(std::move(t));
    }
  } else {
    query_times = trajectory.timestamps;
    queries = trajectory.covariates;
    for (std::uint64_t line : trajectory.lines)
      query_places.push_back(bireg_cli::where(name, line));
  }

  std::vector<bireg::LocalEstimate<G>> estimates, velocity_estimates;
  const std::optional<int> stopped =
      command.spline
          ? spline_estimates<G>(command, name, trajectory, queries, estimates)
          : local_estimates<G>(command, name, trajectory, queries, estimates, velocity_estimates);
  if (stopped) return *stopped;
  const std::vector<bireg::LocalEstimate<G>>& velocities =
      velocity_estimates.empty() ? estimates : velocity_estimates;

  // Failed rows: the query is named on stderr (the first few), its pose is
  // left out of the pose output and its velocity row says why.
  std::size_t failed = 0;
  std::vector<io::Timestamp> pose_times;
  std::vector<typename G::Element> poses;
  poses.reserve(estimates.size());
  for (std::size_t q = 0; q < estimates.size(); ++q) {
    const bireg::LocalEstimate<G>& pose = estimates[q];
    const bireg::LocalEstimate<G>& velocity = velocities[q];
    const bireg::LocalEstimate<G>& bad = pose.ok() ? velocity : pose;
    if (!bad.ok()) {
      if (failed++ < kFailuresShown) {
        std::fprintf(stderr, "bireg_smooth: %s: failed (%s): %s\n", query_places[q].c_str(),
                     &bad == &pose ? "pose" : "velocity", bad.message.c_str());
      }
    }
    if (!pose.ok()) continue;
    poses.push_back(pose.pose);
    pose_times.push_back(query_times[q]);
  }
  if (failed > kFailuresShown) {
    std::fprintf(stderr,
                 "bireg_smooth: %zu queries failed in all (%zu named above; the status column "
                 "of --velocity names each)\n",
                 failed, kFailuresShown);
  }

  const io::Format format = command.output_format.value_or(trajectory.format);
  // KITTI lines carry no timestamp: a reader counts them as frames, so a
  // pose left out would shift every later one. No pose output then.
  if (format == io::Format::kitti && poses.size() < estimates.size()) {
    std::fprintf(stderr,
                 "bireg_smooth: no pose output: KITTI lines have no timestamps, so the %zu "
                 "failed queries cannot be left out (use --output-format tum or matrix)\n",
                 estimates.size() - poses.size());
  } else if (auto error = bireg_cli::write_output<G>(command.output, format, trajectory.format,
                                                     pose_times, poses)) {
    std::fprintf(stderr, "bireg_smooth: %s\n", error->c_str());
    return kExitWriteError;
  }
  if (!command.velocity.empty()) {
    if (auto error = write_velocity<G>(command.velocity, query_times, velocities)) {
      std::fprintf(stderr, "bireg_smooth: %s\n", error->c_str());
      return kExitWriteError;
    }
  }
  return failed == 0 ? 0 : kExitNotConverged;
}

}  // namespace

int bireg_cli::smooth_main(int argc, char** argv) {
  Command command;
  if (const auto error = parse_command(argc, argv, command)) {
    std::fprintf(stderr, "bireg_smooth: %s\n%s", error->c_str(), kUsage);
    return kExitInvalid;
  }
  if (command.help) {
    std::printf("%s\n%s", kUsage, kHelp);
    return 0;
  }
  if (command.version) {
    std::printf("bireg_smooth %s\n", bireg::version);
    return 0;
  }
  if (command.group == "SO2") return run<bireg::SO2<double>>(command);
  if (command.group == "SO3") return run<bireg::SO3<double>>(command);
  if (command.group == "SE2") return run<bireg::SE2<double>>(command);
  if (command.group == "SE3") return run<bireg::SE3<double>>(command);
  std::fprintf(stderr, "bireg_smooth: unknown group '%s' (SO2, SO3, SE2 or SE3)\n%s",
               command.group.c_str(), kUsage);
  return kExitInvalid;
}
