// Local regression on motion that is fast for its sampling rate
// (statistics/smoothing/local_regression.hpp; issue "Velocity on fast real motion"):
// windows cut where they would turn too far, a bandwidth choice that
// counts its failures instead of dropping a bandwidth for one, a velocity
// whose bandwidth is chosen for the velocity, and ends without the local
// line's bias in the derivative. The truth is a simulated angular velocity
// (fast_motion.hpp) or the x-IMU recording's own gyroscope.
//
// The bounds are the issue's: noise-free, the velocity's RMS error at most
// 2x the better of central finite differences and the chart line at its
// best bandwidth; with noise, at most 1.15x that chart line (whose
// bandwidth was chosen by looking at the truth, which no smoother can) and
// at most 0.5x finite differences. Where bireg does not meet a bound the
// case is listed in kKnownGaps below and run as [!mayfail]: it documents
// the gap, measured, instead of widening the bound.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/testing/fast_motion.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

using SO3 = bireg::SO3d;
using SE3 = bireg::SE3d;
using bireg::testing::RotationTrack;
namespace motion = bireg::testing;

struct Velocities {
  std::vector<SO3::Tangent> velocity;
  std::vector<bireg::LocalEstimate<SO3>> estimates;
  bireg::BandwidthSelection<double> selection;
};

// What bireg_smooth --bandwidth auto does: 20 bandwidths from half a
// median spacing to the whole range, the velocity smoothed at its own
// choice.
Velocities auto_velocity(const RotationTrack& track) {
  bireg::LocalRegressionOptions<double> options;
  Velocities out;
  out.selection =
      bireg::select_bandwidth<SO3>(track.f, track.t, options, bireg::auto_bandwidth_grid(track.t));
  REQUIRE(out.selection.ok());
  options.bandwidth = out.selection.velocity_bandwidth;
  options.velocity_degree = out.selection.velocity_degree;
  out.estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(track.f, track.t);
  for (const auto& e : out.estimates)
    out.velocity.push_back(e.velocity);
  return out;
}

// The bounds bireg does not meet yet, measured (2026-11-27, figures in
// the README's gyroscope table). "At most 0.5x finite differences", on
// data where even the chart line at the bandwidth best against the truth
// (which no smoother can see) is 0.64-0.68x finite differences (the 25 Hz
// spins with noise; bireg is 0.52-0.65x there) or 0.6-1.0x (the x-IMU
// recording at 50 and 25 Hz, already smoothed by the device's filter;
// bireg within 1.01-1.07x of that chart line). The whip's "1.15x the chart
// line" gaps (1.24-1.39x: its rest at both ends, where the quadratic's
// one-sided slope adds variance and removes no bias) closed when the
// velocity's degree came to be chosen with its bandwidth (DESIGN.md
// section 5, "The velocity's degree"): the local cubic at about twice the
// bandwidth is 0.89-1.02x the chart line there.
struct Gap {
  const char* name;
  const char* bound;
};

const Gap kKnownGaps[] = {
    {"spin 10 rad/s at 25 Hz, noise 0.005", "0.5 differences"},
    {"spin 20 rad/s at 25 Hz, noise 0.005", "0.5 differences"},
    {"spin 20 rad/s at 25 Hz, noise 0.02", "0.5 differences"},
    {"x-IMU at 50 Hz, noise 0.005", "0.5 differences"},
    {"x-IMU at 25 Hz, noise 0.005", "0.5 differences"},
    {"x-IMU at 50 Hz, noise 0.02", "0.5 differences"},
    {"x-IMU at 25 Hz, noise 0.02", "0.5 differences"},
};

bool known_gap(const std::string& name, const std::string& bound) {
  for (const Gap& gap : kKnownGaps) {
    if (name == gap.name && bound == gap.bound) return true;
  }
  return false;
}

bool has_gap(const std::string& name) {
  for (const Gap& gap : kKnownGaps) {
    if (name == gap.name) return true;
  }
  return false;
}

// The bounds for one case: those that are known gaps when `gaps`,
// the others otherwise. Every query must be ok either way.
void check_bounds(const RotationTrack& track, double noise, const std::string& name, bool gaps) {
  const Velocities bireg = auto_velocity(track);
  std::size_t failed = 0;
  for (const auto& e : bireg.estimates)
    failed += e.ok() ? 0 : 1;
  const double error = motion::rms_error(bireg.velocity, track.velocity);
  const double differences =
      motion::rms_error(motion::finite_differences(track.f, track.t), track.velocity);
  const double chart = motion::oracle_chart_line(track.f, track.t, track.velocity).first;
  INFO(name << ": bireg " << error << " (bandwidths " << bireg.selection.bandwidth << ", "
            << bireg.selection.velocity_bandwidth << " s), finite differences " << differences
            << ", chart line " << chart);
  CHECK(failed == 0);
  const auto check = [&](const char* bound, bool met) {
    if (known_gap(name, bound) == gaps) CHECK(met);
  };
  if (noise == 0) {
    check("2x", error <= 2 * std::min(differences, chart));
  } else {
    check("1.15 chart", error <= 1.15 * chart);
    check("0.5 differences", error <= 0.5 * differences);
  }
}

