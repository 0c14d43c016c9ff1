// bireg: which motion model does a pose sequence require? DESIGN.md
// section 5, "Which motion does the scene require". The criterion, its
// floor and margin, the refusals and the cross-validation are
// selection/criteria.hpp's.
//
// Candidates for poses f_i = [R_i p_i; 0 1] (4x4, SE(3)), each predicting a
// full pose P(t) at every covariate, with its number of parameters k:
//
//   static            P(t) = m, the bi-invariant mean of the f_i             k = 6
//   rotation_only     P(t) = (R(t), p_bar): R the SO(3) geodesic fit of the
//                     R_i, p_bar the mean of the p_i                          k = 9
//   translation_only  P(t) = (R_bar, p(t)): R_bar the SO(3) mean of the R_i,
//                     p the least-squares line (the Rn<3> fit) of the p_i     k = 9
//   rotation_and_line P(t) = (R(t), p(t)): the Product<SO3, Rn<3>> geodesic,
//                     whose estimating equations decouple into the SO(3) and
//                     the Rn<3> fit above                                     k = 12
//   screw             P(t) = the SE(3) geodesic fit (Definition 2.1)          k = 12
//
// Similarities f_i = [s_i R_i p_i; 0 1] (Sim(3), a monocular reconstruction
// whose scale may drift; ModelSelectionOptions::group = PoseGroup::sim3):
// the five models above fitted to the rigid parts (R_i, p_i), each with a
// constant scale s_bar = exp(mean log s_i) (one parameter more:
// P(t) = rigid P(t) times the dilation diag(s_bar I, 1) on the right, which
// scales the rotation block and keeps the positions), static being the
// Sim(3) mean (k = 7), and a sixth candidate,
//
//   similarity        P(t) = the Sim(3) geodesic fit                          k = 14
//
// the screw with a steadily changing scale. Each constant-scale model is a
// Sim(3) model nested in `similarity` or in another (a geodesic times a
// constant element is a geodesic whose log-scale velocity is zero).
//
//
// Invariance (Hanik & von Tycowicz, Theorem 2.4). Left translation f -> h f
// (a change of the world frame for camera-to-world poses) moves every
// candidate's prediction to h P(t): the geodesic fits and means are left
// equivariant, p -> R_h p + t_h (Sim(3): s_h R_h p + t_h) maps lines to
// lines and means to means, and the SE(3) fit of the rigid parts commutes
// with the scaling of translations (an automorphism of SE(3), which commutes
// with exp, log and their differentials). So every r_i, every C, the CV
// errors and the verdict are unchanged. Right translation f -> f h (a change
// of the body frame) maps the residuals of the models closed under it
// (static and screw; for Sim(3) data static and similarity) by Ad_{h^{-1}}:
// det Ad = 1 in SE(3), so their C is unchanged; det Ad_{h^{-1}} = s_h^{-3} in
// Sim(3), so both of their criteria shift by the same -3 N log s_h and their
// comparison is unchanged. The other sub-models are not closed under it (a
// fixed position of the body origin is not a fixed position of another
// body point when the body rotates), so their C, and so possibly the
// verdict, depends on which body point is tracked: exact invariance is
// impossible for them and is not claimed.
//
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/selection/criteria.hpp"

