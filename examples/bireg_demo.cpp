// bireg_demo: fits the geodesic to two real trajectories shipped in
// examples/data and draws each fit.
//
//   bireg_demo [DATA_DIR] [OUTPUT_DIR]
//
// For each trajectory it prints the fitted velocities, the residual RMS
// before (about the data's bi-invariant mean) and after the fit, the
// iterations, the time taken and the 95% confidence band's width, and writes
// an SVG (examples/svg_plot.hpp): the data in the log chart at the fitted
// start point, log(g0^{-1} f_i) against time, where the fitted geodesic is
// the straight line s X, with its confidence band shaded around it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "svg_plot.hpp"

#ifndef BIREG_DEMO_DATA_DIR
#define BIREG_DEMO_DATA_DIR "examples/data"
#endif

namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;
constexpr double kLevel = 0.95;  // of the confidence bands
constexpr const char* kSubtitle =
    "dots: data in the log chart at the fitted start g0, where the fit is a straight line; "
    "shaded: its 95% band";

template <class G>
struct Fitted {
  bireg::io::Trajectory<G> data;
  typename bireg::GeodesicRegression<G>::Result result;
  double milliseconds = 0;
};

// Reads and fits one trajectory; the fit is repeated to time it reliably.
template <class G>
bool fit_file(const std::string& path, bireg::io::Format format, Fitted<G>& out) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "bireg_demo: cannot open %s\n", path.c_str());
    return false;
  }
  if (const auto error = bireg::io::read_trajectory<G>(in, format, out.data)) {
    std::fprintf(stderr, "bireg_demo: %s:%llu: %s\n", path.c_str(),
                 static_cast<unsigned long long>(error->line), error->message.c_str());
    return false;
  }
  const bireg::GeodesicRegression<G> regression;
  constexpr int kRepeats = 20;
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < kRepeats; ++r)
    out.result = regression.fit(out.data.observations, out.data.covariates);
  const auto stop = std::chrono::steady_clock::now();
  out.milliseconds = std::chrono::duration<double, std::milli>(stop - start).count() / kRepeats;
  if (!out.result.ok()) {
    std::fprintf(stderr, "bireg_demo: %s: fit %s %s\n", path.c_str(),
                 bireg::to_string(out.result.status), out.result.message.c_str());
    return false;
  }
  return true;
}

// The 95% confidence band of the fitted geodesic, in the chart the pictures
// use. The fitted pose at s is gamma(s) exp(eps), eps with covariance
// pose_covariance(); in the chart at g0 that is log(exp(sX) exp(eps)) = sX +
// J_r(sX)^{-1} eps to first order, so the chart covariance is J_r(sX)^{-1}
// C J_r(sX)^{-T}. The half-widths are the projections of the pose's 95%
// ellipsoid (pose_quantile), so each time's band holds all coordinates at
// once, as in README "How sure is the fit".
template <class G>
struct ChartBand {
  std::vector<double> times;
  std::vector<typename G::Tangent> centre, half_width;
};

template <class G>
ChartBand<G> chart_band(const bireg::FitCovariance<G>& covariance, double quantile) {
  constexpr int kGrid = 61;  // enough for a smooth outline at 760 px
  const auto& geodesic = covariance.geodesic;
  const typename G::Tangent x = geodesic.displacement();
  ChartBand<G> band;
  for (int j = 0; j < kGrid; ++j) {
    const double s = static_cast<double>(j) / (kGrid - 1);
    const double t = geodesic.t_min() + s * (geodesic.t_max() - geodesic.t_min());
    const typename G::AdMatrix to_chart = bireg::right_jacobian_inverse<G>(s * x);
    const typename G::AdMatrix chart_covariance =
        to_chart * bireg::pose_covariance(covariance, t) * to_chart.transpose();
    band.times.push_back(t);
    band.centre.push_back(s * x);
    band.half_width.push_back(bireg::half_widths(chart_covariance, quantile));
  }
  return band;
}

// Which picture of three chart coordinates: the data and the fitted line,
// or the data minus the fitted line, where a band too narrow to see beside
// the whole motion becomes readable.
enum class View { chart, about_fit };

