// libFuzzer target: model selection on hostile data sets (fuzz_data.hpp)
// and options -- select_motion_model and fit_motion_model on SE(3) poses
// (as rigid motions or as similarities), select_static_or_geodesic, and
// select_curve on the poses' rotations with any knot spacings; any fold
// count, thread count, pose group and motion model (values outside the
// enumerations included).
//
// Properties checked (abort = finding), whatever the input
// (docs/hostile_input.md):
//   * a selection that is not ok says why; one that is ok recommends a
//     fitted candidate, and every fitted candidate's numbers are finite;
//   * the recommended curve (the motion model's prediction, the static
//     element or the geodesic) is finite at every finite covariate of the
//     data;
//   * fit_motion_model's prediction, when there is one, likewise.
//
// Build and run (clang): see fuzz_fit.cpp, target fuzz_model_selection,
// corpus tests/fuzz/corpus_fuzz_model_selection.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>
#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/selection/curve_selection.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "fuzz_data.hpp"

namespace {

using bireg_fuzz::number;
using bireg_fuzz::require;
using bireg_fuzz::require_message;

void check_prediction(const bireg::MotionPrediction& prediction, const std::vector<double>& t) {
  for (const double s : t)
    if (std::isfinite(s)) require(prediction(s).allFinite());
}

void exercise_motion_models(const std::vector<Eigen::Matrix4d>& poses, const std::vector<double>& t,
                            const bireg::ModelSelectionOptions& options, bireg::MotionModel model) {
  const auto selection = bireg::select_motion_model(poses, t, options);
  if (selection.ok()) {
    require(selection.recommended && selection.prediction);
    bool recommended_fitted = false;
    for (const auto& c : selection.candidates) {
      if (!c.fitted) continue;
      require(std::isfinite(c.criterion) && std::isfinite(c.log_det));
      require(std::isfinite(c.rotation_rms_degrees) && std::isfinite(c.translation_rms) &&
              std::isfinite(c.log_scale_rms));
      if (c.cv_error) require(std::isfinite(*c.cv_error));
      recommended_fitted = recommended_fitted || c.model == *selection.recommended;
    }
    require(recommended_fitted);
    check_prediction(*selection.prediction, t);
  } else {
    require_message(selection.message);
    require(!selection.recommended && !selection.prediction);
  }
  if (const auto prediction = bireg::fit_motion_model(model, poses, t, options.group))
    check_prediction(*prediction, t);
}

template <class G>
void exercise_trend(const std::vector<typename G::Element>& f, const std::vector<double>& t,
                    const bireg::ModelSelectionOptions& options) {
  const auto selection = bireg::select_static_or_geodesic<G>(f, t, options);
  if (!selection.ok()) {
    require_message(selection.message);
    return;
  }
  for (const auto& c : selection.candidates)
    if (c.fitted) require(std::isfinite(c.criterion));
  if (selection.static_element) require(selection.static_element->allFinite());
  if (selection.geodesic) {
    for (const double s : t)
      if (std::isfinite(s)) require((*selection.geodesic)(s).allFinite());
  }
}

void exercise_curves(const std::vector<bireg::SO3d::Element>& rotations,
                     const std::vector<double>& t, FuzzedDataProvider& in) {
  bireg::CurveSelectionOptions options;
  for (int k = in.ConsumeIntegralInRange(0, 2); k > 0; --k)
    options.knot_spacings.push_back(number(in, 5.0));
  const auto selection = bireg::select_curve<bireg::SO3d>(rotations, t, options);
  if (!selection.ok()) {
    require_message(selection.message);
    return;
  }
  require(selection.recommended && *selection.recommended < selection.candidates.size());
  require(selection.candidates[*selection.recommended].fitted);
  for (const auto& c : selection.candidates) {
    if (!c.fitted) continue;
    require(std::isfinite(c.criterion) && std::isfinite(c.residual_rms) &&
            std::isfinite(c.log_det));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const auto poses = bireg_fuzz::data_set<bireg::SE3d>(in, 24);
  const auto& t = poses.covariates;

  bireg::ModelSelectionOptions options;
  options.folds = in.ConsumeIntegralInRange(-1, 3);
  options.threads = in.ConsumeIntegralInRange(0, 2);
  // se3, sim3, or a value outside the enumeration.
  options.group = static_cast<bireg::PoseGroup>(in.ConsumeIntegralInRange(0, 2));
  const auto model = static_cast<bireg::MotionModel>(in.ConsumeIntegralInRange(0, 6));

  exercise_motion_models(poses.observations, t, options, model);
  exercise_trend<bireg::SE3d>(poses.observations, t, options);
  if (in.ConsumeBool()) {
    std::vector<bireg::SO3d::Element> rotations;
    for (const auto& g : poses.observations)
      rotations.push_back(g.topLeftCorner<3, 3>());
    exercise_curves(rotations, t, in);
  }
  return 0;
}
