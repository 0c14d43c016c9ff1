// What bireg's command-line tools share: number and option parsing with the
// same spelling and messages, opening input ("-" is standard input),
// reading a trajectory file with its --times file, writing a trajectory
// file, and the exit codes. Not part of the installed library: the tools
// (bireg_fit, bireg_smooth) include it from tools/.
#pragma once

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include "bireg/io/formats.hpp"
#include "bireg/io/line_reader.hpp"
#include "bireg/io/writers.hpp"

namespace bireg_cli {

constexpr int kExitInvalid = 2;       // invalid input or usage
constexpr int kExitNotConverged = 3;  // a fit, or some rows, failed (output still written)
constexpr int kExitWriteError = 4;    // output could not be written

// A finite number spelt entirely by `text` (strtod's syntax).
inline bool parse_number(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(value);
}

// A non-negative integer up to 1e9.
inline bool parse_count(const std::string& text, int& value) {
  double x = 0;
  if (!parse_number(text, x) || x != std::floor(x) || x < 0 || x > 1e9) return false;
  value = static_cast<int>(x);
  return true;
}

// --threads: the tools use every core unless told otherwise (the library's
// own default is 1). Results do not depend on the count (the library's
// parallel work is split independently of it).
inline int default_threads() {
  const unsigned cores = std::thread::hardware_concurrency();
  return cores == 0 ? 1 : static_cast<int>(std::min(cores, 1024u));
}

// The value of --threads (an integer in [1, 1024]), or the message.
inline std::optional<std::string> parse_threads(const std::string& text, int& threads) {
  if (!parse_count(text, threads) || threads < 1 || threads > 1024) {
    return "--threads needs an integer in [1, 1024], got '" + text + "'";
  }
  return std::nullopt;
}

// The spline's --knot-spacing S|auto: a positive number of seconds, or
// auto (empty), or the message.
inline std::optional<std::string> parse_knot_spacing(const std::string& text,
                                                     std::optional<double>& spacing) {
  double h = 0;
  if (text == "auto") {
    spacing.reset();
  } else if (!parse_number(text, h) || !(h > 0)) {
    return "--knot-spacing needs a positive number or auto, got " + bireg::io::quote_excerpt(text);
  } else {
    spacing = h;
  }
  return std::nullopt;
}

// The spline's --roughness-penalty LAMBDA|auto: a number >= 0 (0: none),
// or auto (empty), or the message.
inline std::optional<std::string> parse_roughness_penalty(const std::string& text,
                                                          std::optional<double>& lambda) {
  double value = 0;
  if (text == "auto") {
    lambda.reset();
  } else if (!parse_number(text, value) || !(value >= 0)) {
    return "--roughness-penalty needs a number >= 0 or auto, got " + bireg::io::quote_excerpt(text);
  } else {
    lambda = value;
  }
  return std::nullopt;
}

// The value of --format / --output-format, or the message naming the choices.
inline std::optional<std::string> parse_format(const std::string& text,
                                               std::optional<bireg::io::Format>& format) {
  format = bireg::io::format_from_string(text);
  if (format) return std::nullopt;
  return "unknown format " + bireg::io::quote_excerpt(text) + " (matrix, tum, euroc or kitti)";
}

// The input file's name as messages show it.
inline std::string display_name(const std::string& path) {
  return path == "-" ? "<stdin>" : path;
}

// "name:line", or just the name for a problem with the whole file.
inline std::string where(const std::string& name, std::uint64_t line) {
  return line > 0 ? name + ":" + std::to_string(line) : name;
}

// The source line of observation `index` (a library result's bad_index),
// or 0 (the whole file) when the result names no observation.
inline std::uint64_t line_of(const std::vector<std::uint64_t>& lines, std::ptrdiff_t index) {
  return index >= 0 ? lines[static_cast<std::size_t>(index)] : 0;
}

// Opens `path` ("-": standard input) for reading as a C stream, or says why
// not (a directory is refused by name: reading it would fail with EISDIR).
inline std::FILE* open_input(const std::string& path, std::string& problem) {
  if (path == "-") return stdin;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    problem = display_name(path) + ": is a directory, not a file";
    return nullptr;
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) problem = display_name(path) + ": cannot open file (" + std::strerror(errno) + ")";
  return file;
}