// Three chart coordinates, first .. first + 2, against time, times `scale`:
// the data log(g0^{-1} f_i), the fitted line s X and its band (View::chart),
// or the data minus s X with the band about zero (View::about_fit).
template <class G>
bireg_plot::Panel chart_panel(const Fitted<G>& fitted, const ChartBand<G>& band, int first,
                              double scale, View view, bireg_plot::Panel panel) {
  const char* colours[] = {"#d62728", "#2ca02c", "#1f77b4"};
  const char* names[] = {"x", "y", "z"};
  const auto& geodesic = *fitted.result.geodesic;
  const bool about_fit = view == View::about_fit;
  for (int c = 0; c < 3; ++c) {
    const int k = first + c;
    const std::string name = names[c];
    bireg_plot::Series data{name + " data", colours[c], fitted.data.covariates, {}, true, false};
    for (std::size_t i = 0; i < fitted.data.observations.size(); ++i) {
      const double line =
          about_fit ? geodesic.normalized(fitted.data.covariates[i]) * geodesic.displacement()[k]
                    : 0.0;
      data.y.push_back(scale *
                       (bireg::log_at<G>(geodesic.start(), fitted.data.observations[i])[k] - line));
    }
    bireg_plot::Series fit{name + " fit", colours[c], band.times, {}, false, false};
    bireg_plot::Band confidence{
        name + (about_fit ? " 95% band" : " fit, 95% band"), colours[c], band.times, {}, {}};
    for (std::size_t j = 0; j < band.times.size(); ++j) {
      const double centre = about_fit ? 0.0 : scale * band.centre[j][k];
      const double half = scale * band.half_width[j][k];
      fit.y.push_back(centre);
      confidence.lower.push_back(centre - half);
      confidence.upper.push_back(centre + half);
    }
    panel.series.push_back(data);
    if (!about_fit) panel.series.push_back(fit);
    panel.bands.push_back(confidence);
  }
  if (about_fit) {
    panel.series.push_back(
        {"fitted line", "#333", {geodesic.t_min(), geodesic.t_max()}, {0, 0}, false, true});
  }
  return panel;
}

// The largest half-width of coordinates first .. first + 2 along the band.
template <class G>
double widest(const ChartBand<G>& band, int first) {
  double widest = 0;
  for (const auto& half : band.half_width) {
    widest = std::max(widest, half.template segment<3>(first).maxCoeff());
  }
  return widest;
}

// Standard error of a speed |v| by the delta method: sqrt(u^T C u), u = v / |v|.
template <class Vector, class Matrix>
double speed_standard_error(const Vector& v, const Matrix& c) {
  const Vector u = v.normalized();
  return std::sqrt(std::max(0.0, u.dot(c * u)));
}

// The robust covariance of the fit (real data: the noise need not be the
// same all along) and its 95% pose quantile; false, with a message, where
// the covariance is undefined.
template <class G>
bool fit_covariance(const Fitted<G>& fitted, bireg::FitCovariance<G>& covariance,
                    double& quantile) {
  covariance = bireg::covariance(fitted.result, fitted.data.covariates, {},
                                 bireg::CovarianceFlavour::robust);
  const std::optional<double> q =
      covariance.defined() ? bireg::pose_quantile(covariance, kLevel) : std::optional<double>();
  if (!q) {
    std::fprintf(stderr, "bireg_demo: no confidence band: %s\n",
                 covariance.defined() ? "too few degrees of freedom" : covariance.message.c_str());
    return false;
  }
  quantile = *q;
  return true;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  std::printf("  picture                    %s\n", path.c_str());
}