namespace bireg {

enum class MotionModel {
  static_pose,
  rotation_only,
  translation_only,
  rotation_and_line,
  screw,
  similarity
};

inline const char* to_string(MotionModel model) {
  switch (model) {
    case MotionModel::static_pose:
      return "static";
    case MotionModel::rotation_only:
      return "rotation_only";
    case MotionModel::translation_only:
      return "translation_only";
    case MotionModel::rotation_and_line:
      return "rotation_and_line";
    case MotionModel::screw:
      return "screw";
    case MotionModel::similarity:
      return "similarity";
  }
  return "unknown";
}

// k of the criterion: for Sim(3) data every model but `similarity` has one
// parameter more than for SE(3) data (its constant scale).
inline int parameter_count(MotionModel model, PoseGroup group = PoseGroup::se3) {
  const int constant_scale = group == PoseGroup::sim3 ? 1 : 0;
  switch (model) {
    case MotionModel::static_pose:
      return 6 + constant_scale;
    case MotionModel::rotation_only:
    case MotionModel::translation_only:
      return 9 + constant_scale;
    case MotionModel::rotation_and_line:
    case MotionModel::screw:
      return 12 + constant_scale;
    case MotionModel::similarity:
      return 14;
  }
  return 0;
}

// The candidates for SE(3) data, and for Sim(3) data.
inline constexpr MotionModel kMotionModels[] = {
    MotionModel::static_pose, MotionModel::rotation_only, MotionModel::translation_only,
    MotionModel::rotation_and_line, MotionModel::screw};
inline constexpr MotionModel kSimilarityMotionModels[] = {
    MotionModel::static_pose,       MotionModel::rotation_only, MotionModel::translation_only,
    MotionModel::rotation_and_line, MotionModel::screw,         MotionModel::similarity};

struct CandidateReport {
  MotionModel model = MotionModel::static_pose;
  int parameters = 0;
  bool fitted = false;  // false: excluded, `note` says why
  std::string note;
  double rotation_rms_degrees = 0;  // RMS of |omega part of r_i|
  double translation_rms = 0;       // RMS of |rho part of r_i|, data units
  double log_scale_rms = 0;         // Sim(3) data: RMS of the log-scale part of r_i; else 0
  double log_det = 0;               // log det S with the eigenvalue floor
  double criterion = 0;             // N/2 log det S + k/2 log N
  std::optional<double> cv_error;   // mean held-out |r|^2; empty if a fold failed
  bool within_margin = false;       // C <= best C + kSelectionMargin
  bool recommended = false;
};

// A fitted candidate: its prediction P(t), a 4x4 SE(3) (or, for Sim(3)
// data, Sim(3)) matrix, at any covariate.
struct MotionPrediction {
  MotionModel model = MotionModel::static_pose;
  std::optional<Geodesic<SO3d>> rotation_path;
  std::optional<Geodesic<Rnd<3>>> position_path;
  std::optional<Geodesic<SE3d>> screw_path;
  std::optional<Geodesic<Sim3d>> similarity_path;
  Eigen::Matrix3d fixed_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d fixed_position = Eigen::Vector3d::Zero();
  Eigen::Matrix4d fixed_pose = Eigen::Matrix4d::Identity();
  double scale = 1;  // the constant scale s_bar of a rigid model on Sim(3) data

  Eigen::Matrix4d operator()(double t) const {
    if (model == MotionModel::static_pose) return fixed_pose;
    if (model == MotionModel::similarity) return (*similarity_path)(t);
    Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
    if (model == MotionModel::screw) {
      p = (*screw_path)(t);
    } else {
      p.topLeftCorner<3, 3>() = rotation_path ? (*rotation_path)(t) : fixed_rotation;
      p.topRightCorner<3, 1>() = position_path ? (*position_path)(t) : fixed_position;
    }
    if (scale != 1) p.topLeftCorner<3, 3>() *= scale;
    return p;
  }
};

struct ModelSelection {
  SelectionStatus status = SelectionStatus::invalid_input;
  std::ptrdiff_t bad_index = -1;               // invalid_input: the observation at fault, or -1
  std::vector<CandidateReport> candidates;     // in the order of kMotionModels (or kSimilarity...)
  std::optional<MotionModel> recommended;      // empty unless status is selected
  std::optional<MotionPrediction> prediction;  // the recommended model's fit
  bool ambiguous = false;  // another model of equal complexity is within the margin
  std::string message;