// How to read the input trajectory: the options the tools share.
struct InputOptions {
  std::string path;                         // "-": standard input
  std::optional<bireg::io::Format> format;  // empty: detect by content
  std::string times;                        // KITTI's times.txt, or empty
  bool project = false;                     // re-orthonormalise rotations
};

// Consistency of the shared input options, checked after parsing.
inline std::optional<std::string> check_input_options(const InputOptions& input) {
  if (!input.times.empty() && input.format && *input.format != bireg::io::Format::kitti) {
    return "--times goes with the kitti format";
  }
  if (input.path.empty()) return "no input file (use - for standard input)";
  return std::nullopt;
}

// Reads the trajectory (and its --times file); returns the one-line message
// naming file and line when the input is invalid.
template <class G>
std::optional<std::string> read_input(const InputOptions& input,
                                      bireg::io::Trajectory<G>& trajectory) {
  namespace io = bireg::io;
  io::ReadOptions read_options;
  read_options.format = input.format;
  read_options.project = input.project;
  std::vector<io::Timestamp> times;
  std::string problem;
  if (!input.times.empty()) {
    std::FILE* file = open_input(input.times, problem);
    if (!file) return problem;
    io::FileSource source(file);
    const auto error = io::read_times(source, times);
    if (file != stdin) std::fclose(file);
    if (error) return where(display_name(input.times), error->line) + ": " + error->message;
    read_options.times = &times;
  }
  const std::string name = display_name(input.path);
  std::FILE* file = open_input(input.path, problem);
  if (!file) return problem;
  io::FileSource source(file);
  const auto error = io::read_trajectory<G>(source, read_options, trajectory);
  if (file != stdin) std::fclose(file);
  if (error) return where(name, error->line) + ": " + error->message;
  if (!input.times.empty() && trajectory.format != io::Format::kitti) {
    return name + ": --times goes with the kitti format, and the input reads as " +
           io::to_string(trajectory.format);
  }
  return std::nullopt;
}

// The JSON member that --project adds to a tool's output: the largest
// change the projection made (nothing without --project).
inline std::string projection_json(bool project, double correction) {
  return project ? ", \"projection_correction\": " + bireg::io::json_number(correction)
                 : std::string();
}

// Why the output trajectory of G cannot be written in `requested` (or, if
// none, in the input's `input` format): a similarity read from a pose file
// (Sim3 reads them as scale 1) has no TUM, EuRoC or KITTI spelling. Checked
// before fitting so that the tool fails before the work, not after it.
template <class G>
std::optional<std::string> output_format_problem(std::optional<bireg::io::Format> requested,
                                                 bireg::io::Format input) {
  const bireg::io::Format format = requested.value_or(input);
  if (bireg::io::supports<G>(format)) return std::nullopt;
  return bireg::io::unsupported_format_message<G>(format) +
         (requested ? "" : " (the input's format; use --output-format matrix)");
}

// read_input with the output-format checks of a tool that may write a
// trajectory around it: an explicit `output_format` is checked before the
// input is read (it does not depend on it), the default one (the input's
// format) after, and only when an output trajectory was asked for
// (`writes_trajectory`). Returns the one-line message of the first problem.
template <class G>
std::optional<std::string> read_input_for_output(const InputOptions& input,
                                                 std::optional<bireg::io::Format> output_format,
                                                 bool writes_trajectory,
                                                 bireg::io::Trajectory<G>& trajectory) {
  if (output_format) {
    if (auto problem = output_format_problem<G>(output_format, bireg::io::Format::matrix)) {
      return problem;
    }
  }
  if (auto error = read_input<G>(input, trajectory)) return error;
  if (writes_trajectory) {
    if (auto problem = output_format_problem<G>(output_format, trajectory.format)) {
      return display_name(input.path) + ": " + *problem;
    }
  }
  return std::nullopt;
}

// Writes `poses` at `timestamps` to `path` ("-": standard output) in
// `format`, timestamps rendered as the `source` format wrote them. Returns
// "path: reason" when the file cannot be written.
template <class G>
std::optional<std::string> write_output(const std::string& path, bireg::io::Format format,
                                        bireg::io::Format source,
                                        const std::vector<bireg::io::Timestamp>& timestamps,
                                        const std::vector<typename G::Element>& poses) {
  const bool to_stdout = path == "-";
  const std::string name = to_stdout ? "<stdout>" : path;
  std::FILE* out = to_stdout ? stdout : std::fopen(path.c_str(), "wb");
  if (!out) return name + ": cannot write file (" + std::strerror(errno) + ")";
  auto error = bireg::io::write_trajectory<G>(out, format, source, timestamps, poses);
  errno = 0;
  const int closed = to_stdout ? std::fflush(out) : std::fclose(out);
  if (closed != 0 && !error) error = std::string("write error: ") + std::strerror(errno);
  if (error) return name + ": " + *error;
  return std::nullopt;
}

