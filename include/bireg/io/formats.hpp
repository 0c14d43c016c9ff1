// bireg io: trajectory files as text, read into group elements.
//
// Formats (one observation per line; blank lines and lines whose first
// non-blank character is '#' are skipped; numbers are separated by commas
// and/or white space):
//   matrix  t, m00, m01, ..., m(n-1)(n-1): the covariate then the n x n
//           matrix row-major, any group.
//   tum     timestamp tx ty tz qx qy qz qw (seconds; quaternion w last), for
//           SE3, or SO3 using the rotation. Sim3 reads tum, euroc and kitti
//           too, as similarities of scale 1, and writes the matrix format
//           only (see reads<G> and supports<G>).
//   euroc   timestamp p_x p_y p_z q_w q_x q_y q_z [more columns] (comma-
//           separated, timestamp in integer nanoseconds, quaternion w first;
//           columns after the eighth, such as EuRoC ground truth's
//           velocities and biases, are ignored unread), for SE3 or SO3.
//   kitti   r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz (the 3x4 pose
//           row-major, no timestamp; times come from a separate file, one
//           per line, or are the frame indices 0, 1, 2, ...), for SE3 or SO3.
// Quaternions are normalised; one whose norm is off 1 by more than 1e-3 is an
// error, and a matrix farther than 1e-6 from the group is an error, unless
// ReadOptions::project is set (SO2, SO3, SE2, SE3): then quaternions are
// normalised and rotation blocks replaced by their nearest rotation (SVD),
// the largest change reported; a quaternion of norm below 1e-6 and a block
// whose nearest rotation is not unique (rank < 2) are errors even then.
//
// Detection (ReadOptions::format empty): groups other than SO3, SE3 and Sim3
// read the matrix format. For SO3, SE3 and Sim3 the first data line decides: a format
// is a candidate when the line has its shape (matrix: 1 + n^2 numbers; tum:
// 8 numbers, no comma; kitti: 12 numbers, no comma; euroc: 8 numbers or
// more, comma-separated, an integer first column, and a '#' header line
// containing "timestamp" before the data). Several candidates are narrowed
// to those the line is a valid element in; if that does not leave exactly
// one, the input is ambiguous (an error naming the candidates); no
// candidate is an error naming the line.
//
// Timestamps are kept as text and exactly (see numbers.hpp); the covariate
// of an observation is its time in seconds (or the matrix covariate's own
// unit) after the earliest timestamp, computed exactly then rounded once.
// Never throws on bad input: every problem is a ParseError naming the line.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SVD>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/line_reader.hpp"
#include "bireg/io/numbers.hpp"