  bool ok() const { return status == SelectionStatus::selected; }
};

namespace model_selection_detail {

using Pose = Eigen::Matrix4d;
using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

// The residuals' group for poses of `group`.
template <PoseGroup group>
using Ambient = std::conditional_t<group == PoseGroup::sim3, Sim3d, SE3d>;

constexpr bool is_valid(MotionModel model) {
  return model == MotionModel::static_pose || model == MotionModel::rotation_only ||
         model == MotionModel::translation_only || model == MotionModel::rotation_and_line ||
         model == MotionModel::screw || model == MotionModel::similarity;
}

template <PoseGroup group, class Poses>
std::optional<MotionPrediction> fit_model(MotionModel model, const Poses& poses,
                                          const std::vector<double>& times) {
  using G = Ambient<group>;
  MotionPrediction predictor;
  predictor.model = model;
  const std::size_t n = poses.size();
  if (!is_valid(model)) return std::nullopt;
  if (model == MotionModel::static_pose) {
    const auto m = mean<G>(poses);
    if (!m.ok()) return std::nullopt;
    predictor.fixed_pose = *m.mean;
    return predictor;
  }
  if (model == MotionModel::similarity) {
    if constexpr (group == PoseGroup::sim3) {
      const auto fit = GeodesicRegression<Sim3d>().fit(poses, times);
      if (!fit.ok()) return std::nullopt;
      predictor.similarity_path = fit.geodesic;
      return predictor;
    } else {
      return std::nullopt;  // SE(3) data have no scale to move
    }
  }
  // The rigid parts (R_i, p_i); for similarities s_i = det(s_i R_i)^(1/3).
  std::vector<Pose> rigid(n);
  for (std::size_t i = 0; i < n; ++i)
    rigid[i] = poses[i];
  if constexpr (group == PoseGroup::sim3) {
    double log_scale_sum = 0;
    for (Pose& f : rigid) {
      const double log_scale = std::log(f.topLeftCorner<3, 3>().determinant()) / 3;
      f.topLeftCorner<3, 3>() *= std::exp(-log_scale);
      log_scale_sum += log_scale;
    }
    predictor.scale = std::exp(log_scale_sum / static_cast<double>(n));
  }
  if (model == MotionModel::screw) {
    const auto fit = GeodesicRegression<SE3d>().fit(rigid, times);
    if (!fit.ok()) return std::nullopt;
    predictor.screw_path = fit.geodesic;
    return predictor;
  }
  std::vector<Matrix3> rotations(n);
  std::vector<Vector3> positions(n);
  for (std::size_t i = 0; i < n; ++i) {
    rotations[i] = rigid[i].template topLeftCorner<3, 3>();
    positions[i] = rigid[i].template topRightCorner<3, 1>();
  }
  const bool moving_rotation =
      model == MotionModel::rotation_only || model == MotionModel::rotation_and_line;
  const bool moving_position =
      model == MotionModel::translation_only || model == MotionModel::rotation_and_line;
  if (moving_rotation) {
    const auto fit = GeodesicRegression<SO3d>().fit(rotations, times);
    if (!fit.ok()) return std::nullopt;
    predictor.rotation_path = fit.geodesic;
  } else {
    const auto m = mean<SO3d>(rotations);
    if (!m.ok()) return std::nullopt;
    predictor.fixed_rotation = *m.mean;
  }
  if (moving_position) {
    const auto fit = GeodesicRegression<Rnd<3>>().fit(positions, times);
    if (!fit.ok()) return std::nullopt;
    predictor.position_path = fit.geodesic;
  } else {
    const Vector3 position_sum =
        std::accumulate(positions.begin(), positions.end(), Vector3(Vector3::Zero()));
    predictor.fixed_position = position_sum / static_cast<double>(n);
  }
  return predictor;
}

template <PoseGroup group>
typename Ambient<group>::Tangent residual(const MotionPrediction& predictor, const Pose& pose,
                                          double t) {
  using G = Ambient<group>;
  return G::log(G::compose(G::inverse(predictor(t)), pose));
}

template <PoseGroup group, class Poses>
ModelSelection select(const Poses& poses, const std::vector<double>& times,
                      const ModelSelectionOptions& options) {
  using G = Ambient<group>;
  using Tangent = typename G::Tangent;
  ModelSelection selection;
  const std::size_t n = poses.size();
  if (auto rejection = check_input<G>(poses, times, options.threads)) {
    selection.message = rejection->message;
    selection.bad_index = rejection->index;
    return selection;
  }
  const double n_real = static_cast<double>(n);
  const double rad_to_deg = 180.0 / 3.14159265358979323846;

  std::vector<MotionModel> models(std::begin(kMotionModels), std::end(kMotionModels));
  if (group == PoseGroup::sim3) models.push_back(MotionModel::similarity);
  std::vector<std::optional<MotionPrediction>> predictors(models.size());
  std::vector<std::vector<Tangent>> residuals(models.size());
  selection.candidates.resize(models.size());
  // The candidates' fits, then the folds': at most that many tasks at once.
  const std::size_t fold_tasks =
      models.size() * static_cast<std::size_t>(std::max(options.folds, 1));
  ChunkPool pool(options.threads, std::max(models.size(), fold_tasks));
  pool.run(models.size(), [&](std::size_t c) {
    CandidateReport& report = selection.candidates[c];
    report.model = models[c];
    report.parameters = parameter_count(report.model, group);
    std::optional<MotionPrediction>& predictor = predictors[c];
    if (n_real < report.parameters) {
      report.note = "excluded: " + std::to_string(n) + " observations, fewer than its " +
                    std::to_string(report.parameters) + " parameters";
    } else {
      predictor = fit_model<group>(report.model, poses, times);
      if (!predictor) report.note = "excluded: its fit failed";
    }
    if (predictor) {
      report.fitted = true;
      residuals[c].reserve(n);
      for (std::size_t i = 0; i < n; ++i)
        residuals[c].push_back(residual<group>(*predictor, poses[i], times[i]));
    }
  });

  const double floor = determinant_floor<G>(residuals.front(), poses);

  std::optional<double> best;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    CandidateReport& report = selection.candidates[c];
    if (!report.fitted) continue;
    double rotation_squares = 0, translation_squares = 0, scale_squares = 0;
    for (const auto& ri : residuals[c]) {
      translation_squares += ri.template head<3>().squaredNorm();
      rotation_squares += ri.template segment<3>(3).squaredNorm();
      if constexpr (group == PoseGroup::sim3) scale_squares += ri[6] * ri[6];
    }
    const double rotation_rms_degrees = std::sqrt(rotation_squares / n_real) * rad_to_deg;
    const double translation_rms = std::sqrt(translation_squares / n_real);
    const double log_scale_rms = std::sqrt(scale_squares / n_real);
    const double log_det = floored_log_det(residual_covariance(residuals[c]), floor);
    const double criterion = n_real / 2 * log_det + report.parameters / 2.0 * std::log(n_real);
    // Squares of residuals beyond ~1e154 overflow: such a candidate cannot
    // be scored (a NaN or infinite criterion would compare with nothing).
    const bool finite = std::isfinite(floor) && std::isfinite(rotation_squares) &&
                        std::isfinite(translation_squares) && std::isfinite(scale_squares) &&
                        std::isfinite(criterion);
    if (!finite) {
      report.fitted = false;
      report.note = "excluded: its residuals' squares overflow (criterion not finite)";
      predictors[c].reset();
      continue;
    }
    report.rotation_rms_degrees = rotation_rms_degrees;
    report.translation_rms = translation_rms;
    report.log_scale_rms = log_scale_rms;
    report.log_det = log_det;
    report.criterion = criterion;
    if (!best || report.criterion < *best) best = report.criterion;
  }
  if (options.folds >= 2 && n >= static_cast<std::size_t>(options.folds)) {
    const std::vector<std::optional<double>> errors = cv_errors<Pose>(
        poses, times, options.folds, models.size(),
        [&](std::size_t c) { return selection.candidates[c].fitted; },
        [&](std::size_t c, const std::vector<Pose>& train, const std::vector<double>& train_times) {
          return fit_model<group>(models[c], train, train_times);
        },
        residual<group>, pool);
    for (std::size_t c = 0; c < models.size(); ++c)
      selection.candidates[c].cv_error = errors[c];
  }
  if (!best) {
    selection.status = SelectionStatus::no_candidate;
    selection.message = "no candidate could be fitted and scored (see each candidate's note)";
    return selection;
  }