template <class G>
void print_common(const Fitted<G>& fitted) {
  const auto& d = fitted.result.diagnostics;
  std::printf("  explained variance         %.4f\n", d.explained_variance);
  std::printf("  iterations                 %d (status %s, observed contraction %.3f)\n",
              fitted.result.iterations, bireg::to_string(fitted.result.status),
              d.contraction_factor);
  std::printf("  time                       %.3f ms per fit\n", fitted.milliseconds);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string data_dir = argc > 1 ? argv[1] : BIREG_DEMO_DATA_DIR;
  const std::string out_dir = argc > 2 ? argv[2] : ".";

  // x-IMU: a rotation, SO(3).
  using Rotation = bireg::SO3<double>;
  Fitted<Rotation> imu;
  if (!fit_file(data_dir + "/so3_xio_imu_window.csv", bireg::io::Format::matrix, imu)) return 1;
  {
    const auto& r = imu.result;
    const double seconds = r.geodesic->t_max() - r.geodesic->t_min();
    const Rotation::Tangent w = r.geodesic->body_velocity();
    std::printf("x-IMU orientation (SO3, %zu samples over %.2f s)\n", imu.data.observations.size(),
                seconds);
    std::printf("  fitted angular velocity    %.1f deg/s about body axis (%.3f, %.3f, %.3f)\n",
                w.norm() * kDegrees, w[0] / w.norm(), w[1] / w.norm(), w[2] / w.norm());
    std::printf("  residual RMS               %.2f deg before (about the mean), %.2f deg after\n",
                r.diagnostics.residual_rms_about_mean * kDegrees,
                r.diagnostics.residual_rms * kDegrees);
    print_common(imu);
    bireg::FitCovariance<Rotation> covariance;
    double quantile = 0;
    if (!fit_covariance(imu, covariance, quantile)) return 1;
    const ChartBand<Rotation> band = chart_band(covariance, quantile);
    const double speed_error =
        speed_standard_error(w, bireg::velocity_covariance(covariance)) * kDegrees;
    std::printf(
        "  95%% confidence band        +-%.2f deg at most; speed standard error %.2f deg/s\n",
        widest(band, 0) * kDegrees, speed_error);
    bireg_plot::Figure figure;
    figure.title = "x-IMU orientation: geodesic fit with its 95% confidence band";
    figure.subtitle = kSubtitle;
    figure.panels.push_back(chart_panel(
        imu, band, 0, kDegrees, View::chart,
        {"rotation: log(g0^-1 f), body axes", "time", "s", "rotation vector", "deg", {}, {}}));
    figure.panels.push_back(
        chart_panel(imu, band, 0, kDegrees, View::about_fit,
                    {"rotation minus the fitted line", "time", "s", "deviation", "deg", {}, {}}));
    write_file(out_dir + "/demo_so3_imu.svg", bireg_plot::render_svg(figure));
  }

  // DeepMimic walk: a rigid motion, SE(3) (tangent = translation, rotation).
  using Pose = bireg::SE3<double>;
  Fitted<Pose> walk;
  if (!fit_file(data_dir + "/se3_deepmimic_walk.tum", bireg::io::Format::tum, walk)) return 1;
  {
    const auto& r = walk.result;
    const double seconds = r.geodesic->t_max() - r.geodesic->t_min();
    const Pose::Tangent v = r.geodesic->body_velocity();
    double rotation_sq = 0, translation_sq = 0;
    for (const auto& residual : r.residuals) {
      translation_sq += residual.head<3>().squaredNorm();
      rotation_sq += residual.tail<3>().squaredNorm();
    }
    const double n = static_cast<double>(r.residuals.size());
    std::printf("\nDeepMimic walk, pelvis pose (SE3, %zu samples over %.2f s)\n",
                walk.data.observations.size(), seconds);
    std::printf("  fitted linear velocity     %.3f m/s (body frame)\n", v.head<3>().norm());
    std::printf("  fitted angular velocity    %.1f deg/s\n", v.tail<3>().norm() * kDegrees);
    std::printf(
        "  residual RMS               %.4f before (about the mean), %.4f after (tangent norm, m "
        "and rad)\n",
        r.diagnostics.residual_rms_about_mean, r.diagnostics.residual_rms);
    std::printf("                             after: %.4f m translation, %.2f deg rotation\n",
                std::sqrt(translation_sq / n), std::sqrt(rotation_sq / n) * kDegrees);
    print_common(walk);
    bireg::FitCovariance<Pose> covariance;
    double quantile = 0;
    if (!fit_covariance(walk, covariance, quantile)) return 1;
    const ChartBand<Pose> band = chart_band(covariance, quantile);
    const Pose::AdMatrix velocity_covariance = bireg::velocity_covariance(covariance);
    const double linear_error = speed_standard_error(
        Eigen::Vector3d(v.head<3>()), Eigen::Matrix3d(velocity_covariance.topLeftCorner<3, 3>()));
    const double angular_error =
        speed_standard_error(Eigen::Vector3d(v.tail<3>()),
                             Eigen::Matrix3d(velocity_covariance.bottomRightCorner<3, 3>())) *
        kDegrees;
    std::printf(
        "  95%% confidence band        +-%.4f m, +-%.2f deg at most; speed s.e. %.3f "
        "m/s, %.2f deg/s\n",
        widest(band, 0), widest(band, 3) * kDegrees, linear_error, angular_error);
    bireg_plot::Figure figure;
    figure.title = "DeepMimic walk, pelvis: geodesic fit with its 95% confidence band";
    figure.subtitle = kSubtitle;
    figure.panel_height = 250;
    figure.panels.push_back(
        chart_panel(walk, band, 0, 1.0, View::chart,
                    {"translation part of log(g0^-1 f)", "time", "s", "translation", "m", {}, {}}));
    figure.panels.push_back(
        chart_panel(walk, band, 0, 1.0, View::about_fit,
                    {"translation minus the fitted line", "time", "s", "deviation", "m", {}, {}}));
    figure.panels.push_back(chart_panel(
        walk, band, 3, kDegrees, View::chart,
        {"rotation part of log(g0^-1 f)", "time", "s", "rotation vector", "deg", {}, {}}));
    figure.panels.push_back(
        chart_panel(walk, band, 3, kDegrees, View::about_fit,
                    {"rotation minus the fitted line", "time", "s", "deviation", "deg", {}, {}}));
    write_file(out_dir + "/demo_se3_walk.svg", bireg_plot::render_svg(figure));
  }
  return 0;
}
