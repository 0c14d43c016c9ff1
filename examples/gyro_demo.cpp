// Angular velocity from orientation alone, checked against a gyroscope that
// the estimators never see: the whole 49 s x-IMU recording
// (examples/data/xio_imu_orientation.csv, 128 Hz, and the same recording's
// gyroscope, xio_imu_gyroscope.csv, 256 Hz; see examples/data/README.md).
//
// Frames and units. The orientation R maps sensor to earth, so R' = R [w]x
// with w the body angular velocity, which is what a gyroscope measures and
// what the local regression reports (body velocity per second). Both files
// are in seconds on the gyroscope's clock and the gyroscope is in rad/s, so
// the reference at an orientation sample's time is the gyroscope linearly
// interpolated there. What remains between the two is the on-board
// filter's lag and noise: no estimator from orientation reaches zero.
//
// Estimators, on the raw orientation and with Gaussian noise of 0.005 and
// 0.02 rad per axis added to every sample (R_i exp(e_i), seed 20261123):
//   finite differences: central, w_i = log(R_{i-1}^T R_{i+1}) / (t_{i+1} - t_{i-1})
//     (one-sided at the two ends);
//   the chart line: a Gaussian-weighted line through log(R_c^T R_j) at each
//     sample c, at the bandwidth that is best against the gyroscope (which
//     no smoother can see; bireg/testing/fast_motion.hpp);
//   bireg: LocalGeodesicRegression<SO3>, Gaussian kernel, what
//     `bireg_smooth --bandwidth auto` does: select_bandwidth over 20 values
//     from half a median sample spacing to the whole range, the velocity
//     smoothed at the velocity's choice;
//   the cubic spline: SplineRegression<SO3>, degree 3, its knot spacing by
//     select_knot_spacing over auto_knot_spacing_grid (5 folds), its
//     velocity at every sample;
//   the penalised cubic spline: the same at fine knots (fine_knot_spacing,
//     1.5 median sample spacings) with the roughness penalty chosen by
//     select_roughness_penalty over auto_roughness_penalty_grid, what
//     `bireg_smooth --method spline --roughness-penalty auto` does.
// Prints the RMS error |w - w_gyro| over all samples (rad/s) and the chosen
// bandwidths: for the 128 Hz recording, for it subsampled to 50 and 25 Hz
// (fast relative to the sampling: up to 0.2 and 0.4 rad between samples),
// and for simulated spins and a whip whose truth is known exactly. Draws
// `gyro_demo.svg` (or argv[1]): seconds 20 to 22 of the 128 Hz recording
// with the gyroscope, finite differences and bireg at 0.02 rad; and
// `gyro_spline.svg` (or argv[2]): the same seconds with the cubic spline's
// velocity and its pointwise 95% band (spline_covariance), whose share of
// samples holding the gyroscope on all three axes it prints.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "bireg/groups/so3.hpp"
#include "bireg/statistics/inference/spline_covariance.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
#include "bireg/statistics/smoothing/spline_roughness.hpp"
#include "bireg/testing/fast_motion.hpp"
#include "svg_plot.hpp"

