// bireg: fast rotational motion with a known angular velocity, and the two
// baselines any velocity estimator from orientation must beat: finite
// differences and a kernel-weighted line in the log chart. For testing a
// smoother (tests/test_fast_motion.cpp) and for the gyroscope table of
// examples/gyro_demo.cpp.
//
// Truth. A trajectory is given by its body angular velocity w(t) (rad/s,
// what a gyroscope measures: R' = R [w]x) and integrated exactly enough:
// R(t + dt) = R(t) exp(w(t + dt/2) dt) with dt = 1e-5 s, whose error per
// step is O(dt^3 |w x w'|), 1e-11 rad per second of a 20 rad/s spin whose
// axis turns at 1 rad/s. Samples are taken at a fixed rate and each is
// R(t_i) exp(e_i) with e_i Gaussian, `noise` rad per axis.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/so3.hpp"
#include "bireg/testing/random.hpp"

namespace bireg::testing {

struct RotationTrack {
  std::vector<bireg::SO3d::Element> f;
  std::vector<double> t;
  std::vector<bireg::SO3d::Tangent> velocity;  // the true body angular velocity at t
};

using AngularRate = std::function<bireg::SO3d::Tangent(double)>;

// A recording in a numeric CSV (comma-separated, '#' comments and blank
// lines skipped): the first column (time) and the `columns` after it.
struct Recording {
  std::vector<double> t;
  std::vector<std::vector<double>> values;
};

// Reads `path` into `out`; returns "" or what is wrong ("cannot open
// PATH", "PATH:LINE: expected N numbers").
inline std::string read_recording(const std::string& path, std::size_t columns, Recording& out) {
  std::ifstream in(path);
  if (!in) return "cannot open " + path;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::stringstream fields(line);
    std::string field;
    std::vector<double> row;
    while (std::getline(fields, field, ','))
      row.push_back(std::stod(field));
    if (row.size() != columns + 1) {
      return path + ":" + std::to_string(number) + ": expected " + std::to_string(columns + 1) +
             " numbers";
    }
    out.t.push_back(row[0]);
    out.values.emplace_back(row.begin() + 1, row.end());
  }
  return {};
}

// A rate recording (three columns, rad/s) linearly interpolated at t,
// clamped at its ends.
inline bireg::SO3d::Tangent rate_at(const Recording& rate, double t) {
  const auto upper = std::lower_bound(rate.t.begin(), rate.t.end(), t);
  const std::size_t j = static_cast<std::size_t>(upper - rate.t.begin());
  const auto row = [&](std::size_t k) {
    return bireg::SO3d::Tangent(rate.values[k][0], rate.values[k][1], rate.values[k][2]);
  };
  if (j == 0) return row(0);
  if (j >= rate.t.size()) return row(rate.t.size() - 1);
  const double share = (t - rate.t[j - 1]) / (rate.t[j] - rate.t[j - 1]);
  return (1 - share) * row(j - 1) + share * row(j);
}

// The indices of the first sample at or after each k / hz from the first.
inline std::vector<std::size_t> subsample(const std::vector<double>& t, double hz) {
  std::vector<std::size_t> kept;
  double next = t.front();
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < next - 1e-9) continue;
    kept.push_back(i);
    next += 1.0 / hz;
  }
  return kept;
}

// Samples of the rotation whose body angular velocity is `rate`, from t = 0
// to `duration` s at `hz`, with noise `noise` rad per axis (seed fixed).
inline RotationTrack sample_rotation(const AngularRate& rate, double duration, double hz,
                                     double noise, unsigned seed) {
  using SO3 = bireg::SO3d;
  constexpr double kStep = 1e-5;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  RotationTrack track;
  SO3::Element r = SO3::identity();
  double now = 0;
  const long count = std::lround(std::floor(duration * hz)) + 1;
  for (long i = 0; i < count; ++i) {
    const double t_i = static_cast<double>(i) / hz;
    while (now + kStep <= t_i + 1e-12) {
      r = SO3::compose(r, SO3::exp(rate(now + kStep / 2) * kStep));
      now += kStep;
    }
    if (t_i > now) r = SO3::compose(r, SO3::exp(rate((now + t_i) / 2) * (t_i - now)));
    now = t_i;
    const SO3::Tangent e = draw_vector<SO3::Tangent>(rng, normal);
    track.f.push_back(SO3::compose(r, SO3::exp(noise * e)));
    track.t.push_back(t_i);
    track.velocity.push_back(rate(t_i));
  }
  return track;
}

// A spin at `speed` rad/s about an axis that precesses at 1 rad/s around
// z at 60 degrees from it, the speed modulated by +-25 % at 0.5 Hz: fast,
// smooth, and never one geodesic.
inline AngularRate spin(double speed) {
  return [speed](double t) {
    const double magnitude = speed * (1.0 + 0.25 * std::sin(M_PI * t));
    const double tilt = M_PI / 3;
    return bireg::SO3d::Tangent(magnitude * std::sin(tilt) * std::cos(t),
                                magnitude * std::sin(tilt) * std::sin(t),
                                magnitude * std::cos(tilt));
  };
}