namespace bireg {
namespace io {

enum class Format { matrix, tum, euroc, kitti };

inline const char* to_string(Format format) {
  switch (format) {
    case Format::matrix:
      return "matrix";
    case Format::tum:
      return "tum";
    case Format::euroc:
      return "euroc";
    case Format::kitti:
      return "kitti";
  }
  return "?";
}

inline std::optional<Format> format_from_string(std::string_view name) {
  for (Format f : {Format::matrix, Format::tum, Format::euroc, Format::kitti}) {
    if (name == to_string(f)) return f;
  }
  return std::nullopt;
}

inline TimeUnit time_unit(Format format) {
  return format == Format::euroc ? TimeUnit::nanoseconds : TimeUnit::seconds;
}

// Whether G's elements can be read from (and written to) `format`.
template <class G>
constexpr bool is_pose_group() {
  return std::is_same_v<G, SE3<double>> || std::is_same_v<G, SO3<double>>;
}
template <class G>
constexpr bool supports(Format format) {
  return format == Format::matrix || is_pose_group<G>();
}
// Whether a trajectory of G can be read from `format`: Sim(3) also reads the
// pose formats, a rigid pose being a similarity of scale 1 (bireg_fit
// --group auto reads SE(3) and Sim(3) data in one pass this way). Writing
// is by `supports`: a similarity has no TUM, EuRoC or KITTI spelling.
template <class G>
constexpr bool reads(Format format) {
  return supports<G>(format) || std::is_same_v<G, Sim3<double>>;
}
// Why G has no spelling in `format`: the message for !reads<G> on reading
// and !supports<G> on writing.
template <class G>
std::string unsupported_format_message(Format format) {
  return std::string("the ") + to_string(format) + " format holds SE3 or SO3 poses, not " + G::name;
}
// Whether ReadOptions::project applies to G.
template <class G>
constexpr bool can_project() {
  return is_pose_group<G>() || std::is_same_v<G, SE2<double>> || std::is_same_v<G, SO2<double>>;
}

struct ReadOptions {
  std::optional<Format> format;  // empty: detect from the content
  bool project = false;
  // How far a matrix or KITTI line's rotation may be from orthonormal (a
  // non-negative number); a rotation made from a normalised quaternion (TUM,
  // EuRoC) is one to rounding and is not checked.
  double element_tolerance = 1e-6;
  // kitti: the timestamp of every pose, in order; null: frame indices.
  const std::vector<Timestamp>* times = nullptr;
};

template <class G>
struct Trajectory {
  std::vector<typename G::Element> observations;
  std::vector<double> covariates;  // seconds after `origin`
  std::vector<Timestamp> timestamps;
  std::vector<std::uint64_t> lines;  // source line of each observation
  Format format = Format::matrix;    // as read (detected or given)
  Timestamp origin, last;            // the earliest and the latest timestamp
  double projection_correction = 0;  // largest change made by projection
};

// `from` as a trajectory of another group with the same matrices (rigid
// poses read as SE(3), seen as similarities of scale 1 in Sim(3)).
template <class To, class From>
Trajectory<To> rebind_trajectory(Trajectory<From>&& from) {
  static_assert(std::is_same_v<typename To::Element, typename From::Element>,
                "rebind_trajectory: the groups' elements are different matrices");
  Trajectory<To> to;
  to.observations = std::move(from.observations);
  to.covariates = std::move(from.covariates);
  to.timestamps = std::move(from.timestamps);
  to.lines = std::move(from.lines);
  to.format = from.format;
  to.origin = from.origin;
  to.last = from.last;
  to.projection_correction = from.projection_correction;
  return to;
}

// Side of the square matrix of G's elements in the matrix format.
template <class G>
constexpr int matrix_side() {
  return static_cast<int>(G::Element::RowsAtCompileTime);
}

// Rotation matrix of a unit quaternion (w, x, y, z).
inline Eigen::Matrix3d rotation_of_quaternion(double w, double x, double y, double z) {
  Eigen::Matrix3d r;
  r << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return r;
}

// The rotation nearest to `m` in the Frobenius norm (polar decomposition by
// SVD), or the reason it is not unique: rank < 2, or a reflection whose two
// smallest singular values are equal.
template <int N>
std::optional<std::string> nearest_rotation(Eigen::Matrix<double, N, N>& m) {
  const Eigen::JacobiSVD<Eigen::Matrix<double, N, N>> svd(
      m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  const double tolerance = 1e-9 * s[0];
  if (!(s[0] > 0) || (N >= 3 && !(s[N - 2] > tolerance))) {
    return std::string("rotation block has rank < 2: its nearest rotation is not defined");
  }
  Eigen::Matrix<double, N, N> u = svd.matrixU();
  const Eigen::Matrix<double, N, N>& v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0) {
    if (!(s[N - 2] - s[N - 1] > tolerance)) {
      return std::string("rotation block is a reflection without a unique nearest rotation");
    }
    u.col(N - 1) *= -1;
  }
  m = u * v.transpose();
  return std::nullopt;
}

namespace detail {

// One data line as an element of G (and the line's timestamp token), or an
// error message. `correction` grows to the largest projection change.
template <class G>
std::optional<std::string> parse_line(Format format, const std::vector<std::string_view>& tokens,
                                      const ReadOptions& options, typename G::Element& g,
                                      std::string_view& time_token, double& time_value,
                                      double& correction, const double* numbers = nullptr) {
  constexpr int n = matrix_side<G>();
  constexpr bool is_se3 = std::is_same_v<G, SE3<double>>;
  constexpr bool is_so3 = std::is_same_v<G, SO3<double>>;
  constexpr bool is_sim3 = std::is_same_v<G, Sim3<double>>;
  double x[17];
  // Token k's number: read here, or by read_numbers when `numbers` is given.
  const auto number = [&](std::size_t k, double& value) -> std::optional<std::string> {
    if (numbers) {
      value = numbers[k];
      return std::nullopt;
    }
    return parse_number(tokens[k], value);
  };
  const auto parse = [&](std::size_t first, std::size_t count) -> std::optional<std::string> {
    for (std::size_t i = 0; i < count; ++i) {
      if (auto problem = number(first + i, x[first + i])) return problem;
    }
    return std::nullopt;
  };
  const auto found = [&](const std::string& expected) {
    return "expected " + expected + ", found " + std::to_string(tokens.size());
  };
  g = G::identity();
  time_token = {};
  Eigen::Matrix3d r;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  bool from_rotation = false;  // r (and p) hold the pose
  // TUM and EuRoC give a quaternion, normalised below: a rotation to rounding.
  const bool quaternion = format == Format::tum || format == Format::euroc;
  if (format == Format::matrix) {
    const std::size_t expected = 1 + n * n;
    if (tokens.size() != expected) return found(std::to_string(expected) + " numbers");
    if (auto problem = number(0, time_value)) return problem;
    time_token = tokens[0];
    double value = 0;
    for (int row = 0; row < n; ++row) {
      for (int col = 0; col < n; ++col) {
        const std::size_t k = 1 + static_cast<std::size_t>(row * n + col);
        if (auto problem = number(k, value)) return problem;
        g(row, col) = value;
      }
    }
    if constexpr (can_project<G>()) {
      if (options.project) {
        constexpr int k = is_se3 || std::is_same_v<G, SE2<double>> ? n - 1 : n;
        typename G::Element projected = g;
        Eigen::Matrix<double, k, k> block = g.template topLeftCorner<k, k>();
        if (auto problem = nearest_rotation<k>(block)) return problem;
        projected.template topLeftCorner<k, k>() = block;
        if (k < n) {
          projected.row(n - 1).setZero();
          projected(n - 1, n - 1) = 1;
        }
        const double change = (projected - g).norm();
        if (change > correction) correction = change;
        g = projected;
      }
    }
  } else if (format == Format::kitti) {
    if (tokens.size() != 12) return found("12 numbers (a 3x4 pose, row-major)");
    if (auto problem = parse(0, 12)) return problem;
    r << x[0], x[1], x[2], x[4], x[5], x[6], x[8], x[9], x[10];
    p << x[3], x[7], x[11];
    if (options.project) {
      Eigen::Matrix3d projected = r;
      if (auto problem = nearest_rotation<3>(projected)) return problem;
      const double change = (projected - r).norm();
      if (change > correction) correction = change;
      r = projected;
    }
    from_rotation = true;
  } else {
    // tum and euroc: a timestamp, a position and a quaternion.
    std::size_t qw = 0, qx = 0;
    if (format == Format::tum) {
      if (tokens.size() != 8) return found("8 numbers (timestamp tx ty tz qx qy qz qw)");
      qx = 4;
      qw = 7;
    } else {
      if (tokens.size() < 8) {
        return found("at least 8 numbers (timestamp p_x p_y p_z q_w q_x q_y q_z)");
      }
      qw = 4;
      qx = 5;
    }
    if (auto problem = number(0, time_value)) return problem;
    time_token = tokens[0];
    if (auto problem = parse(1, 7)) return problem;
    const double w = x[qw], a = x[qx], b = x[qx + 1], c = x[qx + 2];
    double norm = std::sqrt(w * w + a * a + b * b + c * c);
    if (!std::isfinite(norm)) {
      // The squares overflowed (components beyond 1e154): scaled by the
      // largest first, the norm is finite.
      const double largest = std::max({std::abs(w), std::abs(a), std::abs(b), std::abs(c)});
      const double sw = w / largest, sa = a / largest, sb = b / largest, sc = c / largest;
      norm = largest * std::sqrt(sw * sw + sa * sa + sb * sb + sc * sc);
      // Beyond the largest double (components near 1.8e308) the norm itself
      // overflows, and q / |q| would be the zero quaternion: refused.
      if (!std::isfinite(norm)) return std::string("quaternion norm beyond the range of double");
    }
    if (options.project) {
      if (!(norm >= 1e-6)) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "quaternion norm %g is too small to normalise", norm);
        return std::string(buffer);
      }
      const double change = std::abs(norm - 1);
      if (change > correction) correction = change;
    } else if (!(std::abs(norm - 1) <= 1e-3)) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "quaternion norm %g is far from 1", norm);
      return std::string(buffer) + " (--project normalises it)";
    }
    r = rotation_of_quaternion(w / norm, a / norm, b / norm, c / norm);
    p << x[1], x[2], x[3];
    from_rotation = true;
  }
  if (from_rotation) {
    if constexpr (is_se3 || is_sim3) {
      g.setIdentity();
      g.template topLeftCorner<3, 3>() = r;
      g.template topRightCorner<3, 1>() = p;
    } else if constexpr (is_so3) {
      g = r;
    }
  }
  if (!quaternion && !G::is_element(g, options.element_tolerance)) {
    std::string message = std::string("matrix is not an element of ") + G::name;
    if (can_project<G>() && !options.project) message += " (--project re-orthonormalises it)";
    return message;
  }
  return std::nullopt;
}

