// bireg_smooth: pose and body velocity along a whole trajectory by
// kernel-weighted local geodesic regression (bireg/statistics/local_regression.hpp).
//
//   bireg_smooth --group SO2|SO3|SE2|SE3 [--format matrix|tum|euroc|kitti]
//                [--times FILE] [--project]
//                [--bandwidth H|auto] [--kernel gaussian|epanechnikov|tricube]
//                [--at FILE | --rate HZ] [--velocity FILE]
//                [--output FILE] [--output-format matrix|tum|euroc|kitti]
//                [--threads N] FILE|-
//
// Input as bireg_fit (same formats, detection, --times and --project).
// H is in seconds (frames for KITTI without --times); the kernels and the
// Gaussian's truncation at 4 H are those of the library. "auto" (the
// default) chooses H by leave-one-out cross-validation (select_bandwidth)
// over 20 values from 2 median sample spacings to the whole range, and
// prints the choice as one line on stderr; it costs 20 smoothing passes,
// the widest windows O(N^2) each (give H for long recordings).
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
// --threads N (default: every core) shares the queries, and the
// cross-validation of --bandwidth auto, out to N threads in blocks of 1024
// queries; the output does not depend on N.
//
// Output: the smoothed poses in the input's format (or --output-format), to
// stdout or --output. --velocity FILE writes CSV: a header line
// "t,<coordinates>,<their standard errors>", the body velocity's tangent
// coordinates in the group's order per second (SO2: w; SO3: wx,wy,wz in
// rad/s; SE2: vx,vy,w; SE3: vx,vy,vz,wx,wy,wz, translation first as in
// bireg/groups/se3.hpp), then se_<name> for each; t is the output's
// timestamp text. A standard error that is not defined (a window of two
// observations, or residuals that are all zero) is an empty field.
//
// Exit codes as bireg_fit: 0 every local fit converged, 2 invalid input or
// usage (one line on stderr naming file, line and problem; also a query
// whose kernel window holds fewer than two distinct timestamps: widen H),
// 3 some local fit did not converge (output still written, its last
// iterate; one line per such query on stderr), 4 output could not be written.
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
#include "bireg/statistics/local_regression.hpp"
#include "cli_common.hpp"
#include "entry_points.hpp"

namespace {

using bireg_cli::kExitInvalid;
using bireg_cli::kExitNotConverged;
using bireg_cli::kExitWriteError;
using bireg_cli::parse_number;

constexpr const char* kUsage =
    "usage: bireg_smooth --group SO2|SO3|SE2|SE3 [--format matrix|tum|euroc|kitti]\n"
    "                    [--times FILE] [--project]\n"
    "                    [--bandwidth H|auto] [--kernel gaussian|epanechnikov|tricube]\n"
    "                    [--at FILE | --rate HZ] [--velocity FILE]\n"
    "                    [--output FILE] [--output-format matrix|tum|euroc|kitti]\n"
    "                    [--threads N] FILE|-\n";

// Bandwidths tried by --bandwidth auto.
constexpr int kAutoGridSize = 20;

// More queries than this from --rate is a typing error, not a request.
constexpr double kMaxRateQueries = 1e8;

struct Command {
  std::string group;
  bireg_cli::InputOptions input;
  std::optional<double> bandwidth;  // empty: auto
  bireg::Kernel kernel = bireg::Kernel::gaussian;
  std::string at;
  std::optional<double> rate;
  std::string velocity;
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
    } else if (arg == "--bandwidth") {
      double h = 0;
      if (v == "auto") {
        command.bandwidth.reset();
      } else if (!parse_number(v, h) || !(h > 0)) {
        return "--bandwidth needs a positive number or auto";
      } else {
        command.bandwidth = h;
      }
    } else if (arg == "--kernel") {
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
    } else if (arg == "--output") {
      command.output = v;
    } else if (arg == "--threads") {
      if (auto error = bireg_cli::parse_threads(v, command.threads)) return error;
    } else {
      return "unknown option " + arg;
    }
  }
  if (command.group.empty()) return "--group is required";
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

