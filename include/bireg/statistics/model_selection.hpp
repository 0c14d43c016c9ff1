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
// Data of any group G (orientations: SO(3)): does the element move along
// the covariate at all? select_static_or_geodesic compares
//
//   static            P(t) = m, the bi-invariant mean                          k = d
//   geodesic          P(t) = the geodesic fit                                  k = 2d
//
// (d = G::dof) with residuals log(P(t_i)^{-1} f_i) in G, and the same
// criterion, eigenvalue floor, margin and cross-validation as below. Both
// candidates are left and right equivariant (Theorem 2.4), so the criteria
// are left invariant, and right invariant where det Ad = 1 (SO(3), SE(3):
// every group whose Ad is orthogonal or unimodular).
//
// Residuals live in one common space, r_i = log(P(t_i)^{-1} f_i) in SE(3)
// (d = 6) or Sim(3) (d = 7), and S = (1/N) sum r_i r_i^T. The criterion is
// the Bayesian information criterion on the half scale of a negative
// log-likelihood:
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
// Singular S (planar motion, noise-free data): the eigenvalues of every
// candidate's S are floored at kDeterminantFloor times the largest
// eigenvalue of the static model's S (the data's own spread, common to all
// candidates), and at the smallest normal double if the data are all equal.
// A perfect fit then scores d N/2 log(floor), the best possible, never -inf
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
// Refusals and statuses. Before any work the input is checked: equal,
// non-empty lengths; every covariate finite and within half the largest
// double (so that any difference of two covariates is finite); every pose
// finite and an element of its group (SE(3): a rotation block and the last
// row (0, 0, 0, 1); Sim(3): a similarity block); the enumerations known.
// A refusal has status invalid_input, a message and bad_index naming the
// observation (or covariate) at fault. A candidate whose criterion or
// RMS is not finite (residuals whose squares overflow: translations near
// 1e154 or beyond) is excluded with a note, like one whose fit failed; if
// no candidate is left the status is no_candidate and nothing is
// recommended. Nothing in a result is NaN.
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
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "bireg/geodesic.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/mean.hpp"

namespace bireg {

enum class MotionModel {
  static_pose,
  rotation_only,
  translation_only,
  rotation_and_line,
  screw,
  similarity
};

// The group the poses are elements of, and the residuals' space.
enum class PoseGroup { se3, sim3 };

constexpr bool is_valid(PoseGroup group) {
  return group == PoseGroup::se3 || group == PoseGroup::sim3;
}

// How a selection ended.
enum class SelectionStatus {
  selected,       // a model is recommended
  invalid_input,  // refused before any work: message and bad_index say why
  no_candidate,   // no candidate could be fitted and scored: message says why
};

inline const char* to_string(SelectionStatus status) {
  switch (status) {
    case SelectionStatus::selected:
      return "selected";
    case SelectionStatus::invalid_input:
      return "invalid_input";
    case SelectionStatus::no_candidate:
      return "no_candidate";
  }
  return "unknown";
}

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

// Eigenvalues of S below this times the static model's largest are raised to it.
inline constexpr double kDeterminantFloor = 1e-12;
// Criterion difference within which the simpler model is preferred.
inline constexpr double kSelectionMargin = 1.0;

struct ModelSelectionOptions {
  int folds = 5;                     // K of the cross-validation; below 2: no cross-validation
  PoseGroup group = PoseGroup::se3;  // sim3: similarities, six candidates
  // Threads (>= 1) for the candidates' fits and the cross-validation's
  // (candidate, fold) fits, each fit serial. The result does not depend on
  // it: every task writes its own slot, and the folds' sums are added in
  // fold order. A std::bad_alloc on a worker terminates.
  int threads = 1;
};

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

// Lengths and covariates: equal, non-empty lengths, and every covariate
// finite with |t| <= max/2, so that t_i - t_j never overflows (the range,
// the centring below, the fits' map onto [0, 1]). The first covariate at
// fault is named.
template <class Times>
std::optional<Rejection> check_covariates(std::size_t observations, const Times& times) {
  if (observations != times.size() || observations == 0) {
    return Rejection{"observations and covariates must be non-empty and of equal length (" +
                     std::to_string(observations) + " vs " + std::to_string(times.size()) + ")"};
  }
  const double half_range = std::numeric_limits<double>::max() / 2;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    const auto index = static_cast<std::ptrdiff_t>(i);
    if (!std::isfinite(t)) {
      return Rejection{"covariate " + std::to_string(i) + " is not finite", index};
    }
    if (std::abs(t) > half_range) {
      return Rejection{"covariate " + std::to_string(i) +
                           " exceeds half the largest double in magnitude: differences of "
                           "covariates would overflow",
                       index};
    }
  }
  // A range the fits refuse (make_problem: the velocity would overflow or
  // underflow) is refused here, before any candidate, so that no model is
  // recommended for lack of a rival.
  double smallest = times[0], largest = times[0];
  for (std::size_t i = 1; i < times.size(); ++i) {
    smallest = std::min<double>(smallest, times[i]);
    largest = std::max<double>(largest, times[i]);
  }
  const double range = largest - smallest;
  const double limit = covariate_range_limit<double>();
  if (range > 0 && (range < limit || range > 1 / limit)) {
    std::ostringstream why;
    why << "the covariates' range " << range << " lies outside [" << limit << ", " << 1 / limit
        << "]: the velocity would overflow or underflow; rescale the covariates";
    return Rejection{why.str()};
  }
  return std::nullopt;
}