const double kNoises[] = {0.0, 0.005, 0.02};

std::string case_name(const std::string& what, double hz, double noise) {
  std::ostringstream out;
  out << what << " at " << hz << " Hz, noise " << noise;
  return out.str();
}

std::string spin_name(double speed) {
  std::ostringstream out;
  out << "spin " << speed << " rad/s";
  return out.str();
}

// The x-IMU recording (examples/data), orientation samples taken at the
// first sample at or after each k / hz, with the gyroscope linearly
// interpolated at their times as the truth, and noise added.
RotationTrack subsampled_xio(double hz, double noise, unsigned seed) {
  motion::Recording orientation, gyroscope;
  const std::string orientation_problem =
      motion::read_recording(BIREG_EXAMPLE_DATA_DIR "/xio_imu_orientation.csv", 9, orientation);
  const std::string gyroscope_problem =
      motion::read_recording(BIREG_EXAMPLE_DATA_DIR "/xio_imu_gyroscope.csv", 3, gyroscope);
  INFO(orientation_problem << gyroscope_problem);
  REQUIRE(orientation_problem.empty());
  REQUIRE(gyroscope_problem.empty());
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  RotationTrack track;
  for (const std::size_t i : motion::subsample(orientation.t, hz)) {
    const std::vector<double>& m = orientation.values[i];
    SO3::Element r;
    r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
    const SO3::Tangent e = bireg::testing::draw_vector<SO3::Tangent>(rng, normal);
    track.f.push_back(SO3::compose(r, SO3::exp(noise * e)));
    track.t.push_back(orientation.t[i]);
    track.velocity.push_back(motion::rate_at(gyroscope, orientation.t[i]));
  }
  return track;
}

}  // namespace

// Every case, every bound that is not a known gap.
TEST_CASE("Fast spins: every query ok, the velocity within the baselines' bounds", "[fast]") {
  for (const double noise : kNoises) {
    for (const double speed : {5.0, 10.0, 20.0}) {
      for (const double hz : {25.0, 50.0, 100.0}) {
        const std::string name = case_name(spin_name(speed), hz, noise);
        SECTION(name) {
          check_bounds(motion::sample_rotation(motion::spin(speed), 4.0, hz, noise, 11), noise,
                       name, false);
        }
      }
    }
  }
}

TEST_CASE("A whip (0 to 16 rad/s in 0.3 s): every query ok, the velocity within bounds", "[fast]") {
  for (const double noise : kNoises) {
    for (const double hz : {60.0, 120.0}) {
      const std::string name = case_name("whip 16 rad/s", hz, noise);
      SECTION(name) {
        check_bounds(motion::sample_rotation(motion::whip(), 2.0, hz, noise, 13), noise, name,
                     false);
      }
    }
  }
}

TEST_CASE("The x-IMU recording at 50 and 25 Hz against its own gyroscope", "[fast][xio]") {
  for (const double noise : kNoises) {
    for (const double hz : {50.0, 25.0}) {
      const std::string name = case_name("x-IMU", hz, noise);
      SECTION(name) {
        check_bounds(subsampled_xio(hz, noise, 7), noise, name, false);
      }
    }
  }
}

// The known gaps, run and reported, expected to fail until fixed.
TEST_CASE("Known gaps against the issue's bounds", "[fast][!mayfail]") {
  for (const double noise : kNoises) {
    for (const double speed : {5.0, 10.0, 20.0}) {
      for (const double hz : {25.0, 50.0, 100.0}) {
        const std::string name = case_name(spin_name(speed), hz, noise);
        if (!has_gap(name)) continue;
        SECTION(name) {
          check_bounds(motion::sample_rotation(motion::spin(speed), 4.0, hz, noise, 11), noise,
                       name, true);
        }
      }
    }
    for (const double hz : {60.0, 120.0}) {
      const std::string name = case_name("whip 16 rad/s", hz, noise);
      if (!has_gap(name)) continue;
      SECTION(name) {
        check_bounds(motion::sample_rotation(motion::whip(), 2.0, hz, noise, 13), noise, name,
                     true);
      }
    }
    for (const double hz : {50.0, 25.0}) {
      const std::string name = case_name("x-IMU", hz, noise);
      if (!has_gap(name)) continue;
      SECTION(name) {
        check_bounds(subsampled_xio(hz, noise, 7), noise, name, true);
      }
    }
  }
}

