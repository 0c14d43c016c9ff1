// bireg io: writing trajectories and JSON as text, with write errors checked.
//
// Trajectory lines follow the conventions evo and the datasets use:
//   matrix  "t, m00, m01, ..." (comma and space);
//   tum     "timestamp tx ty tz qx qy qz qw", single spaces;
//   euroc   a '#timestamp [ns],...' header, then 17 comma-separated columns
//           as EuRoC ground truth has them (evo requires 17): timestamp in
//           nanoseconds, position, quaternion w first, then velocity and
//           biases, which a fitted pose does not have: written as 0;
//   kitti   the 3x4 pose row-major, 12 numbers, single spaces, no time.
// Quaternions (tum, euroc) stay in one hemisphere from line to line: q and
// -q are the same rotation, and each line's quaternion is the one on the
// side of the previous line's (q_k . q_{k-1} >= 0; the first has w >= 0),
// so that a trajectory turning through pi does not flip sign between two
// nearby rotations (evo and interpolating readers take the flip for a
// full turn).
// Timestamps are written exactly as they were read when the output's time
// unit is the input's; converted exactly otherwise (seconds <-> nanoseconds).
// Numbers are the shortest text that reads back to the same double; JSON
// numbers are never nan or inf: a non-finite value is written as null.
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/io/numbers.hpp"

namespace bireg {
namespace io {

// A double as the shortest text that reads back to the same value.
inline std::string format_double(double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}

inline void append_double(std::string& out, double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  out.append(buffer, result.ptr);
}

// A JSON number, or null when x is not finite (JSON has no nan or inf).
inline std::string json_number(double x) {
  return std::isfinite(x) ? format_double(x) : std::string("null");
}

// A matrix as a JSON array of rows (null for non-finite entries).
template <class Matrix>
std::string json_matrix(const Matrix& m) {
  std::string s = "[";
  for (int r = 0; r < m.rows(); ++r) {
    s += r ? ", [" : "[";
    for (int c = 0; c < m.cols(); ++c)
      s += (c ? ", " : "") + json_number(m(r, c));
    s += "]";
  }
  return s + "]";
}

inline constexpr const char* kEurocHeader =
    "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
    "q_RS_z [],v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],b_w_RS_S_x [rad s^-1],"
    "b_w_RS_S_y [rad s^-1],b_w_RS_S_z [rad s^-1],b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],"
    "b_a_RS_S_z [m s^-2]";

// The header line of `format` (with its '\n'), empty when it has none.
inline std::string header_line(Format format) {
  return format == Format::euroc ? std::string(kEurocHeader) + "\n" : std::string();
}

// The text of timestamp `t`, read in `source` format, for a `target` file.
inline std::string timestamp_text(const Timestamp& t, Format source, Format target) {
  if (time_unit(source) == time_unit(target)) return t.text;
  return render_timestamp(t, time_unit(target));
}

// Appends one observation line in `format` (with its '\n'); `time` is the
// timestamp text (unused by kitti). `previous` is the quaternion written on
// the line before (empty for the first line): this line's is taken on its
// side (q . previous >= 0) and stored in it, for the next line.
template <class G>
void append_observation(std::string& out, Format format, std::string_view time,
                        const typename G::Element& g, std::optional<Eigen::Quaterniond>& previous) {
  if (format == Format::matrix) {
    out += time;
    for (int r = 0; r < g.rows(); ++r) {
      for (int c = 0; c < g.cols(); ++c) {
        out += ", ";
        append_double(out, g(r, c));
      }
    }
    out += '\n';
    return;
  }
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // SO3: no translation
  if constexpr (std::is_same_v<G, SE3<double>>) {
    rotation = g.template topLeftCorner<3, 3>();
    translation = g.template topRightCorner<3, 1>();
  } else if constexpr (std::is_same_v<G, SO3<double>>) {
    rotation = g;
  }
  const auto put = [&out](char separator, double x) {
    out += separator;
    append_double(out, x);
  };
  if (format == Format::kitti) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        if (r == 0 && c == 0) {
          append_double(out, rotation(0, 0));
        } else {
          put(' ', rotation(r, c));
        }
      }
      put(' ', translation[r]);
    }
    out += '\n';
    return;
  }
  Eigen::Quaterniond q = SO3<double>::to_quaternion(rotation);
  if (previous && q.coeffs().dot(previous->coeffs()) < 0) q.coeffs() = -q.coeffs();
  previous = q;
  out += time;
  if (format == Format::tum) {
    for (double x : {translation[0], translation[1], translation[2], q.x(), q.y(), q.z(), q.w()})
      put(' ', x);
  } else {
    for (double x : {translation[0], translation[1], translation[2], q.w(), q.x(), q.y(), q.z()})
      put(',', x);
    out += ",0,0,0,0,0,0,0,0,0";
  }
  out += '\n';
}

// One line on its own: its quaternion has w >= 0.
template <class G>
void append_observation(std::string& out, Format format, std::string_view time,
                        const typename G::Element& g) {
  std::optional<Eigen::Quaterniond> none;
  append_observation<G>(out, format, time, g, none);
}

// Writes a trajectory to an open C stream, in blocks, and flushes it.
// Returns the reason when writing failed (disk full, closed pipe, ...).
template <class G>
std::optional<std::string> write_trajectory(std::FILE* file, Format format, Format source,
                                            const std::vector<Timestamp>& times,
                                            const std::vector<typename G::Element>& poses) {
  if (!supports<G>(format)) {
    return unsupported_format_message<G>(format) + " (use the matrix format)";
  }
  std::string buffer = header_line(format);
  const auto flush_buffer = [&]() -> bool {
    errno = 0;
    const bool ok =
        buffer.empty() || std::fwrite(buffer.data(), 1, buffer.size(), file) == buffer.size();
    buffer.clear();
    return ok;
  };
  const auto failure = []() {
    return std::string("write error: ") + (errno != 0 ? std::strerror(errno) : "unknown");
  };
  std::optional<Eigen::Quaterniond> previous;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    append_observation<G>(buffer, format, timestamp_text(times[i], source, format), poses[i],
                          previous);
    if (buffer.size() >= (std::size_t{1} << 20) && !flush_buffer()) return failure();
  }
  if (!flush_buffer()) return failure();
  errno = 0;
  if (std::fflush(file) != 0 || std::ferror(file)) return failure();
  return std::nullopt;
}

// The same text in a string (for tests and in-memory use). Throws
// std::invalid_argument if G has no spelling in `format` (supports<G>):
// writing a similarity as a TUM pose would drop its scale.
template <class G>
std::string format_trajectory(Format format, Format source, const std::vector<Timestamp>& times,
                              const std::vector<typename G::Element>& poses) {
  if (!supports<G>(format)) {
    throw std::invalid_argument("format_trajectory: " + unsupported_format_message<G>(format));
  }
  std::string out = header_line(format);
  std::optional<Eigen::Quaterniond> previous;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    append_observation<G>(out, format, timestamp_text(times[i], source, format), poses[i],
                          previous);
  }
  return out;
}

}  // namespace io
}  // namespace bireg
