// bireg: the automatic bandwidth of local regression
// (statistics/smoothing/local_geodesic.hpp) by cross-validation, one choice for the
// pose and one for the velocity (DESIGN.md section 5).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/math/small_lu.hpp"
#include "bireg/math/symmetric_eigen.hpp"
#include "bireg/statistics/smoothing/local_geodesic.hpp"

namespace bireg {

// The automatic bandwidth: two cross-validation curves over a grid, one
// for the pose and one for the velocity, and their minimisers.
template <class Scalar>
struct BandwidthSelection {
  // The admissible grid value with the smallest criterion (0: none).
  Scalar bandwidth = 0;           // for the pose
  Scalar velocity_bandwidth = 0;  // for the velocity
  // The velocity's local polynomial degree chosen with velocity_bandwidth
  // (LocalRegressionOptions::velocity_degree): the options' own, or 3 where
  // the options' is 2 and the cubic's curve has the smaller minimum.
  int velocity_degree = 2;
  std::vector<Scalar> grid;  // ascending
  // Per grid value: the generalised variance det(S_h)^(1/d) of the
  // cross-validation errors, S_h = (1/M) sum e_i e_i^T over the M
  // observations compared (below). Left invariant; right translation
  // multiplies every S_h by the same Ad S Ad^T, so the ratios and the
  // choice are right invariant on every group (DESIGN.md section 5).
  // Infinite where the grid value was refused. `criterion` has the pose's
  // leave-one-out errors, `velocity_criterion` the velocity's errors
  // against the chords between neighbours, S_h corrected for the noise the
  // two share (LocalGeodesicRegression::held_out, HoldOut::chords).
  std::vector<Scalar> criterion;
  std::vector<Scalar> velocity_criterion;
  // The same for the local cubic's velocity (velocity_degree 3), compared
  // with velocity_criterion on the same observations; empty when it was
  // not evaluated (the options' degree is not 2, or the fits are robust).
  std::vector<Scalar> cubic_velocity_criterion;
  // What the velocity's errors are measured against: the chords between
  // neighbours, or the five-point derivatives where the chords' bias would
  // cost more than the derivatives' noise (velocity_target).
  HoldOut velocity_target = HoldOut::chords;
  // The mean squared pose error (1/M) sum |e_i|^2, for reading: left
  // invariant, right invariant only on compact groups (SO(n)).
  std::vector<Scalar> mean_squared_error;
  // Per grid value, the held-out queries whose local fit failed at every
  // width, and the first of them; a grid value is refused only where
  // more than a tenth of its queries failed (`refusals` says so), and
  // otherwise compared with the others on the observations where every
  // admissible value succeeded (`compared` of them).
  std::vector<std::size_t> failures;
  std::vector<std::size_t> velocity_failures;
  std::vector<std::string> first_failures;
  std::vector<std::string> refusals;  // why a grid value was refused, else empty
  std::vector<std::string> velocity_refusals;
  std::vector<std::string> cubic_velocity_refusals;
  std::size_t compared = 0;
  std::size_t velocity_compared = 0;
  // Whether a choice is the grid's first or last value (the best value
  // may lie beyond the grid), and everything a user should be told: a
  // choice at the edge, most grid values refused, or why nothing could
  // be chosen. Empty when there is nothing to say.
  bool at_edge = false;
  bool velocity_at_edge = false;
  std::string message;
  // The compatibility name of `refusals`' reasons and of the first
  // failures: why a grid value failed or was refused, else empty.
  std::vector<std::string> problems;
  bool ok() const { return bandwidth > 0; }
};

namespace local_regression_detail {

// A grid value whose held-out queries fail at more than this share of the
// observations is refused: its curve would compare a different, easier
// set of observations.
inline constexpr double kMaxFailureShare = 0.1;

// det(S)^(1/d), over S's numerical range where S is singular (the product
// of its r eigenvalues above 1e-12 of the largest, to the power 1/r: the
// pseudo-determinant, as the trend test uses for planar motion in SE(3),
// whose errors have no component out of the plane); infinite when S is
// zero or not finite.
template <class G>
typename G::Scalar generalised_variance(
    const Eigen::Matrix<typename G::Scalar, G::dof, G::dof>& s) {
  using Scalar = typename G::Scalar;
  using std::exp;
  using std::log;
  const Scalar infinity = std::numeric_limits<Scalar>::infinity();
  if (!s.allFinite()) return infinity;
  const auto eigenvalues = symmetric_eigen(s).values;
  const Scalar largest = eigenvalues.maxCoeff();
  if (!(largest > 0)) return infinity;
  Scalar sum_logs = 0;
  int rank = 0;
  for (int k = 0; k < eigenvalues.size(); ++k) {
    if (!(eigenvalues[k] > Scalar(1e-12) * largest)) continue;
    sum_logs += log(eigenvalues[k]);
    ++rank;
  }
  return exp(sum_logs / Scalar(rank));
}

// Whether more than kMaxFailureShare of a curve's held-out fits failed;
// `attempted` receives how many were attempted (succeeded or failed).
template <class G>
bool fails_too_often(const HeldOut<G>& curve, std::size_t& attempted) {
  attempted = curve.failures;
  for (const char ok : curve.ok)
    attempted += ok ? 1 : 0;
  return static_cast<double>(curve.failures) > kMaxFailureShare * static_cast<double>(attempted);
}

// The errors' scatter S = (1/M) sum e_i e_i^T over the M observations that
// `use` keeps, with `noise` (HoldOut::chords) the shared noise added back,
// S + 2 mean(c_i) Sigma; and (1/M) sum |e_i|^2. M = 0 leaves both zero.
template <class G>
struct ErrorScatter {
  Eigen::Matrix<typename G::Scalar, G::dof, G::dof> scatter =
      Eigen::Matrix<typename G::Scalar, G::dof, G::dof>::Zero();
  typename G::Scalar mean_squared = 0;
  std::size_t count = 0;
};

template <class G>
ErrorScatter<G> error_scatter(const HeldOut<G>& curve, const std::vector<char>& use,
                              const Eigen::Matrix<typename G::Scalar, G::dof, G::dof>* noise) {
  using Scalar = typename G::Scalar;
  ErrorScatter<G> out;
  Scalar cross = 0;
  for (std::size_t i = 0; i < use.size(); ++i) {
    if (!use[i]) continue;
    out.scatter.noalias() += curve.errors[i] * curve.errors[i].transpose();
    out.mean_squared += curve.errors[i].squaredNorm();
    if (noise) cross += curve.cross[i];
    ++out.count;
  }
  if (out.count == 0) return out;
  const Scalar count = Scalar(out.count);
  out.scatter /= count;
  out.mean_squared /= count;
  if (noise) out.scatter += (Scalar(2) * cross / count) * *noise;
  return out;
}

// The choice among `curves` (one HeldOut per grid value): refusals, the
// common observations, the generalised variances, the minimiser's index
// (or grid.size()). `mean_squared`, when given, receives (1/M) sum |e|^2.
template <class G>
std::size_t choose(const std::vector<HeldOut<G>>& curves, std::size_t n,
                   std::vector<std::string>& refusals, std::vector<typename G::Scalar>& criteria,
                   std::size_t& compared, std::vector<typename G::Scalar>* mean_squared,
                   const Eigen::Matrix<typename G::Scalar, G::dof, G::dof>* noise = nullptr) {
  using Scalar = typename G::Scalar;
  const std::size_t k = curves.size();
  refusals.assign(k, std::string());
  criteria.assign(k, std::numeric_limits<Scalar>::infinity());
  if (mean_squared) mean_squared->assign(k, std::numeric_limits<Scalar>::infinity());
  std::vector<char> common(n, 1);
  for (std::size_t j = 0; j < k; ++j) {
    const HeldOut<G>& c = curves[j];
    if (!c.problem.empty()) {
      refusals[j] = c.problem;
      continue;
    }
    std::size_t attempted = 0;
    if (fails_too_often(c, attempted)) {
      refusals[j] = std::to_string(c.failures) + " of " + std::to_string(attempted) +
                    " held-out fits failed (more than a tenth); the first: " + c.first_failure;
      continue;
    }
    for (std::size_t i = 0; i < n; ++i)
      common[i] = common[i] && c.ok[i];
  }
  compared = 0;
  for (std::size_t i = 0; i < n; ++i)
    compared += common[i] ? 1 : 0;
  if (compared == 0) return k;
  std::size_t best = k;
  for (std::size_t j = 0; j < k; ++j) {
    if (!refusals[j].empty()) continue;
    const ErrorScatter<G> errors = error_scatter(curves[j], common, noise);
    if (mean_squared) (*mean_squared)[j] = errors.mean_squared;
    const Scalar variance = generalised_variance<G>(errors.scatter);
    if (!std::isfinite(variance)) {
      refusals[j] = "the scatter of the errors over " + std::to_string(compared) +
                    " observations is zero or not finite: its generalised variance "
                    "cannot rank this value";
      continue;
    }
    criteria[j] = variance;
    if (best == k || criteria[j] < criteria[best]) best = j;
  }
  return best;
}

// The permutation that sorts the covariates ascending (stable).
template <class Scalar, class Covariates>
std::vector<std::size_t> covariate_order(const Covariates& covariates) {
  std::vector<std::size_t> order(covariates.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return Scalar(covariates[a]) < Scalar(covariates[b]);
  });
  return order;
}

// The noise covariance Sigma of observations f_i exp(e_i), from third
// divided differences: for four consecutive observations (in covariate
// order) with y_j = log(f_a^{-1} f_j) in the chart at the first, the
// divided difference sum_j a_j y_j, a_j = 1 / prod_{k != j} (t_j - t_k),
// vanishes on every quadratic in t, so on a smooth curve sampled densely
// enough it is noise alone, with covariance (sum_j a_j^2) Sigma:
// Sigma^ = mean of D D^T / sum a_j^2. Left invariant; maps by Ad under
// right translation, like the errors it corrects. Zero with fewer than
// four distinct covariates.
template <class G, class Observations, class Covariates>
Eigen::Matrix<typename G::Scalar, G::dof, G::dof> noise_scatter(const Observations& observations,
                                                                const Covariates& covariates) {
  using Scalar = typename G::Scalar;
  using Scatter = Eigen::Matrix<Scalar, G::dof, G::dof>;
  const std::size_t n = observations.size();
  const std::vector<std::size_t> order = covariate_order<Scalar>(covariates);
  Scatter sum = Scatter::Zero();
  std::size_t count = 0;
  for (std::size_t i = 0; i + 3 < n; ++i) {
    Scalar t[4];
    for (int j = 0; j < 4; ++j)
      t[j] = Scalar(covariates[order[i + static_cast<std::size_t>(j)]]);
    if (!(t[0] < t[1] && t[1] < t[2] && t[2] < t[3])) continue;
    const typename G::Element base_inverse = G::inverse(observations[order[i]]);
    typename G::Tangent difference = G::Tangent::Zero();
    Scalar squares = 0;
    for (int j = 0; j < 4; ++j) {
      Scalar a = 1;
      for (int k = 0; k < 4; ++k) {
        if (k != j) a /= t[j] - t[k];
      }
      squares += a * a;
      if (j > 0) {
        difference += a * G::log(G::compose(base_inverse,
                                            observations[order[i + static_cast<std::size_t>(j)]]));
      }
    }
    if (!(squares > 0) || !difference.allFinite()) continue;
    sum.noalias() += difference * difference.transpose() / squares;
    ++count;
  }
  if (count == 0) return Scatter::Zero();
  return sum / Scalar(count);
}

// Which target the velocity's cross-validation compares with (DESIGN.md
// section 5, "Choosing the bandwidth for the velocity"): the chord between
// an observation's neighbours, d_i (HoldOut::chords), or the five-point
// derivative at it, D_i (HoldOut::derivatives). A target's error enters the
// criterion twice: its noise adds a constant (harmless, but it buries the
// differences between bandwidths), its bias correlates with the
// estimator's and moves the minimum. D_i's bias is O(dt^4) where d_i's is
// O(dt^2), and its noise is larger (the squares of its weights sum to
// 0.90 / dt^2, the chord's to 0.50 / dt^2, for even spacing). Compared
// where both exist, d_i - D_i is d_i's bias plus noise of covariance
// (sum_j (a_j - b_j)^2) Sigma (a the chord's weights, b the derivative's),
// so with Sigma^ = noise, in its whitened coordinates (invariant),
//
//   bias^2 = mean (d - D)^T Sigma^-1 (d - D) - dof mean sum_j (a_j - b_j)^2,
//   extra  = dof mean (sum_j b_j^2 - sum_j a_j^2),
//
// and the derivative is the target when the chord's bias costs more than the
// derivative's extra noise: on a spin of 20 rad/s at 25 Hz without noise the
// chords are 0.22 rad/s off and cross-validation against them chose a
// velocity error of 0.18 where 0.04 was possible; on a 5 rad/s spin at 100
// Hz with noise 0.02 rad they are unbiased to 1e-3 and the derivative's
// noise flattened the curve (0.18 instead of 0.10). Where Sigma^ is singular
// (noise-free data, or noise in fewer directions than the group has) the
// comparison is in traces instead.
template <class G, class Observations, class Covariates>
HoldOut velocity_target(const Observations& observations, const Covariates& covariates,
                        const Eigen::Matrix<typename G::Scalar, G::dof, G::dof>& noise,
                        typename G::Scalar max_turn) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  constexpr int d = G::dof;
  const std::size_t n = observations.size();
  const std::vector<std::size_t> order = covariate_order<Scalar>(covariates);
  std::vector<Scalar> t(n);
  std::vector<typename G::Element> f(n);
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = Scalar(covariates[order[i]]);
    f[i] = observations[order[i]];
  }
  const SmallLU<Eigen::Matrix<Scalar, d, d>> whitening(noise);
  const bool whitened = whitening.invertible();
  const Scalar trace = noise.trace();
  Scalar bias = 0, extra = 0;
  std::size_t count = 0;
  for (std::size_t i = 2; i + 2 < n; ++i) {
    const DerivativeTarget<G> five = five_point_target<G>(f, t, i, max_turn);
    if (!five.defined) continue;
    const Scalar span = t[i + 1] - t[i - 1];
    const Tangent chord = G::log(G::compose(G::inverse(f[i - 1]), f[i + 1])) / span;
    if (!chord.allFinite()) continue;
    const Tangent difference = chord - five.velocity;
    const Scalar chord_weights[5] = {0, -1 / span, 0, 1 / span, 0};
    Scalar difference_squares = 0, five_squares = 0, chord_squares = 0;
    for (int k = 0; k < 5; ++k) {
      const Scalar gap = chord_weights[k] - five.weights[k];
      difference_squares += gap * gap;
      five_squares += five.weights[k] * five.weights[k];
      chord_squares += chord_weights[k] * chord_weights[k];
    }
    const Scalar scale = whitened ? Scalar(d) : trace;
    bias += (whitened ? difference.dot(whitening.solve(difference)) : difference.squaredNorm()) -
            scale * difference_squares;
    extra += scale * (five_squares - chord_squares);
    ++count;
  }
  if (count == 0) return HoldOut::chords;
  return bias > extra ? HoldOut::derivatives : HoldOut::chords;
}

}  // namespace local_regression_detail

