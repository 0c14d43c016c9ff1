// bireg io: reading and writing trajectories as text, for bireg_fit and
// the demo. Uses the standard library only and never throws on bad input:
// every problem is returned as a ParseError naming the line.
//
// Formats
//   matrix  one observation per line: t, m00, m01, ..., m(n-1)(n-1), the
//           covariate then the n x n matrix row-major; commas and/or white
//           space separate; blank lines and lines starting with '#' are
//           ignored.
//   tum     the TUM trajectory format, `timestamp tx ty tz qx qy qz qw`, for
//           SE3 (and SO3, which uses the rotation alone). Quaternions are
//           normalised; one whose norm is off 1 by more than 1e-3 is an error.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"

namespace bireg {
namespace io {

enum class Format { matrix, tum };

struct ParseError {
  int line = 0;  // 1-based; 0 when the problem is the file as a whole
  std::string message;
};

template <class G>
struct Trajectory {
  std::vector<typename G::Element> observations;
  std::vector<double> covariates;
  std::vector<int> lines;  // source line of each observation
};

// Splits a line into numbers. Separators are commas and white space. A token
// that is not entirely a finite number (text, "nan", "inf", or out of the
// double range such as 1e400) is an error naming the token.
inline std::optional<std::string> split_numbers(const std::string& line, std::vector<double>& out) {
  out.clear();
  std::size_t i = 0;
  const auto is_separator = [](char c) {
    return c == ',' || c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
  };
  while (i < line.size()) {
    while (i < line.size() && is_separator(line[i]))
      ++i;
    if (i >= line.size()) break;
    std::size_t end = i;
    while (end < line.size() && !is_separator(line[end]))
      ++end;
    const std::string token = line.substr(i, end - i);
    errno = 0;
    char* parsed_end = nullptr;
    const double value = std::strtod(token.c_str(), &parsed_end);
    if (parsed_end != token.c_str() + token.size()) {
      return "not a number: '" + token + "'";
    }
    if (errno == ERANGE && std::abs(value) > 1.0) return "number out of range: '" + token + "'";
    if (!std::isfinite(value)) return "not a finite number: '" + token + "'";
    out.push_back(value);
    i = end;
  }
  return std::nullopt;
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

// Reads a whole trajectory. On success `error` is empty; the caller still has
// to check that there are enough observations for its purpose.
template <class G>
std::optional<ParseError> read_trajectory(std::istream& in, Format format, Trajectory<G>& out,
                                          double element_tolerance = 1e-6) {
  constexpr int n = matrix_side<G>();
  constexpr bool is_se3 = std::is_same_v<G, SE3<double>>;
  constexpr bool is_so3 = std::is_same_v<G, SO3<double>>;
  if (format == Format::tum && !is_se3 && !is_so3) {
    return ParseError{0, std::string("the tum format holds SE3 or SO3 poses, not ") + G::name};
  }
  out = Trajectory<G>();
  std::string line;
  std::vector<double> numbers;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::size_t first = line.find_first_not_of(" \t\r,");
    if (first == std::string::npos || line[first] == '#') continue;
    if (const auto problem = split_numbers(line, numbers)) return ParseError{line_number, *problem};

    typename G::Element g = G::identity();
    if (format == Format::matrix) {
      const std::size_t expected = 1 + n * n;
      if (numbers.size() != expected) {
        return ParseError{line_number, "expected " + std::to_string(expected) + " numbers, found " +
                                           std::to_string(numbers.size())};
      }
      for (int r = 0; r < n; ++r) {
        for (int c = 0; c < n; ++c)
          g(r, c) = numbers[1 + r * n + c];
      }
    } else {
      if (numbers.size() != 8) {
        return ParseError{line_number,
                          "expected 8 numbers (timestamp tx ty tz qx qy qz qw), found " +
                              std::to_string(numbers.size())};
      }
      const double qx = numbers[4], qy = numbers[5], qz = numbers[6], qw = numbers[7];
      const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
      if (!(std::abs(norm - 1) <= 1e-3)) {
        std::ostringstream message;
        message << "quaternion norm " << norm << " is far from 1";
        return ParseError{line_number, message.str()};
      }
      const Eigen::Matrix3d r = rotation_of_quaternion(qw / norm, qx / norm, qy / norm, qz / norm);
      if constexpr (is_se3) {
        g.setIdentity();
        g.template topLeftCorner<3, 3>() = r;
        g.template topRightCorner<3, 1>() = Eigen::Vector3d(numbers[1], numbers[2], numbers[3]);
      } else if constexpr (is_so3) {
        g = r;
      }
    }
    if (!G::is_element(g, element_tolerance)) {
      return ParseError{line_number, std::string("matrix is not an element of ") + G::name};
    }
    out.observations.push_back(g);
    out.covariates.push_back(numbers[0]);
    out.lines.push_back(line_number);
  }
  if (out.observations.empty()) return ParseError{0, "no observations"};
  return std::nullopt;
}

// A double printed so that it reads back to the same value.
inline std::string format_double(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// One observation line in `format` (the inverse of read_trajectory).
template <class G>
std::string format_observation(Format format, double t, const typename G::Element& g) {
  std::string line = format_double(t);
  if (format == Format::matrix) {
    for (int r = 0; r < g.rows(); ++r) {
      for (int c = 0; c < g.cols(); ++c)
        line += ", " + format_double(g(r, c));
    }
    return line;
  }
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // SO3 in tum: no translation
  if constexpr (std::is_same_v<G, SE3<double>>) {
    rotation = g.template topLeftCorner<3, 3>();
    translation = g.template topRightCorner<3, 1>();
  } else if constexpr (std::is_same_v<G, SO3<double>>) {
    rotation = g;
  } else {
    return line;  // read_trajectory refuses tum for other groups
  }
  const Eigen::Vector4d q = SO3<double>::to_quaternion(rotation);  // (w, x, y, z)
  for (double x : {translation[0], translation[1], translation[2], q[1], q[2], q[3], q[0]}) {
    line += " " + format_double(x);
  }
  return line;
}

// A matrix as a JSON array of rows.
template <class Matrix>
std::string json_matrix(const Matrix& m) {
  std::string s = "[";
  for (int r = 0; r < m.rows(); ++r) {
    s += r ? ", [" : "[";
    for (int c = 0; c < m.cols(); ++c)
      s += (c ? ", " : "") + format_double(m(r, c));
    s += "]";
  }
  return s + "]";
}

}  // namespace io
}  // namespace bireg