  std::optional<std::size_t> chosen;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    CandidateReport& report = selection.candidates[c];
    if (!report.fitted) continue;
    report.within_margin = report.criterion <= *best + kSelectionMargin;
    if (!report.within_margin) continue;
    const bool simpler = !chosen || report.parameters < selection.candidates[*chosen].parameters;
    const bool equal_but_better = chosen &&
                                  report.parameters == selection.candidates[*chosen].parameters &&
                                  report.criterion < selection.candidates[*chosen].criterion;
    if (simpler || equal_but_better) chosen = c;
  }
  if (!chosen) {  // unreachable: the best finite criterion is within the margin of itself
    selection.status = SelectionStatus::no_candidate;
    selection.message = "no candidate's criterion is within the margin of the best";
    return selection;
  }
  selection.status = SelectionStatus::selected;
  CandidateReport& winner = selection.candidates[*chosen];
  winner.recommended = true;
  selection.recommended = winner.model;
  selection.prediction = predictors[*chosen];
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    const CandidateReport& other = selection.candidates[c];
    if (c != *chosen && other.within_margin && other.parameters == winner.parameters) {
      selection.ambiguous = true;
      selection.message = std::string(to_string(winner.model)) + " and " + to_string(other.model) +
                          " cannot be told apart by these data (criteria within the margin)";
    }
  }
  return selection;
}

}  // namespace model_selection_detail