// Reads a file of query timestamps (bireg_smooth --at): one timestamp per
// line in `unit` (the input trajectory's convention: seconds, or
// nanoseconds for EuRoC), blank and '#' lines skipped, with each one's line
// number. Returns the one-line message naming file and line when invalid.
inline std::optional<std::string> read_query_times(const std::string& path,
                                                   bireg::io::TimeUnit unit,
                                                   std::vector<bireg::io::Timestamp>& times,
                                                   std::vector<std::uint64_t>& lines) {
  namespace io = bireg::io;
  times.clear();
  lines.clear();
  std::string problem;
  std::FILE* file = open_input(path, problem);
  if (!file) return problem;
  const std::string name = display_name(path);
  io::FileSource source(file);
  io::LineReader reader(source);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::optional<std::string> error;
  while (!error && reader.next(line)) {
    io::split_tokens(line, tokens);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (tokens.size() != 1) {
      error = where(name, reader.line_number()) + ": expected 1 timestamp, found " +
              std::to_string(tokens.size()) + " numbers";
      break;
    }
    io::Timestamp t;
    if (auto bad = io::parse_timestamp(tokens[0], unit, t)) {
      error = where(name, reader.line_number()) + ": " + *bad;
      break;
    }
    times.push_back(std::move(t));
    lines.push_back(reader.line_number());
  }
  if (!error && reader.error()) {
    error = where(name, reader.error()->line) + ": " + reader.error()->message;
  }
  if (file != stdin) std::fclose(file);
  if (!error && times.empty()) error = name + ": no timestamps";
  return error;
}

// Flushes stdout after the JSON: false, with "<tool>: <stdout>: write
// error: reason" on stderr, when it could not be written (disk full, a
// closed pipe); the caller then exits with kExitWriteError.
inline bool stdout_written(const char* tool) {
  errno = 0;
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return true;
  std::fprintf(stderr, "%s: <stdout>: write error: %s\n", tool,
               errno != 0 ? std::strerror(errno) : "unknown");
  return false;
}

// Writes `text` to the file `path`; returns "path: reason" when it cannot.
inline std::optional<std::string> write_text_file(const std::string& path,
                                                  const std::string& text) {
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

// A JSON string literal (quotes, backslashes and control characters escaped).
inline std::string json_text(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A CSV field: as it is, or in double quotes (inner quotes doubled) when it
// holds a comma, a quote or a line break.
inline std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c == '\n' || c == '\r' ? ' ' : c;
  }
  return quoted + "\"";
}

// Progress of long work on stderr, never on stdout: shown when asked
// (--progress) or when stderr is a terminal, and only once the work has run
// for two seconds (short runs stay quiet). On a terminal one line is
// rewritten in place; otherwise a line is written at every tenth.
class Progress {
 public:
  Progress(const char* tool, bool requested)
      : tool_(tool),
        terminal_(isatty(STDERR_FILENO) != 0),
        enabled_(requested || terminal_),
        start_(std::chrono::steady_clock::now()) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  // `done` of `total` units of `what` are finished.
  void update(const char* what, std::size_t done, std::size_t total) {
    if (!enabled_ || total == 0) return;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (seconds < 2.0) return;
    const int percent = static_cast<int>(100.0 * static_cast<double>(done) / total);
    if (!terminal_ && percent / 10 == last_tenth_) return;
    last_tenth_ = percent / 10;
    std::fprintf(stderr, "%s%s: %s: %d%% (%zu of %zu) after %.1f s%s", terminal_ ? "\r" : "", tool_,
                 what, percent, done, total, seconds, terminal_ ? "\033[K" : "\n");
    std::fflush(stderr);
    shown_ = true;
  }

  // Ends the in-place line, so what follows starts on a line of its own.
  void finish() {
    if (shown_ && terminal_) std::fputc('\n', stderr);
    shown_ = false;
  }

 private:
  const char* tool_;
  bool terminal_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  int last_tenth_ = -1;
  bool shown_ = false;
};

}  // namespace bireg_cli
