// libFuzzer target: the io/ readers and writers, and fit() on whatever the
// readers accept.
//
// The first byte of the input selects the group (bits 0, 1, 4: SO2, SO3,
// SE2, SE3, Sim3, SL3, GLp3, Heisenberg), the format (bits 2 and 5: matrix,
// tum, euroc, kitti), the solver (bit 3), --project (bit 6) and detection of
// the format from the content (bit 7: the format bits are then ignored); the
// rest is the file's text. Properties checked (abort = finding):
//   * the readers (trajectories and KITTI times) never crash and either
//     report an error with a bounded, printable message and a line number
//     inside the text, or return observations in the group with finite
//     covariates;
//   * what they accept, written back in the format read, reads again to the
//     same number of observations with the same timestamps;
//   * fit() on parsed input never crashes, never returns NaN or infinity
//     in its endpoints, diagnostics (the largest residual angle included)
//     or residuals, and reports invalid input only with
//     a message;
//   * for SO3 and SE3 (the groups bireg_fit computes statistics for) and
//     Sim3: the bi-invariant mean is finite when it succeeds; a defined
//     covariance (both flavours) is finite, symmetric and positive
//     semi-definite with positive degrees of freedom, an undefined one has
//     a message; the trend test (9 permutations) gives a p-value in (0, 1]
//     and a finite, non-negative statistic; motion-model selection (SE3 and
//     Sim3) gives finite criteria and recommends a model whenever one was
//     fitted.
//
// Build and run (clang):
//   cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DBIREG_BUILD_FUZZERS=ON
//   cmake --build build-fuzz --target fuzz_fit
//   ./build-fuzz/tests/fuzz_fit -max_total_time=60 -timeout=10 tests/fuzz/corpus_fuzz_fit
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/io/line_reader.hpp"
#include "bireg/io/writers.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "require.hpp"