// "Whatever the bandwidth": a spin of 20 rad/s at 50 Hz (0.4 rad between
// samples), smoothed with a bandwidth of a whole second, turned through
// 20 rad by the kernel's support. Before the cut every window spanned
// more than pi and the local fits ended no_descent or converged to the
// wrong side.
TEST_CASE("A bandwidth far too wide for a fast spin still gives a valid local estimate", "[fast]") {
  const RotationTrack track = motion::sample_rotation(motion::spin(20.0), 4.0, 50.0, 0.0, 11);
  for (const bool wide : {false, true}) {
    bireg::LocalRegressionOptions<double> options;
    options.bandwidth = 1.0;
    options.wide_windows = wide;
    const auto estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(track.f, track.t);
    std::vector<SO3::Tangent> velocity;
    for (const auto& e : estimates) {
      REQUIRE(e.ok());
      // The cut: every observation within max_turn / 2 = 1.25 rad of the
      // anchor, at 0.3-0.5 rad between samples (15-25 rad/s) at most 4 on
      // each side, far below the kernel's 200; the wide window's path of
      // 2.5 rad on each side at most 8.
      CHECK(e.window <= (wide ? 17u : 9u));
      velocity.push_back(e.velocity);
    }
    // Before the cut the error was the whole signal (15-25 rad/s). A flat
    // window leaves the curvature's bias, which grows with the square of
    // its length: 1 % of the slowest rate over +-4 samples, and twice the
    // length, 4x that and the axis's precession (1 rad/s) over 0.3 s,
    // under 7 % over +-8 (measured 0.81 rad/s). The bandwidth choice
    // (select_bandwidth) never lands here: it is the wide windows' price
    // for a bandwidth the data cannot support.
    CHECK(motion::rms_error(velocity, track.velocity) < (wide ? 1.0 : 0.15));
  }
}

// The cut is left and right invariant (turn_angle of f_a^{-1} f_b is
// unchanged by f -> g f h), so the estimates stay equivariant on SE(3)
// when it binds: poses map to g p h, velocities to Ad_{h^{-1}} v.
TEST_CASE("Cut windows keep the local fit left and right equivariant on SE(3)", "[fast]") {
  const RotationTrack spin = motion::sample_rotation(motion::spin(15.0), 2.0, 50.0, 0.01, 5);
  std::vector<SE3::Element> f;
  for (std::size_t i = 0; i < spin.f.size(); ++i) {
    SE3::Element g = SE3::Element::Identity();
    g.topLeftCorner<3, 3>() = spin.f[i];
    g.topRightCorner<3, 1>() = Eigen::Vector3d(std::sin(3 * spin.t[i]), spin.t[i], 0.2);
    f.push_back(g);
  }
  std::mt19937 rng(3);
  const SE3::Element left = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  const SE3::Element right = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  std::vector<SE3::Element> moved;
  for (const auto& g : f)
    moved.push_back(SE3::compose(SE3::compose(left, g), right));
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 0.5;  // the cut binds everywhere
  const bireg::LocalGeodesicRegression<SE3> smoother(options);
  const auto base = smoother.smooth(f, spin.t);
  const auto mapped = smoother.smooth(moved, spin.t);
  const SE3::AdMatrix ad_inverse = SE3::Ad(SE3::inverse(right));
  for (std::size_t q = 0; q < base.size(); ++q) {
    REQUIRE(base[q].ok());
    REQUIRE(mapped[q].ok());
    REQUIRE(base[q].window == mapped[q].window);
    CHECK((SE3::compose(SE3::compose(left, base[q].pose), right) - mapped[q].pose).norm() < 1e-8);
    CHECK((ad_inverse * base[q].velocity - mapped[q].velocity).norm() <
          1e-8 * (1 + base[q].velocity.norm()));
  }
}