// Whether the first data line has the shape of `format` (see the rules at
// the top of this file).
template <class G>
bool has_shape(Format format, const std::vector<std::string_view>& tokens, bool had_comma,
               bool timestamp_header) {
  constexpr std::size_t n = static_cast<std::size_t>(matrix_side<G>());
  switch (format) {
    case Format::matrix:
      return tokens.size() == 1 + n * n;
    case Format::tum:
      return tokens.size() == 8 && !had_comma;
    case Format::kitti:
      return tokens.size() == 12 && !had_comma;
    case Format::euroc: {
      if (tokens.size() < 8 || !had_comma || !timestamp_header) return false;
      for (char c : tokens[0])
        if (c < '0' || c > '9') return false;
      return true;
    }
  }
  return false;
}

inline bool mentions_timestamp(std::string_view line) {
  static constexpr std::string_view kWord = "timestamp";
  if (line.size() < kWord.size()) return false;
  for (std::size_t i = 0; i + kWord.size() <= line.size(); ++i) {
    std::size_t k = 0;
    while (k < kWord.size() && (line[i + k] | 0x20) == kWord[k])
      ++k;
    if (k == kWord.size()) return true;
  }
  return false;
}

// At most this many observations are reserved ahead (about 200 MB for
// 4 x 4 poses with their timestamps); beyond, the vectors grow as they fill.
inline constexpr std::size_t kMaxReservedLines = std::size_t{1} << 20;

