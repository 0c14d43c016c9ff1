// bireg_fit's statistical report: the JSON sections of --confidence and
// --permutations and the CSV of --output-band. Kept out of bireg_fit.cpp so
// that the tool's driver stays readable; not shared with bireg_smooth.
//
// Coordinates. Every vector and covariance here is in the group's tangent
// coordinates, left-trivialised (a perturbation eps of a pose g means
// g exp(eps)): for SE3 and Sim3 translation first, then rotation (and
// Sim3's log-scale last), for SE2 (x, y, angle), for SO2/SO3 the rotation
// vector, for SL3 and GLp3 the coordinates of their Lie algebra's basis
// (bireg/groups/matrix_group.hpp), which have no rotation/translation
// split. Rotation coordinates are in radians (degrees in the band file),
// translation coordinates in the data's units and along the pose's own
// axes (g exp((rho, 0)) moves the position by R rho).
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "bireg/io/formats.hpp"
#include "bireg/io/writers.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "cli_common.hpp"

namespace bireg_fit_report {

using bireg::io::json_matrix;
using bireg::io::json_number;

// What one tangent coordinate measures.
enum class Kind { translation, rotation, other };

struct Coordinate {
  std::string name;
  Kind kind;
};

// The tangent layout of G (see the header comment).
template <class G>
std::vector<Coordinate> coordinates() {
  const std::string group = G::name;
  const auto translation = [](const char* axis) {
    return Coordinate{std::string("trans_") + axis, Kind::translation};
  };
  const auto rotation = [](const char* axis) {
    return Coordinate{std::string("rot_") + axis, Kind::rotation};
  };
  if (group == "SO2") return {Coordinate{"rot", Kind::rotation}};
  if (group == "SO3") return {rotation("x"), rotation("y"), rotation("z")};
  if (group == "SE2")
    return {translation("x"), translation("y"), Coordinate{"rot", Kind::rotation}};
  if (group == "SE3" || group == "Sim3") {
    std::vector<Coordinate> layout = {translation("x"), translation("y"), translation("z"),
                                      rotation("x"),    rotation("y"),    rotation("z")};
    if (group == "Sim3") layout.push_back(Coordinate{"log_scale", Kind::other});
    return layout;
  }
  std::vector<Coordinate> layout;
  for (int k = 0; k < G::dof; ++k)
    layout.push_back(Coordinate{"x" + std::to_string(k + 1), Kind::other});
  return layout;
}

using bireg_cli::json_text;

template <class Vector>
std::string json_vector(const Vector& v) {
  std::string s = "[";
  for (int k = 0; k < v.size(); ++k)
    s += (k ? ", " : "") + json_number(v[k]);
  return s + "]";
}

template <class G>
std::string json_layout() {
  std::string s = "[";
  for (const Coordinate& c : coordinates<G>())
    s += (s.size() > 1 ? ", " : "") + json_text(c.name);
  return s + "]";
}

// Both covariance flavours of one fit, or why they are undefined.
template <class G>
struct Covariances {
  bireg::FitCovariance<G> homoscedastic, robust;
  std::string problem;  // empty when both are defined