// The covariates as doubles, for the public entry points' overloads that
// take any indexable container with size() (std::array, std::deque, Eigen
// vectors, ...), as the fits do.
template <class Times>
std::vector<double> as_doubles(const Times& times) {
  using Index = decltype(times.size());
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(times.size()));
  for (Index i = 0; i < times.size(); ++i)
    out.push_back(static_cast<double>(times[i]));
  return out;
}

template <class Times>
constexpr bool kOtherTimes = !std::is_same_v<std::decay_t<Times>, std::vector<double>>;

// Lengths, covariates, then every observation finite and an element of G
// (to the default element tolerance); the first at fault is named.
template <class G, class Observations>
std::optional<Rejection> check_input(const Observations& observations,
                                     const std::vector<double>& times, int threads) {
  if (auto rejection = check_covariates(observations.size(), times)) return rejection;
  if (threads < 1) return Rejection{"threads must be at least 1, got " + std::to_string(threads)};
  return check_observations<G>(observations, default_element_tolerance<typename G::Scalar>());
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

// K-fold cross-validated prediction errors of `candidates` models: for
// each, the mean over i of |residual(the prediction fitted without i's
// fold, f_i, t_i)|^2, or nothing if the model is not `fitted(c)` or a fold's
// fit fails. `fit(c, train, train_times)` returns an optional prediction;
// training sets are vectors of Element. The (candidate, fold) fits run as
// tasks on `pool`; each fold's squared sum is kept apart and the folds are
// added in order, so the errors do not depend on the pool's threads.
template <class Element, class Observations, class Fitted, class Fit, class Residual>
std::vector<std::optional<double>> cv_errors(const Observations& observations,
                                             const std::vector<double>& times, int folds,
                                             std::size_t candidates, const Fitted& fitted,
                                             const Fit& fit, const Residual& residual,
                                             ChunkPool& pool) {
  const std::vector<int> fold = fold_of(times, folds);
  const std::size_t fold_count = static_cast<std::size_t>(folds);
  std::vector<std::optional<double>> fold_sums(candidates * fold_count);
  pool.run(candidates * fold_count, [&](std::size_t task) {
    const std::size_t c = task / fold_count;
    const int k = static_cast<int>(task % fold_count);
    if (!fitted(c)) return;
    std::vector<Element> train;
    std::vector<double> train_times;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (fold[i] == k) continue;
      train.push_back(observations[i]);
      train_times.push_back(times[i]);
    }
    const auto prediction = fit(c, train, train_times);
    if (!prediction) return;
    double squared_sum = 0;
    for (std::size_t i = 0; i < observations.size(); ++i)
      if (fold[i] == k)
        squared_sum += residual(*prediction, observations[i], times[i]).squaredNorm();
    fold_sums[task] = squared_sum;
  });
  std::vector<std::optional<double>> errors(candidates);
  for (std::size_t c = 0; c < candidates; ++c) {
    double squared_sum = 0;
    bool complete = true;
    for (std::size_t k = 0; k < fold_count && complete; ++k) {
      complete = fold_sums[c * fold_count + k].has_value();
      if (complete) squared_sum += *fold_sums[c * fold_count + k];
    }
    const double error = squared_sum / static_cast<double>(observations.size());
    if (complete && std::isfinite(error)) errors[c] = error;
  }
  return errors;
}