// Cross-validation over `grid` (options.bandwidth is ignored): for each
// value the pose's leave-one-out errors and the velocity's errors against
// the chords (LocalGeodesicRegression::held_out), and the minimiser of
// each curve. The bandwidth that predicts the pose best is narrower than
// the one that estimates its derivative best (a derivative's optimal
// bandwidth shrinks more slowly with the noise), hence two choices.
// Where options.velocity_degree is 2 (the default) and the fits are not
// robust, the velocity's curve is also evaluated for the local cubic
// (degree 3), and the velocity's choice is the (degree, bandwidth) with
// the smallest criterion of the two curves (velocity_degree says which):
// the criterion estimates the velocity's mean squared error up to a
// constant that depends on neither. Set velocity_degree to 1 or 3 to fix
// the degree. `progress`, when set, is called with (done, total) after
// the pose's and after the velocity's held-out passes (2 per grid value).
// Cost: two local fits per observation per grid value evaluated (the
// cubic's curve shares the velocity's), each over its window; windows are capped in turn
// (Options::max_turn) and in the kernel's support, and the values past
// both curves' minima are skipped (below), so the widest values, O(N^2)
// each on slow motion over a long range, are seldom reached.
template <class G, class Observations, class Covariates>
BandwidthSelection<typename G::Scalar> select_bandwidth(
    const Observations& observations, const Covariates& covariates,
    LocalRegressionOptions<typename G::Scalar> options, const std::vector<typename G::Scalar>& grid,
    const std::function<void(std::size_t, std::size_t)>& progress = {}) {
  using Scalar = typename G::Scalar;
  BandwidthSelection<Scalar> selection;
  if (grid.empty()) {
    selection.message =
        "the bandwidth grid is empty (bandwidth_grid gives none for fewer than two distinct "
        "covariates, a covariate that is not finite or a range that overflows)";
    return selection;
  }
  for (std::size_t j = 0; j < grid.size(); ++j) {
    using std::isfinite;
    if (!(grid[j] > 0) || !isfinite(grid[j])) {
      selection.message =
          "bandwidth grid value " + std::to_string(j) + " is not a positive finite number";
      return selection;
    }
  }
  selection.grid = grid;
  std::sort(selection.grid.begin(), selection.grid.end());
  const std::size_t k = selection.grid.size();
  const std::size_t n = observations.size();
  options.standard_errors = false;
  using Scatter = Eigen::Matrix<Scalar, G::dof, G::dof>;
  // Computed once the first held-out pass has checked the input.
  Scatter noise = Scatter::Zero();
  bool noise_ready = false;
  // The curves are evaluated in ascending bandwidth, and the rest of the
  // grid is skipped once neither has improved on its smallest value for
  // kRisesBeforeStop values in a row (each judged provisionally, on its own
  // successes): past their minimum the widest windows cost the most and
  // cannot win.
  constexpr std::size_t kRisesBeforeStop = 4;
  const auto provisional = [](const HeldOut<G>& c, const Scatter* correction) {
    // As choose() refuses: a refused input, too many failures, none compared.
    std::size_t attempted = 0;
    if (!c.problem.empty() || local_regression_detail::fails_too_often(c, attempted)) {
      return std::numeric_limits<Scalar>::infinity();
    }
    const auto errors = local_regression_detail::error_scatter(c, c.ok, correction);
    return errors.count == 0 ? std::numeric_limits<Scalar>::infinity()
                             : local_regression_detail::generalised_variance<G>(errors.scatter);
  };
  Scalar best_pose = std::numeric_limits<Scalar>::infinity();
  Scalar best_velocity = best_pose;
  std::size_t rises = 0;
  // The cubic's velocity is a second curve over the same grid (DESIGN.md
  // section 5, "The velocity's degree"): the same local fits, another
  // polynomial through their residuals.
  const bool try_cubic = options.velocity_degree == 2 && !options.robust;
  std::vector<HeldOut<G>> poses, velocities, cubics;
  for (std::size_t j = 0; j < k; ++j) {
    if (rises >= kRisesBeforeStop) {
      HeldOut<G> skipped;
      skipped.problem = "not evaluated: neither criterion improved for " +
                        std::to_string(kRisesBeforeStop) + " smaller bandwidths";
      poses.push_back(skipped);
      velocities.push_back(skipped);
      if (try_cubic) cubics.push_back(skipped);
    } else {
      options.bandwidth = selection.grid[j];
      const LocalGeodesicRegression<G> smoother(options);
      poses.push_back(smoother.held_out(observations, covariates, HoldOut::one));
      if (progress) progress(2 * j + 1, 2 * k);
      if (!noise_ready && poses.back().problem.empty()) {
        noise = local_regression_detail::noise_scatter<G>(observations, covariates);
        selection.velocity_target = local_regression_detail::velocity_target<G>(
            observations, covariates, noise, options.max_turn);
        noise_ready = true;
      }
      HeldOut<G> cubic;
      velocities.push_back(smoother.held_out(observations, covariates, selection.velocity_target,
                                             try_cubic ? &cubic : nullptr));
      Scalar velocity = provisional(velocities.back(), &noise);
      if (try_cubic) {
        cubics.push_back(std::move(cubic));
        velocity = std::min(velocity, provisional(cubics.back(), &noise));
      }
      if (progress) progress(2 * j + 2, 2 * k);
      const Scalar pose = provisional(poses.back(), nullptr);
      const bool improved = pose < best_pose || velocity < best_velocity;
      best_pose = std::min(best_pose, pose);
      best_velocity = std::min(best_velocity, velocity);
      const bool started = best_pose < std::numeric_limits<Scalar>::infinity() &&
                           best_velocity < std::numeric_limits<Scalar>::infinity();
      rises = improved || !started ? 0 : rises + 1;
    }
    selection.failures.push_back(poses.back().failures);
    selection.velocity_failures.push_back(velocities.back().failures);
    selection.first_failures.push_back(poses.back().problem.empty() ? poses.back().first_failure
                                                                    : poses.back().problem);
  }
  if (progress) progress(2 * k, 2 * k);
  const std::size_t pose_best =
      local_regression_detail::choose<G>(poses, n, selection.refusals, selection.criterion,
                                         selection.compared, &selection.mean_squared_error);
  // Both degrees' curves in one choice, so that they are compared on the
  // same observations; then split back into the two curves.
  const std::size_t curves = velocities.size();
  velocities.insert(velocities.end(), cubics.begin(), cubics.end());
  std::size_t velocity_best = local_regression_detail::choose<G>(
      velocities, n, selection.velocity_refusals, selection.velocity_criterion,
      selection.velocity_compared, nullptr, &noise);
  selection.velocity_degree = options.velocity_degree;
  if (try_cubic) {
    selection.cubic_velocity_criterion.assign(selection.velocity_criterion.begin() + curves,
                                              selection.velocity_criterion.end());
    selection.cubic_velocity_refusals.assign(selection.velocity_refusals.begin() + curves,
                                             selection.velocity_refusals.end());
    selection.velocity_criterion.resize(curves);
    selection.velocity_refusals.resize(curves);
    if (velocity_best == 2 * k) {
      velocity_best = k;  // none admissible
    } else if (velocity_best >= k) {
      velocity_best -= k;
      selection.velocity_degree = 3;
    }
  }
  selection.problems = selection.refusals;
  for (std::size_t j = 0; j < k; ++j) {
    if (selection.problems[j].empty()) selection.problems[j] = selection.first_failures[j];
  }
  std::size_t refused = 0;  // for a stated reason, not skipped
  for (const std::string& r : selection.refusals)
    refused += r.empty() || r.rfind("not evaluated", 0) == 0 ? 0 : 1;
  const auto text = [](Scalar h) {
    std::ostringstream out;
    out.precision(6);
    out << h;
    return out.str();
  };
  if (pose_best == k) {
    selection.message = "no bandwidth from " + text(selection.grid.front()) + " to " +
                        text(selection.grid.back()) +
                        " could be ranked (the first: " + selection.refusals.front() + ")";
    return selection;
  }
  selection.bandwidth = selection.grid[pose_best];
  selection.at_edge = k > 1 && (pose_best == 0 || pose_best + 1 == k);
  // The velocity falls back to the pose's choice where its own curve has
  // no admissible value (fewer than three observations, or noise that
  // swamps the chords' correction).
  selection.velocity_bandwidth =
      velocity_best == k ? selection.bandwidth : selection.grid[velocity_best];
  selection.velocity_at_edge =
      velocity_best != k && k > 1 && (velocity_best == 0 || velocity_best + 1 == k);
  std::string notes;
  if (selection.at_edge) {
    notes += std::string("the pose's choice is the grid's ") +
             (pose_best == 0 ? "smallest" : "largest") + " value, " + text(selection.bandwidth) +
             ": the best bandwidth may lie beyond the grid";
  }
  if (selection.velocity_at_edge) {
    notes += std::string(notes.empty() ? "" : "; ") + "the velocity's choice is the grid's " +
             (velocity_best == 0 ? "smallest" : "largest") + " value, " +
             text(selection.velocity_bandwidth);
  }
  if (velocity_best == k) {
    notes += std::string(notes.empty() ? "" : "; ") +
             "no bandwidth could be ranked for the velocity: it uses the pose's";
  }
  if (2 * refused > k) {
    notes += std::string(notes.empty() ? "" : "; ") + std::to_string(refused) + " of " +
             std::to_string(k) + " bandwidths were refused (the first: " +
             *std::find_if(selection.refusals.begin(), selection.refusals.end(),
                           [](const std::string& r) { return !r.empty(); }) +
             ")";
  }
  selection.message = notes;
  return selection;
}