namespace {

using SO3 = bireg::SO3d;
using Vector3 = SO3::Tangent;

using bireg::testing::finite_differences;
using bireg::testing::rms_error;

struct Smoothed {
  std::vector<Vector3> velocity;
  double bandwidth = 0;       // the velocity's
  double pose_bandwidth = 0;  // the pose's
  int degree = 2;             // the velocity's local polynomial
  int failed = 0;
  double mean_iterations = 0;
};

Smoothed smooth(const std::vector<SO3::Element>& r, const std::vector<double>& t) {
  bireg::LocalRegressionOptions<double> options;
  options.kernel = bireg::Kernel::gaussian;
  options.standard_errors = false;
  const std::vector<double> grid = bireg::auto_bandwidth_grid(t);
  const bireg::BandwidthSelection<double> selection =
      bireg::select_bandwidth<SO3>(r, t, options, grid);
  Smoothed out;
  out.bandwidth = selection.velocity_bandwidth;
  out.pose_bandwidth = selection.bandwidth;
  out.degree = selection.velocity_degree;
  if (!selection.ok()) return out;
  options.bandwidth = selection.velocity_bandwidth;
  options.velocity_degree = selection.velocity_degree;
  const auto estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(r, t);
  long iterations = 0;
  for (const auto& e : estimates) {
    out.velocity.push_back(e.velocity);
    out.failed += e.ok() ? 0 : 1;
    iterations += e.iterations;
  }
  out.mean_iterations = static_cast<double>(iterations) / static_cast<double>(estimates.size());
  return out;
}

// Writes `figure` to `path`; false, with a line on stderr, if it cannot.
bool save_svg(const std::string& path, const bireg_plot::Figure& figure) {
  std::ofstream out(path);
  out << bireg_plot::render_svg(figure);
  out.close();
  if (!out) std::fprintf(stderr, "gyro_demo: cannot write %s\n", path.c_str());
  return static_cast<bool>(out);
}

// One panel of the pictures: the body angular velocity about the sensor's
// axis k (rad/s) against time.
bireg_plot::Panel velocity_panel(int k) {
  const char* axes[] = {"x", "y", "z"};
  bireg_plot::Panel panel;
  panel.title = std::string("about the sensor's ") + axes[k] + " axis";
  panel.x_label = "time";
  panel.x_unit = "s";
  panel.y_label = std::string("w") + axes[k];
  panel.y_unit = "rad/s";
  return panel;
}

// The picture: over [from, to] seconds, one panel per axis with the
// gyroscope, finite differences and bireg (body angular velocity, rad/s).
bool write_plot_svg(const std::string& path, double from, double to, double noise,
                    const std::vector<double>& t, const std::vector<Vector3>& gyro,
                    const std::vector<Vector3>& differences, const std::vector<Vector3>& smoothed) {
  bireg_plot::Figure figure;
  figure.title = "x-IMU: body angular velocity from orientation alone, against the gyroscope";
  char subtitle[120];
  std::snprintf(subtitle, sizeof subtitle,
                "orientation noise %g rad added; bireg at the cross-validated bandwidth", noise);
  figure.subtitle = subtitle;
  for (int k = 0; k < 3; ++k) {
    bireg_plot::Series gyro_series{"gyroscope", "#444444", {}, {}, false, false};
    bireg_plot::Series difference_series{"finite differences", "#ff7f0e", {}, {}, false, true};
    bireg_plot::Series bireg_series{"bireg", "#1f77b4", {}, {}, false, false};
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] < from || t[i] > to) continue;
      for (auto [series, values] :
           {std::pair{&gyro_series, &gyro}, std::pair{&difference_series, &differences},
            std::pair{&bireg_series, &smoothed}}) {
        series->x.push_back(t[i]);
        series->y.push_back((*values)[i][k]);
      }
    }
    bireg_plot::Panel panel = velocity_panel(k);
    panel.series = {difference_series, gyro_series, bireg_series};
    figure.panels.push_back(panel);
  }
  return save_svg(path, figure);
}

// The cubic spline's velocity at the samples and the half-widths of its
// pointwise 95% band (statistics/inference/spline_covariance.hpp: the
// projections of the Hotelling ellipsoid on each axis), for the picture.
struct SplineVelocity {
  std::vector<Vector3> velocity, half_width;
};

// The cubic spline's column: its velocity's RMS error at the knot spacing
// chosen by cross-validation (statistics/smoothing/spline_knots.hpp), or
// why there is none; with `picture`, its velocity and band too.
std::string spline_cell(const std::vector<SO3::Element>& r, const std::vector<double>& t,
                        const std::vector<Vector3>& truth, SplineVelocity* picture = nullptr) {
  bireg::SplineOptions<double> options;
  const auto selection =
      bireg::select_knot_spacing<SO3>(r, t, options, bireg::auto_knot_spacing_grid(t));
  if (!selection.ok()) return "no spacing: " + selection.message;
  options.knot_spacing = selection.knot_spacing;
  const auto fit = bireg::SplineRegression<SO3>(options).fit(r, t);
  if (!fit.ok()) return std::string("failed: ") + bireg::to_string(fit.status);
  std::vector<Vector3> velocity;
  for (const double ti : t)
    velocity.push_back(fit.spline->body_velocity(ti));
  if (picture) {
    const auto covariance = bireg::spline_covariance(fit, r, t);
    const std::optional<double> q = bireg::pointwise_quantile(covariance, 0.95);
    if (!q) return "no band: " + covariance.message;
    picture->velocity = velocity;
    for (const double ti : t)
      picture->half_width.push_back(
          bireg::half_widths(bireg::velocity_covariance(covariance, ti), *q));
  }
  char cell[48];
  std::snprintf(cell, sizeof cell, "%.3f (%.4f)", rms_error(velocity, truth),
                selection.knot_spacing);
  return cell;
}