template <class Tangent>
auto residual_covariance(const std::vector<Tangent>& r) {
  using Square = Eigen::Matrix<double, Tangent::RowsAtCompileTime, Tangent::RowsAtCompileTime>;
  Square s = Square::Zero();
  for (const auto& ri : r)
    s += ri * ri.transpose();
  return Square(s / static_cast<double>(r.size()));
}

// The eigenvalue floor of every candidate's S: kDeterminantFloor times the
// largest eigenvalue of the static model's S (`spread`: its residuals), or,
// if the static model was excluded (`spread` empty), of the spread about
// the middle observation; at least the smallest normal double.
template <class G, class Observations>
double determinant_floor(std::vector<typename G::Tangent> spread,
                         const Observations& observations) {
  const std::size_t n = observations.size();
  if (spread.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      spread.push_back(G::log(G::compose(G::inverse(observations[n / 2]), observations[i])));
  }
  const auto spread_covariance = residual_covariance(spread);
  const double largest_spread =
      Eigen::SelfAdjointEigenSolver<std::decay_t<decltype(spread_covariance)>>(
          spread_covariance, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .maxCoeff();
  return std::max(kDeterminantFloor * largest_spread, std::numeric_limits<double>::min());
}

template <class Square>
double floored_log_det(const Square& s, double floor) {
  const Eigen::SelfAdjointEigenSolver<Square> eigen(s, Eigen::EigenvaluesOnly);
  double log_det = 0;
  for (Eigen::Index j = 0; j < s.rows(); ++j)
    log_det += std::log(std::max(eigen.eigenvalues()[j], floor));
  return log_det;
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

enum class TrendModel { static_element, geodesic };

inline const char* to_string(TrendModel model) {
  return model == TrendModel::static_element ? "static" : "geodesic";
}

struct TrendCandidate {
  TrendModel model = TrendModel::static_element;
  int parameters = 0;
  bool fitted = false;  // false: excluded, `note` says why
  std::string note;
  double residual_rms = 0;         // RMS of |r_i| in G's tangent coordinates
  double log_det = 0;              // log det S with the eigenvalue floor
  double criterion = 0;            // N/2 log det S + k/2 log N
  std::optional<double> cv_error;  // mean held-out |r|^2; empty if a fold failed
  bool within_margin = false;      // C <= best C + kSelectionMargin
  bool recommended = false;
};

template <class G>
struct TrendSelection {
  SelectionStatus status = SelectionStatus::invalid_input;
  std::ptrdiff_t bad_index = -1;  // invalid_input: the observation or covariate at fault, or -1
  std::vector<TrendCandidate> candidates;             // static, then geodesic
  std::optional<TrendModel> recommended;              // empty unless status is selected
  std::optional<typename G::Element> static_element;  // the mean, if fitted
  std::optional<Geodesic<G>> geodesic;  // the geodesic fit in the user's covariates, if fitted
  std::string message;

  bool ok() const { return status == SelectionStatus::selected; }
};

namespace model_selection_detail {

// The prediction of a static or geodesic candidate fitted to `observations`
// at centred covariates `times`. The static one is the constant geodesic
// (m, m) parametrised on `span` (the centred covariates' range, first <
// second): evaluated at any covariate of the data it computes
// m exp(s log(m^{-1} m)) with s in [0, 1], so the rounding-level
// log(m^{-1} m) (a few epsilon) stays at that level; on (0, 1) it would be
// multiplied by the covariate itself (1.4e18 for nanosecond timestamps).
template <class G, class Observations>
std::optional<Geodesic<G>> fit_trend_model(TrendModel model, const Observations& observations,
                                           const std::vector<double>& times,
                                           std::pair<double, double> span) {
  using Scalar = typename G::Scalar;
  if (model == TrendModel::static_element) {
    const auto m = mean<G>(observations);
    if (!m.ok()) return std::nullopt;
    return Geodesic<G>(*m.mean, *m.mean, static_cast<Scalar>(span.first),
                       static_cast<Scalar>(span.second));
  }
  const auto fit = GeodesicRegression<G>().fit(observations, times);
  if (!fit.ok()) return std::nullopt;
  return fit.geodesic;
}

template <class G>
typename G::Tangent trend_residual(const Geodesic<G>& prediction,
                                   const typename G::Element& observation, double t) {
  return G::log(G::compose(G::inverse(prediction(t)), observation));
}

}  // namespace model_selection_detail

// Static against geodesic for `observations` of any group G (indexable,
// with size()) at covariates `times`: the recommendation is the static
// model unless the geodesic's criterion is lower by more than
// kSelectionMargin. Never throws for bad data, never returns NaN: input
// refused as select_motion_model refuses it (a covariate not finite or
// beyond half the largest double, an observation not finite or not in G)
// has status invalid_input, naming the index; a model that cannot be
// fitted or scored (N below its parameter count, a failed fit, an
// overflowing criterion) is excluded with a note; with neither left the
// status is no_candidate.
//
// Covariates are centred before any arithmetic: c_i = t_i - t_ref with
// t_ref the midpoint of their range, so that covariates far from zero
// (EuRoC nanoseconds as doubles, 1.4e18 + 5e6 i) are worked on as their
// differences, which double holds exactly enough; the geodesic returned is
// parametrised in the user's covariates again.
template <class G, class Observations>
TrendSelection<G> select_static_or_geodesic(const Observations& observations,
                                            const std::vector<double>& times,
                                            const ModelSelectionOptions& options = {}) {
  namespace detail = model_selection_detail;
  using Tangent = typename G::Tangent;
  using Scalar = typename G::Scalar;
  TrendSelection<G> selection;
  const std::size_t n = observations.size();
  if (auto rejection = detail::check_input<G>(observations, times, options.threads)) {
    selection.message = rejection->message;
    selection.bad_index = rejection->index;
    return selection;
  }
  // Centring: |t_i| <= max/2 (checked), so every c_i is finite; the
  // midpoint min/2 + max/2 cannot overflow.
  const auto [smallest, largest] = std::minmax_element(times.begin(), times.end());
  const double reference = *smallest / 2 + *largest / 2;
  std::vector<double> centred(n);
  for (std::size_t i = 0; i < n; ++i)
    centred[i] = times[i] - reference;
  const double low = *smallest - reference, high = *largest - reference;
  // The static candidate's parametrisation (any interval will do if all
  // covariates are equal).
  const std::pair<double, double> span =
      high > low ? std::pair(low, high) : std::pair(low, low + 1);
  const double n_real = static_cast<double>(n);
  std::vector<std::vector<Tangent>> residuals;
  for (TrendModel model : {TrendModel::static_element, TrendModel::geodesic}) {
    TrendCandidate report;
    report.model = model;
    report.parameters = (model == TrendModel::static_element ? 1 : 2) * G::dof;
    std::optional<Geodesic<G>> prediction;
    if (n_real < report.parameters) {
      report.note = "excluded: " + std::to_string(n) + " observations, fewer than its " +
                    std::to_string(report.parameters) + " parameters";
    } else {
      prediction = detail::fit_trend_model<G>(model, observations, centred, span);
      if (!prediction) report.note = "excluded: its fit failed";
    }
    std::vector<Tangent> r;
    if (prediction) {
      report.fitted = true;
      for (std::size_t i = 0; i < n; ++i)
        r.push_back(detail::trend_residual<G>(*prediction, observations[i], centred[i]));
      if (model == TrendModel::static_element) {
        selection.static_element = prediction->start();
      } else {
        // Back to the user's covariates: gamma(t) = fit(t - t_ref).
        selection.geodesic =
            Geodesic<G>(prediction->start(), prediction->end(),
                        static_cast<Scalar>(static_cast<double>(prediction->t_min()) + reference),
                        static_cast<Scalar>(static_cast<double>(prediction->t_max()) + reference));
      }
    }
    residuals.push_back(r);
    selection.candidates.push_back(report);
  }
  const double floor = detail::determinant_floor<G>(residuals.front(), observations);
  std::optional<double> best;
  for (std::size_t c = 0; c < selection.candidates.size(); ++c) {
    TrendCandidate& report = selection.candidates[c];
    if (!report.fitted) continue;
    double squares = 0;
    for (const auto& ri : residuals[c])
      squares += ri.squaredNorm();
    const double log_det =
        detail::floored_log_det(detail::residual_covariance(residuals[c]), floor);
    const double criterion = n_real / 2 * log_det + report.parameters / 2.0 * std::log(n_real);
    if (!std::isfinite(floor) || !std::isfinite(squares) || !std::isfinite(criterion)) {
      report.fitted = false;
      report.note = "excluded: its residuals' squares overflow (criterion not finite)";
      if (report.model == TrendModel::static_element) {
        selection.static_element.reset();
      } else {
        selection.geodesic.reset();
      }
      continue;
    }
    report.residual_rms = std::sqrt(squares / n_real);
    report.log_det = log_det;
    report.criterion = criterion;
    if (!best || report.criterion < *best) best = report.criterion;
  }
  if (options.folds >= 2 && n >= static_cast<std::size_t>(options.folds)) {
    using Element = typename G::Element;
    const std::size_t tasks = selection.candidates.size() * static_cast<std::size_t>(options.folds);
    ChunkPool pool(options.threads, tasks);
    const std::vector<std::optional<double>> errors = detail::cv_errors<Element>(
        observations, centred, options.folds, selection.candidates.size(),
        [&](std::size_t c) { return selection.candidates[c].fitted; },
        [&](std::size_t c, const std::vector<Element>& train,
            const std::vector<double>& train_times) {
          return detail::fit_trend_model<G>(selection.candidates[c].model, train, train_times,
                                            span);
        },
        detail::trend_residual<G>, pool);
    for (std::size_t c = 0; c < selection.candidates.size(); ++c)
      selection.candidates[c].cv_error = errors[c];
  }
  if (!best) {
    selection.status = SelectionStatus::no_candidate;
    selection.message = "neither model could be fitted and scored (see each candidate's note)";
    return selection;
  }
  // The static model has fewer parameters: it wins within the margin. The
  // best finite criterion is within the margin of itself, so one does.
  for (TrendCandidate& report : selection.candidates)
    report.within_margin = report.fitted && report.criterion <= *best + kSelectionMargin;
  selection.status = SelectionStatus::selected;
  TrendCandidate& winner = selection.candidates[selection.candidates[0].within_margin ? 0 : 1];
  winner.recommended = true;
  selection.recommended = winner.model;
  return selection;
}

// The same with covariates in any indexable container with size()
// (std::array, Eigen::VectorXd, ...), read as doubles.
template <class G, class Observations, class Times,
          std::enable_if_t<model_selection_detail::kOtherTimes<Times>, int> = 0>
TrendSelection<G> select_static_or_geodesic(const Observations& observations, const Times& times,
                                            const ModelSelectionOptions& options = {}) {
  return select_static_or_geodesic<G>(observations, model_selection_detail::as_doubles(times),
                                      options);
}

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