namespace {

using bireg_fuzz::require;

std::uint64_t count_lines(const std::string& text) {
  std::uint64_t lines = 1;
  for (char c : text)
    lines += c == '\n';
  return lines;
}

void require_message(const bireg::io::ParseError& error, const std::string& text) {
  require(!error.message.empty());
  require(error.message.size() < 400);
  for (char c : error.message)
    require(c >= 0x20 && c < 0x7f);
  require(error.line <= count_lines(text));
}

// A defined covariance is finite, symmetric and positive semi-definite
// (eigenvalues >= -1e-9 of the largest: rounding of a PSD sandwich).
template <class G>
void check_covariance(const bireg::FitCovariance<G>& c) {
  if (!c.defined()) {
    require(!c.message.empty());
    return;
  }
  const auto& m = c.endpoints;
  require(m.allFinite() && c.residual.allFinite());
  const double scale = m.cwiseAbs().maxCoeff();
  require((m - m.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale + 1e-300);
  using Matrix = std::decay_t<decltype(m)>;
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(m, Eigen::EigenvaluesOnly);
  require(eigen.eigenvalues().minCoeff() >= -1e-9 * scale);
  require(std::isfinite(c.degrees_of_freedom) && c.degrees_of_freedom > 0);
  for (double nu :
       {c.effective.endpoints, c.effective.start, c.effective.end, c.effective.velocity})
    require(std::isfinite(nu) && nu > 0);
}

template <class G>
void exercise_statistics(const bireg::io::Trajectory<G>& trajectory,
                         const bireg::GeodesicRegression<G>& regression,
                         const bireg::RegressionResult<G>& fit) {
  const auto m = bireg::mean<G>(trajectory.observations);
  if (m.ok()) require(m.mean->allFinite());
  if (!fit.ok()) return;
  for (auto flavour : {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust})
    check_covariance(bireg::covariance(fit, trajectory.covariates, {}, flavour));
  bireg::TrendTestOptions options;
  options.permutations = 9;
  options.seed = 1;
  const auto test =
      bireg::trend_test(regression, trajectory.observations, trajectory.covariates, {}, options);
  if (test.ok()) {
    require(test.p_value > 0 && test.p_value <= 1);
    require(std::isfinite(test.statistic) && test.statistic >= 0);
  } else {
    require(!test.message.empty());
  }
  if constexpr (std::is_same_v<G, bireg::SE3<double>> || std::is_same_v<G, bireg::Sim3<double>>) {
    bireg::ModelSelectionOptions selection_options;
    selection_options.folds = 2;
    if (std::is_same_v<G, bireg::Sim3<double>>) selection_options.group = bireg::PoseGroup::sim3;
    const auto selection = bireg::select_motion_model(trajectory.observations,
                                                      trajectory.covariates, selection_options);
    bool any_fitted = false;
    for (const auto& c : selection.candidates) {
      if (!c.fitted) continue;
      any_fitted = true;
      require(std::isfinite(c.criterion) && std::isfinite(c.log_det));
      require(std::isfinite(c.rotation_rms_degrees) && std::isfinite(c.translation_rms) &&
              std::isfinite(c.log_scale_rms));
      if (c.cv_error) require(std::isfinite(*c.cv_error));
    }
    require(any_fitted == selection.recommended.has_value());
    require(selection.recommended.has_value() == selection.prediction.has_value());
  }
}

template <class G>
void exercise(const std::string& text, const bireg::io::ReadOptions& read_options,
              bireg::Solver solver) {
  bireg::io::MemorySource source(text);
  bireg::io::Trajectory<G> trajectory;
  const auto error = bireg::io::read_trajectory<G>(source, read_options, trajectory);
  if (error) {
    require_message(*error, text);
    return;
  }
  require(!trajectory.observations.empty());
  require(trajectory.covariates.size() == trajectory.observations.size());
  require(trajectory.timestamps.size() == trajectory.observations.size());
  for (const auto& g : trajectory.observations)
    require(G::is_element(g, 1e-6));
  for (double c : trajectory.covariates)
    require(std::isfinite(c) && c >= 0);
  require(std::isfinite(trajectory.projection_correction));

  // Written back in the format read (the matrix format for a similarity
  // read from a pose format), the text reads again.
  const bireg::io::Format written_format =
      bireg::io::supports<G>(trajectory.format) ? trajectory.format : bireg::io::Format::matrix;
  const std::string written = bireg::io::format_trajectory<G>(
      written_format, trajectory.format, trajectory.timestamps, trajectory.observations);
  bireg::io::ReadOptions again;
  again.format = written_format;
  if (trajectory.format == bireg::io::Format::kitti) again.times = &trajectory.timestamps;
  bireg::io::MemorySource written_source(written);
  bireg::io::Trajectory<G> reread;
  require(!bireg::io::read_trajectory<G>(written_source, again, reread));
  require(reread.observations.size() == trajectory.observations.size());
  for (std::size_t i = 0; i < reread.timestamps.size() && written_format == trajectory.format;
       ++i) {
    require(reread.timestamps[i].text == trajectory.timestamps[i].text);
    require(reread.covariates[i] == trajectory.covariates[i]);
  }

  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.max_iterations = 50;
  const auto result =
      bireg::GeodesicRegression<G>(options).fit(trajectory.observations, trajectory.covariates);
  if (result.status == bireg::Status::invalid_input) {
    require(!result.message.empty());
    return;
  }
  require(result.geodesic->start().allFinite() && result.geodesic->end().allFinite());
  const auto& d = result.diagnostics;
  for (double x :
       {d.mu_min, d.mu_max, d.step_size, d.contraction_factor, d.force_norm, d.residual_rms,
        d.residual_rms_about_mean, d.explained_variance, d.largest_residual_angle}) {
    require(std::isfinite(x));
  }
  for (const auto& r : result.residuals)
    require(r.allFinite());
  if constexpr (std::is_same_v<G, bireg::SO3<double>> || std::is_same_v<G, bireg::SE3<double>> ||
                std::is_same_v<G, bireg::Sim3<double>>) {
    exercise_statistics(trajectory, bireg::GeodesicRegression<G>(options), result);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t selector = data[0];
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  using bireg::io::Format;
  static constexpr Format kFormats[] = {Format::matrix, Format::tum, Format::euroc, Format::kitti};
  bireg::io::ReadOptions options;
  if (!(selector & 128)) options.format = kFormats[((selector >> 2) & 1) | ((selector >> 4) & 2)];
  options.project = (selector & 64) != 0;
  const auto solver = (selector & 8) ? bireg::Solver::paper : bireg::Solver::gauss_newton;

  // The KITTI times reader sees the same text.
  {
    bireg::io::MemorySource source(text);
    std::vector<bireg::io::Timestamp> times;
    if (const auto error = bireg::io::read_times(source, times)) require_message(*error, text);
  }

  switch ((selector & 3) | ((selector >> 2) & 4)) {  // bits 0, 1 and 4
    case 0:
      exercise<bireg::SO2<double>>(text, options, solver);
      break;
    case 1:
      exercise<bireg::SO3<double>>(text, options, solver);
      break;
    case 2:
      exercise<bireg::SE2<double>>(text, options, solver);
      break;
    case 3:
      exercise<bireg::SE3<double>>(text, options, solver);
      break;
    case 4:
      exercise<bireg::Sim3<double>>(text, options, solver);
      break;
    case 5:
      exercise<bireg::SL3<double>>(text, options, solver);
      break;
    case 6:
      exercise<bireg::GLp<3, double>>(text, options, solver);
      break;
    default:
      exercise<bireg::Heisenberg<double>>(text, options, solver);
      break;
  }
  return 0;
}