// The penalised cubic spline's column: its velocity's RMS error at fine
// knots and the lambda chosen by cross-validation
// (statistics/smoothing/spline_roughness.hpp), or why there is none.
std::string penalised_spline_cell(const std::vector<SO3::Element>& r, const std::vector<double>& t,
                                  const std::vector<Vector3>& truth) {
  bireg::SplineOptions<double> options;
  options.knot_spacing = bireg::fine_knot_spacing(t);
  const auto selection = bireg::select_roughness_penalty<SO3>(
      r, t, options, bireg::auto_roughness_penalty_grid(t, double(options.knot_spacing)));
  if (!selection.ok()) return "no penalty: " + selection.message;
  options.roughness_penalty = selection.roughness_penalty;
  const auto fit = bireg::SplineRegression<SO3>(options).fit(r, t);
  if (!fit.ok()) return std::string("failed: ") + bireg::to_string(fit.status);
  std::vector<Vector3> velocity;
  for (const double ti : t)
    velocity.push_back(fit.spline->body_velocity(ti));
  char cell[48];
  std::snprintf(cell, sizeof cell, "%.3f (%.2g)", rms_error(velocity, truth),
                selection.roughness_penalty);
  return cell;
}

// The spline's picture: over [from, to] seconds, one panel per axis with
// the gyroscope and the spline's velocity inside its pointwise 95% band.
bool write_spline_svg(const std::string& path, double from, double to, double noise,
                      const std::vector<double>& t, const std::vector<Vector3>& gyro,
                      const SplineVelocity& spline) {
  bireg_plot::Figure figure;
  figure.title =
      "x-IMU: the cubic spline's angular velocity and its 95% band, against the gyroscope";
  char subtitle[120];
  std::snprintf(subtitle, sizeof subtitle,
                "orientation noise %g rad added; knot spacing by cross-validation", noise);
  figure.subtitle = subtitle;
  for (int k = 0; k < 3; ++k) {
    bireg_plot::Series gyro_series{"gyroscope", "#444444", {}, {}, false, false};
    bireg_plot::Series spline_series{"cubic spline", "#2ca02c", {}, {}, false, false};
    bireg_plot::Band band{"pointwise 95% band", "#2ca02c", {}, {}, {}};
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] < from || t[i] > to) continue;
      gyro_series.x.push_back(t[i]);
      gyro_series.y.push_back(gyro[i][k]);
      spline_series.x.push_back(t[i]);
      spline_series.y.push_back(spline.velocity[i][k]);
      band.x.push_back(t[i]);
      band.lower.push_back(spline.velocity[i][k] - spline.half_width[i][k]);
      band.upper.push_back(spline.velocity[i][k] + spline.half_width[i][k]);
    }
    bireg_plot::Panel panel = velocity_panel(k);
    panel.bands = {band};
    panel.series = {gyro_series, spline_series};
    figure.panels.push_back(panel);
  }
  return save_svg(path, figure);
}

// The fraction of samples whose reference lies inside the band on every axis.
double band_coverage(const SplineVelocity& spline, const std::vector<Vector3>& truth) {
  std::size_t inside = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Vector3 off = (spline.velocity[i] - truth[i]).cwiseAbs();
    inside += (off.array() <= spline.half_width[i].array()).all() ? 1 : 0;
  }
  return truth.empty() ? 0.0 : double(inside) / double(truth.size());
}