// `count` bandwidths, geometrically spaced from `smallest_spacings` median
// sample spacings up to the covariates' whole range. Empty (no grid, and
// select_bandwidth then says so) when there is none to give: fewer than two
// distinct covariates, a covariate that is not finite, a range that
// overflows a double, `count` outside [2, kMaxGridSize], or
// `smallest_spacings` not a positive finite number. Every value returned
// is positive and finite.
inline constexpr int kMaxGridSize = 10000;

template <class Covariates>
std::vector<double> bandwidth_grid(const Covariates& covariates, int count = 20,
                                   double smallest_spacings = 2) {
  if (count < 2 || count > kMaxGridSize) return {};
  if (!(smallest_spacings > 0) || !std::isfinite(smallest_spacings)) return {};
  std::vector<double> t(covariates.begin(), covariates.end());
  for (const double covariate : t) {
    if (!std::isfinite(covariate)) return {};
  }
  std::sort(t.begin(), t.end());
  std::vector<double> spacings;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) spacings.push_back(t[i] - t[i - 1]);
  }
  if (spacings.empty()) return {};
  const auto middle = spacings.begin() + static_cast<std::ptrdiff_t>(spacings.size() / 2);
  std::nth_element(spacings.begin(), middle, spacings.end());
  const double low = smallest_spacings * *middle;
  const double high = t.back() - t.front();
  if (!std::isfinite(high) || !std::isfinite(low) || !(low > 0)) return {};
  if (!(high > low)) return {high};
  // low (high / low)^(k / (count - 1)), from the logarithms: high / low
  // may overflow. Where its power does too (low 1e-301, high 1e308: every
  // value of the grid is a double, the ratio of its ends is not), the same
  // value from log low. (Not everywhere: the rounding differs, and the
  // selection's near-ties at covariates of 1e18 would follow it.)
  std::vector<double> grid(static_cast<std::size_t>(count));
  const double log_low = std::log(low);
  const double ratio = (std::log(high) - log_low) / (count - 1);
  for (int k = 0; k < count; ++k) {
    const double power = std::exp(ratio * k);
    const double value = std::isfinite(power) ? low * power : std::exp(log_low + ratio * k);
    grid[static_cast<std::size_t>(k)] = std::clamp(value, low, high);
  }
  grid.back() = high;  // exp(log(high / low)) may round past the range
  return grid;
}

// The grid of "bandwidth auto" (bireg_smooth, the Python package's
// LocalRegression): kAutoGridSize values from kAutoSmallestSpacings median
// sample spacings to the whole range. Half a spacing is the narrowest
// useful Gaussian (its window then holds a sample on each side);
// noise-free or fast recordings need it.
inline constexpr int kAutoGridSize = 20;
inline constexpr double kAutoSmallestSpacings = 0.5;

template <class Covariates>
std::vector<double> auto_bandwidth_grid(const Covariates& covariates) {
  return bandwidth_grid(covariates, kAutoGridSize, kAutoSmallestSpacings);
}

}  // namespace bireg