// How many observations to reserve for the lines left, estimated from the
// first data line's length with an eighth to spare (lines vary in their
// digits), at most kMaxReservedLines. Without it the vectors double as they
// fill, copying the observations and touching their memory twice (about a
// fifth of the reading time of a 1e6-line file). A first line longer than
// the rest makes the estimate short (the vectors then grow as before), a
// shorter one makes it long, by at most kMaxReservedLines entries.
inline std::size_t reservation(std::size_t remaining_bytes, std::size_t line_bytes) {
  const std::size_t lines_left = remaining_bytes / (line_bytes > 0 ? line_bytes : 1);
  if (lines_left >= kMaxReservedLines) return kMaxReservedLines;  // and no overflow below
  const std::size_t estimate = 1 + lines_left;
  const std::size_t room = estimate + estimate / 8;
  return room < kMaxReservedLines ? room : kMaxReservedLines;
}

template <class G>
void reserve_for(std::size_t remaining_bytes, std::size_t line_bytes, Trajectory<G>& out) {
  const std::size_t room = reservation(remaining_bytes, line_bytes);
  out.observations.reserve(room);
  out.timestamps.reserve(room);
  out.lines.reserve(room);
}

}  // namespace detail

// Reads a whole trajectory. On success the trajectory has at least one
// observation; the caller checks whether that is enough for its purpose.
template <class G>
std::optional<ParseError> read_trajectory(ByteSource& source, const ReadOptions& options,
                                          Trajectory<G>& out) {
  out = Trajectory<G>();
  if (options.format && !reads<G>(*options.format)) {
    return ParseError{0, unsupported_format_message<G>(*options.format)};
  }
  if (!(options.element_tolerance >= 0)) {
    return ParseError{0, "element_tolerance must be a non-negative number"};
  }
  if (options.project && !can_project<G>()) {
    return ParseError{0, std::string("--project applies to SO2, SO3, SE2 and SE3, not ") + G::name};
  }
  std::optional<Format> format = options.format;
  if (!format && !reads<G>(Format::tum)) format = Format::matrix;
  LineReader reader(source);
  std::string_view line;
  std::vector<std::string_view> tokens;
  bool timestamp_header = false;
  typename G::Element g;
  std::string_view time_token;
  double time_value = 0;
  double numbers[kMaxNumbersPerLine];
  while (reader.next(line)) {
    const std::uint64_t line_number = reader.line_number();
    std::size_t first = 0;
    while (first < line.size() && is_separator(line[first]))
      ++first;
    if (first == line.size()) continue;
    if (line[first] == '#') {
      if (out.observations.empty() && detail::mentions_timestamp(line)) timestamp_header = true;
      continue;
    }
    bool had_comma = false;
    const bool all_numbers = read_numbers(line, tokens, numbers, had_comma);
    if (!format) {
      // Detection on the first data line.
      std::vector<Format> shaped, valid;
      for (Format f : {Format::matrix, Format::tum, Format::euroc, Format::kitti}) {
        if (detail::has_shape<G>(f, tokens, had_comma, timestamp_header)) shaped.push_back(f);
      }
      if (shaped.empty()) {
        return ParseError{line_number,
                          "no format fits this line (" + std::to_string(tokens.size()) +
                              " numbers; matrix has " +
                              std::to_string(1 + matrix_side<G>() * matrix_side<G>()) +
                              ", tum 8, kitti 12, euroc 8 or more comma-separated): use --format"};
      }
      if (shaped.size() == 1) {
        format = shaped.front();
      } else {
        ReadOptions strict = options;
        strict.project = false;
        double ignored = 0;
        for (Format f : shaped) {
          if (!detail::parse_line<G>(f, tokens, strict, g, time_token, time_value, ignored))
            valid.push_back(f);
        }
        if (valid.size() != 1) {
          std::string names;
          for (Format f : shaped)
            names += std::string(names.empty() ? "" : " or ") + to_string(f);
          return ParseError{line_number, "ambiguous format: the line reads as " + names +
                                             "; say which with --format"};
        }
        format = valid.front();
      }
    }
    double correction = out.projection_correction;
    if (auto problem = detail::parse_line<G>(*format, tokens, options, g, time_token, time_value,
                                             correction, all_numbers ? numbers : nullptr)) {
      return ParseError{line_number, std::move(*problem)};
    }
    out.projection_correction = correction;
    Timestamp stamp;
    if (*format == Format::kitti) {
      const std::size_t index = out.observations.size();
      if (options.times) {
        if (index >= options.times->size()) {
          return ParseError{
              line_number, "more poses than times (" + std::to_string(options.times->size()) + ")"};
        }
        stamp = (*options.times)[index];
      } else {
        stamp = frame_timestamp(index);
      }
    } else {
      timestamp_of_number(time_token, time_value, time_unit(*format), stamp);
    }
    if (out.observations.empty())
      detail::reserve_for(reader.remaining_hint(), line.size() + 1, out);
    out.observations.push_back(g);
    out.timestamps.push_back(std::move(stamp));
    out.lines.push_back(line_number);
  }
  if (reader.error()) return reader.error();
  if (out.observations.empty()) return ParseError{0, "no observations"};
  out.format = *format;
  if (*format == Format::kitti && options.times &&
      options.times->size() != out.observations.size()) {
    return ParseError{0, std::to_string(options.times->size()) + " times for " +
                             std::to_string(out.observations.size()) + " poses"};
  }
  // Covariates: seconds after the earliest timestamp, exact until rounded.
  std::size_t earliest = 0, latest = 0;
  for (std::size_t i = 1; i < out.timestamps.size(); ++i) {
    if (earlier(out.timestamps[i], out.timestamps[earliest])) earliest = i;
    if (earlier(out.timestamps[latest], out.timestamps[i])) latest = i;
  }
  out.origin = out.timestamps[earliest];
  out.last = out.timestamps[latest];
  out.covariates.reserve(out.timestamps.size());
  for (std::size_t i = 0; i < out.timestamps.size(); ++i) {
    const double c = seconds_between(out.timestamps[i], out.origin);
    if (!std::isfinite(c)) {
      return ParseError{out.lines[i], "timestamp " + quote_excerpt(out.timestamps[i].text) +
                                          " is too far from the earliest one"};
    }
    out.covariates.push_back(c);
  }
  return std::nullopt;
}