// Writes the velocity CSV; returns "path: reason" when it cannot.
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
  text += '\n';
  for (std::size_t q = 0; q < estimates.size(); ++q) {
    const bireg::LocalEstimate<G>& e = estimates[q];
    text += times[q].text;
    for (int k = 0; k < e.velocity.size(); ++k) {
      text += ',';
      bireg::io::append_double(text, e.velocity[k]);
    }
    for (int k = 0; k < e.velocity.size(); ++k) {
      text += ',';
      if (e.velocity_error_defined) bireg::io::append_double(text, e.velocity_error[k]);
    }
    text += '\n';
  }
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (!out) return path + ": cannot write file (" + std::strerror(errno) + ")";
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), out) == text.size();
  const bool closed = std::fclose(out) == 0;
  if (!written || !closed) {
    return path + ": write error: " + (errno != 0 ? std::strerror(errno) : "unknown");
  }
  return std::nullopt;
}

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

  bireg::LocalRegressionOptions<double> options;
  options.kernel = command.kernel;
  options.threads = command.threads;
  if (command.bandwidth) {
    options.bandwidth = *command.bandwidth;
  } else {
    const std::vector<double> grid = bireg::bandwidth_grid(trajectory.covariates, kAutoGridSize);
    const bireg::BandwidthSelection<double> selection =
        bireg::select_bandwidth<G>(trajectory.observations, trajectory.covariates, options, grid);
    if (!selection.ok()) {
      return fail(name + ": no bandwidth from " + io::json_number(grid.front()) + " to " +
                  io::json_number(grid.back()) +
                  " s fits every leave-one-out window (the narrowest: " +
                  selection.problems.front() + "): give --bandwidth H");
    }
    options.bandwidth = selection.bandwidth;
    std::fprintf(stderr,
                 "bireg_smooth: bandwidth auto: %s s (leave-one-out cross-validation over %zu "
                 "values from %s to %s s)\n",
                 io::json_number(selection.bandwidth).c_str(), grid.size(),
                 io::json_number(grid.front()).c_str(), io::json_number(grid.back()).c_str());
  }
  const bireg::LocalGeodesicRegression<G> smoother(options);
  const std::vector<bireg::LocalEstimate<G>> estimates =
      smoother.smooth_at(trajectory.observations, trajectory.covariates, queries);

  bool all_converged = true;
  std::vector<typename G::Element> poses;
  poses.reserve(estimates.size());
  for (std::size_t q = 0; q < estimates.size(); ++q) {
    const bireg::LocalEstimate<G>& e = estimates[q];
    if (e.status == bireg::Status::invalid_input) {
      return fail(query_places[q] + ": " + e.message);
    }
    if (!e.ok()) {
      all_converged = false;
      const std::string why = e.message.empty() ? std::string() : ": " + e.message;
      std::fprintf(stderr, "bireg_smooth: %s: the local fit ended %s%s\n", query_places[q].c_str(),
                   bireg::to_string(e.status), why.c_str());
    }
    poses.push_back(e.pose);
  }

  const io::Format format = command.output_format.value_or(trajectory.format);
  if (auto error = bireg_cli::write_output<G>(command.output, format, trajectory.format,
                                              query_times, poses)) {
    std::fprintf(stderr, "bireg_smooth: %s\n", error->c_str());
    return kExitWriteError;
  }
  if (!command.velocity.empty()) {
    if (auto error = write_velocity<G>(command.velocity, query_times, estimates)) {
      std::fprintf(stderr, "bireg_smooth: %s\n", error->c_str());
      return kExitWriteError;
    }
  }
  return all_converged ? 0 : kExitNotConverged;
}

}  // namespace

int bireg_cli::smooth_main(int argc, char** argv) {
  Command command;
  if (const auto error = parse_command(argc, argv, command)) {
    std::fprintf(stderr, "bireg_smooth: %s\n%s", error->c_str(), kUsage);
    return kExitInvalid;
  }
  if (command.group == "SO2") return run<bireg::SO2<double>>(command);
  if (command.group == "SO3") return run<bireg::SO3<double>>(command);
  if (command.group == "SE2") return run<bireg::SE2<double>>(command);
  if (command.group == "SE3") return run<bireg::SE3<double>>(command);
  std::fprintf(stderr, "bireg_smooth: unknown group '%s' (SO2, SO3, SE2 or SE3)\n%s",
               command.group.c_str(), kUsage);
  return kExitInvalid;
}
