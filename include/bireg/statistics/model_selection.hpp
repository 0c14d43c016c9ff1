// bireg: which motion model does a pose sequence require? DESIGN.md
// section 5, "Which motion does the scene require".
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
// Residuals live in one common space, r_i = log_SE3(P(t_i)^{-1} f_i), and
// S = (1/N) sum r_i r_i^T. The criterion is the Bayesian information
// criterion on the half scale of a negative log-likelihood:
//
//   C = N/2 log det S + k/2 log N,
//
// the Gaussian likelihood with the residuals' full covariance maximised over
// that covariance, plus the BIC penalty. BIC, not AIC: its penalty grows with
// N, so the chosen model converges to the simplest true one (AIC keeps a
// fixed probability of choosing a richer model however long the sequence).
//
// Invariance (Hanik & von Tycowicz, Theorem 2.4). Left translation f -> h f
// (a change of the world frame for camera-to-world poses) moves every
// candidate's prediction to h P(t): the SE(3), SO(3) and Rn<3> fits and both
// means are left equivariant, and p -> R_h p + t_h maps lines to lines and
// means to means. So every r_i, every C, the CV errors and the verdict are
// unchanged. Right translation f -> f h (a change of the body frame) maps the
// static and screw residuals by Ad_{h^{-1}}, so det S changes by
// det(Ad)^2 = 1 and their C is unchanged; the three sub-models are not closed
// under it (a fixed position of the body origin is not a fixed position of
// another body point when the body rotates), so their C, and so possibly
// the verdict, depends on which body point is tracked: exact invariance is
// impossible for them and is not claimed.
//
// Singular S (planar motion, noise-free data): the eigenvalues of every
// candidate's S are floored at kDeterminantFloor times the largest
// eigenvalue of the static model's S (the data's own spread, common to all
// candidates), and at the smallest normal double if the data are all equal.
// A perfect fit then scores 6 N/2 log(floor), the best possible, never -inf
// or NaN.
//
// Recommendation: among the candidates whose C is within kSelectionMargin
// of the best, the one with the fewest parameters (a margin of 1 on this
// half scale is a BIC difference of 2 on the usual scale, the start of
// "positive evidence", Kass & Raftery 1995). When another candidate with the
// same number of parameters is also within the margin (screw vs rotation and
// line at small rotation, rotation only vs translation only at tiny motion),
// `ambiguous` is set and the table says so; the recommended one is then the
// one of smaller C.
//
// Second opinion: K-fold cross-validated prediction error, folds assigned by
// the rank of the covariate (rank mod K; ties broken by the pose's input
// index, so shuffling the input keeps the folds whenever covariates are
// distinct), error = mean of |log(P(t_i)^{-1} f_i)|^2 over held-out i
// (left invariant).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "bireg/geodesic.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/mean.hpp"

namespace bireg {

enum class MotionModel { static_pose, rotation_only, translation_only, rotation_and_line, screw };

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
  }
  return "unknown";
}

inline int parameter_count(MotionModel model) {
  switch (model) {
    case MotionModel::static_pose:
      return 6;
    case MotionModel::rotation_only:
      return 9;
    case MotionModel::translation_only:
      return 9;
    case MotionModel::rotation_and_line:
      return 12;
    case MotionModel::screw:
      return 12;
  }
  return 0;
}

inline constexpr MotionModel kMotionModels[] = {
    MotionModel::static_pose, MotionModel::rotation_only, MotionModel::translation_only,
    MotionModel::rotation_and_line, MotionModel::screw};

// Eigenvalues of S below this times the static model's largest are raised to it.
inline constexpr double kDeterminantFloor = 1e-12;
// Criterion difference within which the simpler model is preferred.
inline constexpr double kSelectionMargin = 1.0;

struct ModelSelectionOptions {
  int folds = 5;  // K of the cross-validation; below 2: no cross-validation
};

struct CandidateReport {
  MotionModel model = MotionModel::static_pose;
  int parameters = 0;
  bool fitted = false;  // false: excluded, `note` says why
  std::string note;
  double rotation_rms_degrees = 0;  // RMS of |omega part of r_i|
  double translation_rms = 0;       // RMS of |rho part of r_i|, data units
  double log_det = 0;               // log det S with the eigenvalue floor
  double criterion = 0;             // N/2 log det S + k/2 log N
  std::optional<double> cv_error;   // mean held-out |r|^2; empty if a fold failed
  bool within_margin = false;       // C <= best C + kSelectionMargin
  bool recommended = false;
};