  bool defined() const { return problem.empty(); }
};

// `weights`: the weights the fit used (the final robust weights with
// --loss, treated as fixed; empty: all 1).
template <class G>
Covariances<G> covariances(const bireg::RegressionResult<G>& fit,
                           const std::vector<double>& covariates,
                           const std::vector<double>& weights) {
  Covariances<G> c;
  c.homoscedastic =
      bireg::covariance(fit, covariates, weights, bireg::CovarianceFlavour::homoscedastic);
  c.robust = bireg::covariance(fit, covariates, weights, bireg::CovarianceFlavour::robust);
  for (const auto* flavour : {&c.homoscedastic, &c.robust}) {
    if (flavour->status != bireg::CovarianceStatus::defined && c.problem.empty()) {
      c.problem =
          std::string(bireg::to_string(flavour->flavour)) + " covariance: " + flavour->message;
    }
  }
  return c;
}

// The "confidence" JSON object (without its key). `defined` is set false
// when the covariance or the explained variance is undefined: the object
// then has "covariance_defined": false or "explained_variance":
// {"defined": false} with a "message" instead of the numbers (no null).
template <class G>
std::string confidence_json(const Covariances<G>& c, const bireg::RegressionResult<G>& fit,
                            const bireg::MeanResult<G>& mean, const std::vector<double>& weights,
                            double level, bool robust_weights, bool& defined) {
  std::string json = "{\"level\": " + json_number(level) +
                     ", \"coordinates\": " + json_layout<G>() + ",\n   \"covariance_weights\": " +
                     json_text(robust_weights ? "final robust weights, held fixed" : "none") +
                     ",\n   ";
  const bireg::Geodesic<G>& geodesic = *fit.geodesic;
  const double range = geodesic.t_max() - geodesic.t_min();
  const typename G::Tangent velocity = geodesic.displacement() / range;
  json += "\"velocity\": " + json_vector(velocity) + ",\n   ";
  defined = c.defined();
  if (c.defined()) {
    json += "\"covariance_defined\": true,\n   ";
    const auto velocity_se = bireg::standard_errors(bireg::velocity_covariance(c.homoscedastic));
    const auto velocity_se_robust = bireg::standard_errors(bireg::velocity_covariance(c.robust));
    json += "\"velocity_standard_error\": {\"homoscedastic\": " + json_vector(velocity_se) +
            ", \"heteroscedasticity_robust\": " + json_vector(velocity_se_robust) + "},\n   ";
    json +=
        "\"endpoint_covariance\": {\"homoscedastic\": " + json_matrix(c.homoscedastic.endpoints) +
        ",\n    \"heteroscedasticity_robust\": " + json_matrix(c.robust.endpoints) + "},\n   ";
    json += "\"degrees_of_freedom\": {\"homoscedastic\": " +
            json_number(c.homoscedastic.degrees_of_freedom) +
            ", \"robust_endpoints\": " + json_number(c.robust.effective.endpoints) +
            ", \"robust_velocity\": " + json_number(c.robust.effective.velocity) + "},\n   ";
  } else {
    json += "\"covariance_defined\": false, \"message\": " + json_text(c.problem) + ",\n   ";
  }
  const auto explained = bireg::explained_variance(fit, mean, weights);
  if (explained.defined) {
    json += "\"explained_variance\": {\"defined\": true, \"r_squared\": " +
            json_number(explained.euclidean) +
            ", \"wilks_lambda\": " + json_number(explained.wilks_lambda) +
            ", \"generalized\": " + json_number(explained.generalized) +
            ", \"rank\": " + std::to_string(explained.rank) +
            (explained.message.empty() ? "" : ", \"note\": " + json_text(explained.message)) + "}";
  } else {
    defined = false;
    json += "\"explained_variance\": {\"defined\": false, \"message\": " +
            json_text(explained.message) + "}";
  }
  return json + "}";
}

// The "trend_test" JSON object (without its key); `defined` false when the
// test could not run (the object says why).
template <class G>
std::string trend_test_json(const bireg::TrendTestResult<G>& test, int permutations,
                            std::uint64_t seed, bool& defined) {
  std::string json =
      "{\"permutations\": " + std::to_string(permutations) + ", \"seed\": " + std::to_string(seed);
  defined = test.ok();
  if (!defined) return json + ", \"defined\": false, \"message\": " + json_text(test.message) + "}";
  json += ", \"defined\": true, \"statistic\": \"wilks_lambda\", \"wilks_lambda\": " +
          json_number(test.statistic) + ", \"p_value\": " + json_number(test.p_value) +
          ", \"at_least_as_extreme\": " + std::to_string(test.at_least_as_extreme) +
          ", \"failed_permutations\": " + std::to_string(test.failed_permutations);
  if (!test.message.empty()) json += ", \"note\": " + json_text(test.message);
  return json + "}";
}

// The band's quantile at `level`, or why there is none: the covariance
// is undefined, or it has too few degrees of freedom for the quantile.
// Either is an undefined statistic (exit code 5), not a write error.
template <class G>
std::optional<double> band_quantile(const Covariances<G>& covariances, double level,
                                    std::string& problem) {
  if (!covariances.defined()) {
    problem = covariances.problem;
    return std::nullopt;
  }
  const std::optional<double> quantile = bireg::pose_quantile(covariances.homoscedastic, level);
  if (!quantile) problem = "too few degrees of freedom for the band's quantile";
  return quantile;
}

// Writes the band CSV: a header line, then per input observation (input
// order) its timestamp as written in the input, the fitted pose's matrix
// entries row by row, and the half-widths of the homoscedastic `level`
// confidence ellipsoid of the pose projected on each tangent coordinate
// (rotation in degrees, translation in the data's units, other
// coordinates as they are), scaled by `quantile` (band_quantile's).
// Returns "path: reason" when the file cannot be written.
template <class G>
std::optional<std::string> write_band(const std::string& path,
                                      const bireg::io::Trajectory<G>& trajectory,
                                      const bireg::FitCovariance<G>& c, double quantile) {
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  const std::vector<Coordinate> layout = coordinates<G>();
  const int side = bireg::io::matrix_side<G>();
  std::string text = "timestamp";
  for (int r = 0; r < side; ++r) {
    for (int k = 0; k < side; ++k)
      text += ",m" + std::to_string(r) + std::to_string(k);
  }
  for (const Coordinate& coordinate : layout) {
    text += ",half_width_" + coordinate.name + (coordinate.kind == Kind::rotation ? "_deg" : "");
  }
  text += '\n';
  for (std::size_t i = 0; i < trajectory.covariates.size(); ++i) {
    const double t = trajectory.covariates[i];
    const bireg::io::Timestamp& stamp = trajectory.timestamps[i];
    text += stamp.text.empty() ? bireg::io::render_timestamp(stamp, bireg::io::TimeUnit::seconds)
                               : stamp.text;
    const typename G::Element pose = c.geodesic(t);
    for (int r = 0; r < side; ++r) {
      for (int k = 0; k < side; ++k) {
        text += ',';
        bireg::io::append_double(text, pose(r, k));
      }
    }
    const auto widths = bireg::half_widths(bireg::pose_covariance(c, t), quantile);
    for (int k = 0; k < G::dof; ++k) {
      const bool degrees = layout[static_cast<std::size_t>(k)].kind == Kind::rotation;
      text += ',';
      bireg::io::append_double(text, degrees ? widths[k] * kDegrees : widths[k]);
    }
    text += '\n';
  }
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (!out) return path + ": cannot write file (" + std::strerror(errno) + ")";
  const bool written = std::fwrite(text.data(), 1, text.size(), out) == text.size();
  errno = 0;
  const bool closed = std::fclose(out) == 0;
  if (!written || !closed) return path + ": write error: " + std::strerror(errno);
  return std::nullopt;
}

}  // namespace bireg_fit_report