template <class G>
std::optional<ParseError> read_trajectory(std::istream& in, const ReadOptions& options,
                                          Trajectory<G>& out) {
  StreamSource source(in);
  return read_trajectory<G>(source, options, out);
}

// The reader of earlier versions: a given format, no projection.
template <class G>
std::optional<ParseError> read_trajectory(std::istream& in, Format format, Trajectory<G>& out,
                                          double element_tolerance = 1e-6) {
  ReadOptions options;
  options.format = format;
  options.element_tolerance = element_tolerance;
  return read_trajectory<G>(in, options, out);
}

// A KITTI times file: one time in seconds per line (blank and '#' lines
// skipped).
inline std::optional<ParseError> read_times(ByteSource& source, std::vector<Timestamp>& out) {
  out.clear();
  LineReader reader(source);
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (reader.next(line)) {
    split_tokens(line, tokens);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (tokens.size() != 1) {
      return ParseError{reader.line_number(),
                        "expected 1 number, found " + std::to_string(tokens.size())};
    }
    Timestamp t;
    if (auto problem = parse_timestamp(tokens[0], TimeUnit::seconds, t)) {
      return ParseError{reader.line_number(), std::move(*problem)};
    }
    out.push_back(std::move(t));
  }
  if (reader.error()) return reader.error();
  if (out.empty()) return ParseError{0, "no times"};
  return std::nullopt;
}

}  // namespace io
}  // namespace bireg
