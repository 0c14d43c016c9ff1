// bireg_demo: fits the geodesic to two real trajectories shipped in
// examples/data and draws each fit.
//
//   bireg_demo [DATA_DIR] [OUTPUT_DIR]
//
// For each trajectory it prints the fitted velocities, the residual RMS
// before (about the data's bi-invariant mean) and after the fit, the
// iterations and the time taken, and writes an SVG: the data in the log chart
// at the fitted start point, log(g0^{-1} f_i) against time, where the fitted
// geodesic is the straight line s X.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"

#ifndef BIREG_DEMO_DATA_DIR
#define BIREG_DEMO_DATA_DIR "examples/data"
#endif

namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

// One panel of the picture: several coordinates against time, as dots (data)
// and straight segments (the fitted geodesic in the chart).
struct Panel {
  std::string title;
  std::string unit;
  std::vector<std::string> labels;
  std::vector<std::vector<double>> data;   // [coordinate][observation]
  std::vector<double> fit_start, fit_end;  // fitted line at t_min and t_max
};

std::string svg_panels(const std::string& title, const std::vector<double>& t,
                       const std::vector<Panel>& panels) {
  const char* colours[] = {"#d62728", "#2ca02c", "#1f77b4"};
  const double width = 720, panel_height = 260, left = 70, right = 60, top = 56;
  const double plot_w = width - left - right, plot_h = panel_height - 70;
  const double height = top + panels.size() * panel_height;
  const auto [t_lo, t_hi] = std::minmax_element(t.begin(), t.end());
  const double t0 = *t_lo, t1 = *t_hi;
  std::string svg;
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" "
      "fill=\"white\"/>\n<text x=\"%.0f\" y=\"22\" font-size=\"15\">%s</text>\n"
      "<text x=\"%.0f\" y=\"40\" fill=\"#555\">dots: data, lines: the fitted geodesic "
      "(a straight line in this chart)</text>\n",
      width, height, left, title.c_str(), left);
  svg += buf;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const Panel& panel = panels[p];
    const double y_top = top + p * panel_height + 20;
    double lo = 0, hi = 0;
    for (const auto& series : panel.data) {
      for (double y : series)
        lo = std::min(lo, y), hi = std::max(hi, y);
    }
    const double pad = 0.05 * (hi - lo + 1e-12);
    lo -= pad;
    hi += pad;
    const auto x_of = [&](double ti) { return left + (ti - t0) / (t1 - t0) * plot_w; };
    const auto y_of = [&](double y) { return y_top + (hi - y) / (hi - lo) * plot_h; };
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%.0f\" y=\"%.0f\" font-size=\"13\">%s</text>\n"
                  "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
                  "stroke=\"#999\"/>\n",
                  left, y_top - 6, panel.title.c_str(), left, y_top, plot_w, plot_h);
    svg += buf;
    for (int tick = 0; tick <= 4; ++tick) {  // axis labels
      const double y = lo + (hi - lo) * tick / 4, ti = t0 + (t1 - t0) * tick / 4;
      std::snprintf(buf, sizeof buf,
                    "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"end\">%.3g</text>\n"
                    "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">%.4g</text>\n",
                    left - 6, y_of(y) + 4, y, x_of(ti), y_top + plot_h + 16, ti);
      svg += buf;
    }
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">time [s]</text>\n"
                  "<text x=\"16\" y=\"%.0f\" transform=\"rotate(-90 16 %.0f)\" "
                  "text-anchor=\"middle\">%s</text>\n",
                  left + plot_w / 2, y_top + plot_h + 34, y_top + plot_h / 2, y_top + plot_h / 2,
                  panel.unit.c_str());
    svg += buf;
    for (std::size_t k = 0; k < panel.data.size(); ++k) {
      const char* colour = colours[k % 3];
      for (std::size_t i = 0; i < t.size(); ++i) {
        std::snprintf(buf, sizeof buf, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.2\" fill=\"%s\"/>\n",
                      x_of(t[i]), y_of(panel.data[k][i]), colour);
        svg += buf;
      }
      std::snprintf(buf, sizeof buf,
                    "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"%s\" "
                    "stroke-width=\"1.5\"/>\n<text x=\"%.0f\" y=\"%.0f\" fill=\"%s\">%s</text>\n",
                    x_of(t0), y_of(panel.fit_start[k]), x_of(t1), y_of(panel.fit_end[k]), colour,
                    left + plot_w + 10, y_top + 16 + 18.0 * k, colour, panel.labels[k].c_str());
      svg += buf;
    }
  }
  return svg + "</svg>\n";
}

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

// Coordinates of log(g0^{-1} f_i), and of the fitted line, for the picture.
template <class G>
std::vector<Panel> chart_panels(const Fitted<G>& fitted, int first, int count, Panel panel) {
  const auto& geodesic = *fitted.result.geodesic;
  for (int k = first; k < first + count; ++k) {
    std::vector<double> series;
    for (const auto& f : fitted.data.observations)
      series.push_back(bireg::log_at<G>(geodesic.start(), f)[k]);
    panel.data.push_back(series);
    panel.fit_start.push_back(0.0);
    panel.fit_end.push_back(geodesic.displacement()[k]);
  }
  return {panel};
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
    Panel panel{"rotation vector log(g0^-1 f)", "rad", {"x", "y", "z"}, {}, {}, {}};
    write_file(out_dir + "/demo_so3_imu.svg",
               svg_panels("x-IMU orientation: data in the log chart at the fitted start",
                          imu.data.covariates, chart_panels(imu, 0, 3, panel)));
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
    std::vector<Panel> panels =
        chart_panels(walk, 0, 3, Panel{"translation part", "m", {"x", "y", "z"}, {}, {}, {}});
    const std::vector<Panel> rotation =
        chart_panels(walk, 3, 3, Panel{"rotation part", "rad", {"rx", "ry", "rz"}, {}, {}, {}});
    panels.push_back(rotation.front());
    write_file(out_dir + "/demo_se3_walk.svg",
               svg_panels("DeepMimic walk: data in the log chart at the fitted start",
                          walk.data.covariates, panels));
  }
  return 0;
}