struct ModelSelection {
  std::vector<CandidateReport> candidates;  // in the order of kMotionModels
  std::optional<MotionModel> recommended;   // empty if no candidate could be fitted
  bool ambiguous = false;  // another model of equal complexity is within the margin
  std::string message;
};

namespace model_selection_detail {

using Pose = Eigen::Matrix4d;
using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

// A fitted candidate: its prediction at any covariate.
struct Predictor {
  MotionModel model = MotionModel::static_pose;
  std::optional<Geodesic<SO3d>> rotation_path;
  std::optional<Geodesic<Rnd<3>>> position_path;
  std::optional<Geodesic<SE3d>> screw_path;
  Matrix3 fixed_rotation = Matrix3::Identity();
  Vector3 fixed_position = Vector3::Zero();
  Pose fixed_pose = Pose::Identity();

  Pose operator()(double t) const {
    if (model == MotionModel::static_pose) return fixed_pose;
    if (model == MotionModel::screw) return (*screw_path)(t);
    Pose p = Pose::Identity();
    p.topLeftCorner<3, 3>() = rotation_path ? (*rotation_path)(t) : fixed_rotation;
    p.topRightCorner<3, 1>() = position_path ? (*position_path)(t) : fixed_position;
    return p;
  }
};

template <class Poses>
std::optional<Predictor> fit_model(MotionModel model, const Poses& poses,
                                   const std::vector<double>& times) {
  Predictor predictor;
  predictor.model = model;
  const std::size_t n = poses.size();
  std::vector<Matrix3> rotations(n);
  std::vector<Vector3> positions(n);
  for (std::size_t i = 0; i < n; ++i) {
    rotations[i] = poses[i].template topLeftCorner<3, 3>();
    positions[i] = poses[i].template topRightCorner<3, 1>();
  }
  const bool moving_rotation =
      model == MotionModel::rotation_only || model == MotionModel::rotation_and_line;
  const bool moving_position =
      model == MotionModel::translation_only || model == MotionModel::rotation_and_line;
  if (model == MotionModel::static_pose) {
    const auto m = mean<SE3d>(poses);
    if (!m.ok()) return std::nullopt;
    predictor.fixed_pose = *m.mean;
    return predictor;
  }
  if (model == MotionModel::screw) {
    const auto fit = GeodesicRegression<SE3d>().fit(poses, times);
    if (!fit.ok()) return std::nullopt;
    predictor.screw_path = fit.geodesic;
    return predictor;
  }
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

inline SE3d::Tangent residual(const Predictor& predictor, const Pose& pose, double t) {
  return SE3d::log(SE3d::compose(SE3d::inverse(predictor(t)), pose));
}

// Fold of observation i: rank of (t_i, i) modulo K.
inline std::vector<int> fold_of(const std::vector<double>& times, int folds) {
  std::vector<std::size_t> order(times.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return times[a] < times[b]; });
  std::vector<int> fold(times.size());
  for (std::size_t rank = 0; rank < order.size(); ++rank)
    fold[order[rank]] = static_cast<int>(rank % static_cast<std::size_t>(folds));
  return fold;
}

template <class Poses>
std::optional<double> cv_error(MotionModel model, const Poses& poses,
                               const std::vector<double>& times, int folds) {
  const std::vector<int> fold = fold_of(times, folds);
  double squared_sum = 0;
  for (int k = 0; k < folds; ++k) {
    std::vector<Pose> train_poses;
    std::vector<double> train_times;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (fold[i] == k) continue;
      train_poses.push_back(poses[i]);
      train_times.push_back(times[i]);
    }
    const auto predictor = fit_model(model, train_poses, train_times);
    if (!predictor) return std::nullopt;
    for (std::size_t i = 0; i < poses.size(); ++i)
      if (fold[i] == k) squared_sum += residual(*predictor, poses[i], times[i]).squaredNorm();
  }
  return squared_sum / static_cast<double>(poses.size());
}

inline Eigen::Matrix<double, 6, 6> residual_covariance(const std::vector<SE3d::Tangent>& r) {
  Eigen::Matrix<double, 6, 6> s = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& ri : r)
    s += ri * ri.transpose();
  return s / static_cast<double>(r.size());
}