// One row of the table: the three estimators' RMS errors against `truth`
// and bireg's bandwidths. Returns bireg's velocities (empty on failure).
std::vector<Vector3> print_row(const std::string& label, double noise,
                               const std::vector<SO3::Element>& r, const std::vector<double>& t,
                               const std::vector<Vector3>& truth,
                               SplineVelocity* spline = nullptr) {
  const std::vector<Vector3> differences = finite_differences(r, t);
  const auto [chart, chart_bandwidth] = bireg::testing::oracle_chart_line(r, t, truth);
  const Smoothed smoothed = smooth(r, t);
  if (smoothed.velocity.empty() || smoothed.failed > 0) {
    std::fprintf(stderr, "gyro_demo: %s, noise %g: the local regression failed (%d queries)\n",
                 label.c_str(), noise, smoothed.failed);
    return {};
  }
  std::printf("| %s | %g | %.3f | %.3f (%.4f) | %.3f | %.4f, %.4f, %s | %.2f | %s | %s |\n",
              label.c_str(), noise, rms_error(differences, truth), chart, chart_bandwidth,
              rms_error(smoothed.velocity, truth), smoothed.pose_bandwidth, smoothed.bandwidth,
              smoothed.degree == 3 ? "cubic" : "quadratic", smoothed.mean_iterations,
              spline_cell(r, t, truth, spline).c_str(), penalised_spline_cell(r, t, truth).c_str());
  return smoothed.velocity;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = BIREG_DEMO_DATA_DIR;
  bireg::testing::Recording orientation, gyroscope;
  for (const std::string& problem :
       {bireg::testing::read_recording(dir + "/xio_imu_orientation.csv", 9, orientation),
        bireg::testing::read_recording(dir + "/xio_imu_gyroscope.csv", 3, gyroscope)}) {
    if (!problem.empty()) {
      std::fprintf(stderr, "gyro_demo: %s\n", problem.c_str());
      return 1;
    }
  }
  std::vector<SO3::Element> raw;
  std::vector<Vector3> reference;
  for (std::size_t i = 0; i < orientation.t.size(); ++i) {
    const std::vector<double>& m = orientation.values[i];
    SO3::Element r;
    r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
    raw.push_back(r);
    reference.push_back(bireg::testing::rate_at(gyroscope, orientation.t[i]));
  }
  std::printf("x-IMU recording: %zu orientation samples over %.1f s; gyroscope RMS %.3f rad/s\n\n",
              raw.size(), orientation.t.back() - orientation.t.front(),
              rms_error(reference, std::vector<Vector3>(raw.size(), Vector3::Zero())));
  const char* header =
      "| recording | orientation noise (rad) | finite differences RMS (rad/s) | chart line "
      "RMS, best bandwidth (s) | bireg RMS (rad/s) | bireg bandwidths, pose and velocity (s), "
      "velocity's degree "
      "| GN iterations per query | cubic spline RMS, knot spacing (s) | penalised cubic spline "
      "RMS, lambda |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  std::printf("%s", header);
  std::mt19937 rng(20261123);
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::string plot_path = argc > 1 ? argv[1] : "gyro_demo.svg";
  const std::string spline_path = argc > 2 ? argv[2] : "gyro_spline.svg";
  double spline_band_coverage = 0;
  for (const double hz : {128.0, 50.0, 25.0}) {
    const std::vector<std::size_t> kept = bireg::testing::subsample(orientation.t, hz);
    for (const double noise : {0.0, 0.005, 0.02}) {
      std::vector<SO3::Element> r;
      std::vector<double> t;
      std::vector<Vector3> truth;
      for (const std::size_t i : kept) {
        const Vector3 e = bireg::testing::draw_vector<Vector3>(rng, normal);
        r.push_back(SO3::compose(raw[i], SO3::exp(noise * e)));
        t.push_back(orientation.t[i]);
        truth.push_back(reference[i]);
      }
      char label[40];
      std::snprintf(label, sizeof label, "x-IMU at %g Hz", hz);
      const bool drawn = hz == 128.0 && noise == 0.02;
      SplineVelocity spline;
      const std::vector<Vector3> smoothed =
          print_row(label, noise, r, t, truth, drawn ? &spline : nullptr);
      if (smoothed.empty()) return 1;
      if (drawn && (spline.velocity.empty() ||
                    !write_plot_svg(plot_path, 20.0, 22.0, noise, t, truth,
                                    finite_differences(r, t), smoothed) ||
                    !write_spline_svg(spline_path, 20.0, 22.0, noise, t, truth, spline))) {
        return 1;
      }
      if (drawn) spline_band_coverage = band_coverage(spline, truth);
    }
  }
  std::printf("\nSimulated (bireg/testing/fast_motion.hpp: the truth is the simulated rate)\n\n%s",
              header);
  namespace motion = bireg::testing;
  for (const double noise : {0.0, 0.005, 0.02}) {
    for (const double speed : {5.0, 10.0, 20.0}) {
      for (const double hz : {25.0, 50.0, 100.0}) {
        const motion::RotationTrack track =
            motion::sample_rotation(motion::spin(speed), 4.0, hz, noise, 11);
        char label[48];
        std::snprintf(label, sizeof label, "spin %g rad/s at %g Hz", speed, hz);
        if (print_row(label, noise, track.f, track.t, track.velocity).empty()) return 1;
      }
    }
    for (const double hz : {60.0, 120.0}) {
      const motion::RotationTrack track =
          motion::sample_rotation(motion::whip(), 2.0, hz, noise, 13);
      char label[48];
      std::snprintf(label, sizeof label, "whip to 16 rad/s at %g Hz", hz);
      if (print_row(label, noise, track.f, track.t, track.velocity).empty()) return 1;
    }
  }
  std::printf("\nplots (128 Hz, 20-22 s, noise 0.02 rad): %s, %s\n", plot_path.c_str(),
              spline_path.c_str());
  std::printf(
      "the spline's pointwise 95%% velocity band holds the gyroscope on all three axes at %.1f%% "
      "of the 128 Hz samples (noise 0.02 rad)\n",
      100 * spline_band_coverage);
  return 0;
}