// One candidate fitted alone: its prediction P(t) at any covariate, or
// nothing if its fit failed, the input is refused (as select_motion_model
// refuses it: a pose that is not an element of `group`, a covariate that
// is not finite, ...; an unknown model or group) or `model` is
// `similarity` and the poses are SE(3).
template <class Poses>
std::optional<MotionPrediction> fit_motion_model(MotionModel model, const Poses& poses,
                                                 const std::vector<double>& times,
                                                 PoseGroup group = PoseGroup::se3) {
  namespace detail = model_selection_detail;
  if (!is_valid(group) || !detail::is_valid(model)) return std::nullopt;
  if (group == PoseGroup::sim3) {
    if (detail::check_input<Sim3d>(poses, times, 1)) return std::nullopt;
    return detail::fit_model<PoseGroup::sim3>(model, poses, times);
  }
  if (detail::check_input<SE3d>(poses, times, 1)) return std::nullopt;
  return detail::fit_model<PoseGroup::se3>(model, poses, times);
}

// The same with covariates in any indexable container with size().
template <class Poses, class Times,
          std::enable_if_t<model_selection_detail::kOtherTimes<Times>, int> = 0>
std::optional<MotionPrediction> fit_motion_model(MotionModel model, const Poses& poses,
                                                 const Times& times,
                                                 PoseGroup group = PoseGroup::se3) {
  return fit_motion_model(model, poses, model_selection_detail::as_doubles(times), group);
}

// Compare the pose-motion models on `poses` (indexable 4x4 matrices with
// size(): SE(3) elements, or Sim(3) ones with options.group = sim3) at
// covariates `times`: the five rigid candidates, and for similarities the
// sixth, `similarity`. Never throws for bad data, never returns NaN:
// refused input (see "Refusals and statuses" above) has status
// invalid_input, naming the observation; a model that cannot be fitted or
// scored (N below its parameter count, a failed fit, an overflowing
// criterion) is excluded with a note; with none left the status is
// no_candidate. The recommended model's fit is returned with the table
// (`prediction`), so the caller need not refit it.
template <class Poses>
ModelSelection select_motion_model(const Poses& poses, const std::vector<double>& times,
                                   const ModelSelectionOptions& options = {}) {
  namespace detail = model_selection_detail;
  if (!is_valid(options.group)) {
    ModelSelection refused;
    refused.message = "options.group must be se3 or sim3 (got " +
                      std::to_string(static_cast<int>(options.group)) + ")";
    return refused;
  }
  if (options.group == PoseGroup::sim3)
    return detail::select<PoseGroup::sim3>(poses, times, options);
  return detail::select<PoseGroup::se3>(poses, times, options);
}

// The same with covariates in any indexable container with size()
// (std::array, std::deque, Eigen::VectorXd, ...), read as doubles.
template <class Poses, class Times,
          std::enable_if_t<model_selection_detail::kOtherTimes<Times>, int> = 0>
ModelSelection select_motion_model(const Poses& poses, const Times& times,
                                   const ModelSelectionOptions& options = {}) {
  return select_motion_model(poses, model_selection_detail::as_doubles(times), options);
}

}  // namespace bireg