inline double floored_log_det(const Eigen::Matrix<double, 6, 6>& s, double floor) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(s, Eigen::EigenvaluesOnly);
  double log_det = 0;
  for (int j = 0; j < 6; ++j)
    log_det += std::log(std::max(eigen.eigenvalues()[j], floor));
  return log_det;
}

}  // namespace model_selection_detail

// One candidate fitted alone: its prediction P(t) at any covariate (what
// bireg_fit --group auto writes for the recommended model), or nothing if
// its fit failed.
using MotionPrediction = model_selection_detail::Predictor;
template <class Poses>
std::optional<MotionPrediction> fit_motion_model(MotionModel model, const Poses& poses,
                                                 const std::vector<double>& times) {
  return model_selection_detail::fit_model(model, poses, times);
}

// Compare the five pose-motion models on `poses` (indexable 4x4 SE(3)
// matrices with size()) at covariates `times`. Never throws for bad data,
// never returns NaN: a model that cannot be fitted (N below its parameter
// count, a failed fit) is excluded with a note.
template <class Poses>
ModelSelection select_motion_model(const Poses& poses, const std::vector<double>& times,
                                   const ModelSelectionOptions& options = {}) {
  namespace detail = model_selection_detail;
  ModelSelection selection;
  const std::size_t n = poses.size();
  if (n != times.size() || n == 0) {
    selection.message = "poses and times must be non-empty and of equal length";
    return selection;
  }
  const double n_real = static_cast<double>(n);
  const double rad_to_deg = 180.0 / 3.14159265358979323846;

  std::vector<std::optional<detail::Predictor>> predictors;
  std::vector<std::vector<SE3d::Tangent>> residuals;
  for (MotionModel model : kMotionModels) {
    CandidateReport report;
    report.model = model;
    report.parameters = parameter_count(model);
    std::optional<detail::Predictor> predictor;
    if (n_real < report.parameters) {
      report.note = "excluded: " + std::to_string(n) + " observations, fewer than its " +
                    std::to_string(report.parameters) + " parameters";
    } else {
      predictor = detail::fit_model(model, poses, times);
      if (!predictor) report.note = "excluded: its fit failed";
    }
    std::vector<SE3d::Tangent> r;
    if (predictor) {
      report.fitted = true;
      for (std::size_t i = 0; i < n; ++i)
        r.push_back(detail::residual(*predictor, poses[i], times[i]));
    }
    predictors.push_back(predictor);
    residuals.push_back(r);
    selection.candidates.push_back(report);
  }

  // The floor's reference: the largest eigenvalue of the static model's S
  // (computed directly if static itself was excluded).
  std::vector<SE3d::Tangent> spread = residuals.front();
  if (spread.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      spread.push_back(SE3d::log(SE3d::compose(SE3d::inverse(poses[n / 2]), poses[i])));
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> spread_eigen(
      detail::residual_covariance(spread), Eigen::EigenvaluesOnly);
  const double largest_spread = spread_eigen.eigenvalues()[5];
  const double floor =
      std::max(kDeterminantFloor * largest_spread, std::numeric_limits<double>::min());

  std::optional<double> best;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    CandidateReport& report = selection.candidates[c];
    if (!report.fitted) continue;
    double rotation_squares = 0, translation_squares = 0;
    for (const auto& ri : residuals[c]) {
      translation_squares += ri.head<3>().squaredNorm();
      rotation_squares += ri.tail<3>().squaredNorm();
    }
    report.rotation_rms_degrees = std::sqrt(rotation_squares / n_real) * rad_to_deg;
    report.translation_rms = std::sqrt(translation_squares / n_real);
    report.log_det = detail::floored_log_det(detail::residual_covariance(residuals[c]), floor);
    report.criterion = n_real / 2 * report.log_det + report.parameters / 2.0 * std::log(n_real);
    if (options.folds >= 2 && n >= static_cast<std::size_t>(options.folds))
      report.cv_error = detail::cv_error(report.model, poses, times, options.folds);
    if (!best || report.criterion < *best) best = report.criterion;
  }
  if (!best) {
    selection.message = "no candidate could be fitted";
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
  CandidateReport& winner = selection.candidates[*chosen];
  winner.recommended = true;
  selection.recommended = winner.model;
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

}  // namespace bireg