// A motion-capture-like whip: at rest for 0.5 s, the rate rises from 0 to
// 16 rad/s within 0.3 s (a smoothstep), falls back to 0 within 0.4 s, rest;
// about an axis that tilts as it goes.
inline AngularRate whip() {
  return [](double t) {
    const auto smoothstep = [](double u) {
      u = std::clamp(u, 0.0, 1.0);
      return u * u * (3 - 2 * u);
    };
    const double rise = smoothstep((t - 0.5) / 0.3);
    const double fall = 1.0 - smoothstep((t - 0.8) / 0.4);
    const double magnitude = 16.0 * rise * fall;
    const double tilt = 0.8 * (t - 0.5);
    return bireg::SO3d::Tangent(magnitude * std::sin(tilt), 0.3 * magnitude * std::cos(tilt),
                                magnitude * std::cos(tilt));
  };
}

// Central finite differences log(R_{i-1}^T R_{i+1}) / (t_{i+1} - t_{i-1}),
// one-sided at the two ends.
inline std::vector<bireg::SO3d::Tangent> finite_differences(
    const std::vector<bireg::SO3d::Element>& f, const std::vector<double>& t) {
  using SO3 = bireg::SO3d;
  const std::size_t n = f.size();
  std::vector<SO3::Tangent> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t before = i == 0 ? 0 : i - 1;
    const std::size_t after = i + 1 == n ? n - 1 : i + 1;
    w[i] = SO3::log(SO3::compose(SO3::inverse(f[before]), f[after])) / (t[after] - t[before]);
  }
  return w;
}

// The chart line: at each sample c, the Gaussian-weighted (truncated at 4
// h) least-squares line through y_j = log(R_c^T R_j) against t_j - t_c,
// using only the samples within pi of R_c; its slope is the estimate.
inline std::vector<bireg::SO3d::Tangent> chart_line(const std::vector<bireg::SO3d::Element>& f,
                                                    const std::vector<double>& t, double h) {
  using SO3 = bireg::SO3d;
  const std::size_t n = f.size();
  std::vector<SO3::Tangent> w(n, SO3::Tangent::Zero());
  for (std::size_t c = 0; c < n; ++c) {
    double s0 = 0, s1 = 0, s2 = 0;
    SO3::Tangent m0 = SO3::Tangent::Zero(), m1 = SO3::Tangent::Zero();
    const SO3::Element inverse = SO3::inverse(f[c]);
    // Outward from c on each side while the chart holds (angle < 2.5 rad).
    for (const int direction : {-1, 1}) {
      for (long j = static_cast<long>(c) + (direction > 0 ? 1 : 0);
           j >= 0 && j < static_cast<long>(n); j += direction) {
        const double u = (t[static_cast<std::size_t>(j)] - t[c]) / h;
        if (std::abs(u) >= 4) break;
        const SO3::Tangent y = SO3::log(SO3::compose(inverse, f[static_cast<std::size_t>(j)]));
        if (y.norm() > 2.5) break;
        const double weight = std::exp(-u * u / 2);
        const double dt = t[static_cast<std::size_t>(j)] - t[c];
        s0 += weight;
        s1 += weight * dt;
        s2 += weight * dt * dt;
        m0 += weight * y;
        m1 += weight * dt * y;
      }
    }
    const double determinant = s0 * s2 - s1 * s1;
    if (determinant > 0) w[c] = (s0 * m1 - s1 * m0) / determinant;
  }
  return w;
}

// RMS of |w_i - reference_i| over all samples.
inline double rms_error(const std::vector<bireg::SO3d::Tangent>& w,
                        const std::vector<bireg::SO3d::Tangent>& reference) {
  double sum = 0;
  for (std::size_t i = 0; i < w.size(); ++i)
    sum += (w[i] - reference[i]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(w.size()));
}

// The chart line at the bandwidth that is best against the truth (which
// no real smoother can see): the minimum over `count` bandwidths from 0.5
// to 20 sample spacings, geometric. Returns {RMS error, bandwidth}.
inline std::pair<double, double> oracle_chart_line(const std::vector<bireg::SO3d::Element>& f,
                                                   const std::vector<double>& t,
                                                   const std::vector<bireg::SO3d::Tangent>& truth,
                                                   int count = 24) {
  const double spacing = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  std::pair<double, double> best{std::numeric_limits<double>::infinity(), 0};
  for (int k = 0; k < count; ++k) {
    const double h = spacing * 0.5 * std::pow(40.0, k / double(count - 1));
    const double error = rms_error(chart_line(f, t, h), truth);
    if (error < best.first) best = {error, h};
  }
  return best;
}

}  // namespace bireg::testing