// Boundary: a rotation whose rate grows linearly, w(t) = (2 + 12t, -3t, 1)
// rad/s, 101 samples over 1 s with noise 0.01 rad, bandwidth h = 0.05 s. At
// an end the window is one-sided: offsets s >= 0 weighted by a half
// Gaussian, whose moments are E s = 0.80 h, E s^2 = h^2, E s^3 = 1.60 h^3.
// A least-squares line through y(s) = y0 + w s + w' s^2 / 2 has the slope
// w + (w'/2) Cov(s, s^2) / Var(s) = w + (w'/2) (0.80 h / 0.36) = w + 1.1 w' h:
// 0.66 rad/s off on the first axis here (the local line has no first-order
// bias in the pose, only in its derivative), about 5 of the slope's
// standard errors (0.12 rad/s). The quadratic correction removes it: the
// end estimates lie within 3 standard errors of the truth per coordinate,
// while the geodesic's velocity alone is more than 3 away. (With w' = 6 the
// bias, 0.33 rad/s, was within a standard error of the 3-error line, and
// which side of it one sample fell on decided the test.)
TEST_CASE("At the ends of the data the velocity has no first-order bias", "[fast]") {
  const motion::AngularRate rate = [](double t) { return SO3::Tangent(2 + 12 * t, -3 * t, 1.0); };
  const RotationTrack track = motion::sample_rotation(rate, 1.0, 100.0, 0.01, 21);
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 0.05;
  const std::size_t ends[] = {0, track.t.size() - 1};
  const auto quadratic = bireg::LocalGeodesicRegression<SO3>(options).smooth(track.f, track.t);
  for (const std::size_t q : ends) {
    REQUIRE(quadratic[q].ok());
    REQUIRE(quadratic[q].velocity_error_defined);
    for (int k = 0; k < 3; ++k) {
      INFO("end " << q << " axis " << k << ": " << quadratic[q].velocity[k] << " +- "
                  << quadratic[q].velocity_error[k] << " against " << track.velocity[q][k]);
      CHECK(std::abs(quadratic[q].velocity[k] - track.velocity[q][k]) <=
            3 * quadratic[q].velocity_error[k]);
    }
  }
  options.velocity_degree = 1;
  const auto line = bireg::LocalGeodesicRegression<SO3>(options).smooth(track.f, track.t);
  for (const std::size_t q : ends) {
    REQUIRE(line[q].velocity_error_defined);
    const double off = std::abs(line[q].velocity[0] - track.velocity[q][0]);
    CHECK(off > 3 * line[q].velocity_error[0]);
  }
}

// Half the grid below half a sample spacing: the Gaussian's support then
// holds no neighbour, every held-out fit fails and those values are
// refused with the reason; the choice is the minimiser among the others,
// and a gap in the data that makes a few held-out fits fail at one
// admissible value does not disqualify it.
TEST_CASE("A bandwidth is refused only for a stated reason, and failures are counted", "[fast]") {
  RotationTrack track = motion::sample_rotation(motion::spin(3.0), 2.0, 100.0, 0.01, 9);
  // Sample 100 isolated: 97..99 and 101..103 removed, 4 spacings of
  // nothing on each side, so at the smaller admissible bandwidths leaving
  // it out leaves its query an empty window.
  track.f.erase(track.f.begin() + 101, track.f.begin() + 104);
  track.t.erase(track.t.begin() + 101, track.t.begin() + 104);
  track.f.erase(track.f.begin() + 97, track.f.begin() + 100);
  track.t.erase(track.t.begin() + 97, track.t.begin() + 100);
  const double spacing = 0.01;
  std::vector<double> grid;
  for (const double spacings : {0.05, 0.08, 0.1, 0.12, 0.6, 1.0, 2.0, 4.0})
    grid.push_back(spacings * spacing);
  bireg::LocalRegressionOptions<double> options;
  const auto selection = bireg::select_bandwidth<SO3>(track.f, track.t, options, grid);
  REQUIRE(selection.ok());
  std::size_t best = grid.size();
  for (std::size_t k = 0; k < grid.size(); ++k) {
    INFO("bandwidth " << grid[k] << ": " << selection.refusals[k]);
    if (k < 4) {
      CHECK(selection.failures[k] == track.t.size());
      CHECK(selection.refusals[k].find("held-out fits failed") != std::string::npos);
      CHECK(std::isinf(selection.criterion[k]));
      continue;
    }
    CHECK(selection.refusals[k].empty());
    CHECK(std::isfinite(selection.criterion[k]));
    if (best == grid.size() || selection.criterion[k] < selection.criterion[best]) best = k;
  }
  CHECK(selection.bandwidth == grid[best]);
  // 0.6 spacings: the Gaussian reaches 2.4 spacings, so the isolated
  // observation left out has an empty window: one failure, counted, the
  // value still compared, on the observations where every admissible
  // value succeeded.
  CHECK(selection.failures[4] == 1);
  CHECK(selection.compared == track.t.size() - 1);
}
