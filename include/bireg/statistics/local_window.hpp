// bireg: the window of a local regression query (statistics/local_geodesic.hpp):
// which observations it holds, how far it may reach on fast rotation, and
// the quadratic correction of its velocity (DESIGN.md section 5).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/geodesic.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/statistics/kernel.hpp"

namespace bireg {

// A query's observations, covariates and kernel weights, ascending in the
// covariate; reused from query to query.
template <class G>
struct LocalWindow {
  std::vector<typename G::Element> observations;
  std::vector<typename G::Scalar> covariates;
  std::vector<typename G::Scalar> weights;
  void clear() {
    observations.clear();
    covariates.clear();
    weights.clear();
  }
};

// What decides a window: the kernel, its bandwidth, and the most the
// window may turn (LocalRegressionOptions).
template <class Scalar>
struct WindowShape {
  Kernel kernel = Kernel::gaussian;
  Scalar bandwidth = Scalar(1);
  Scalar max_turn = Scalar(2.5);
  Scalar reach() const { return Scalar(kernel_support(kernel)) * bandwidth; }
};

// How far from tau the window may reach while it turns steadily less
// than max_turn: from the anchor a, the observation nearest tau, walk
// outward on each side and stop at the first two consecutive observations
// j with turn_angle(f_a^{-1} f_j) > max_turn / 2; that side's bound is
// the first one's distance |t_j - tau|, and the window's radius is the
// smaller of the two sides' (so the cut is symmetric in time), or `reach`
// when neither side stops or the group has no rotation. The turn angle of
// f_a^{-1} f_b is a bi-invariant distance (the angle of the relative
// rotation), so by the triangle inequality the motion within the window
// turns by at most max_turn, and the cut is left and right invariant. One
// observation alone beyond the ball is an outlier, not a turn: it stays in
// the window, for the fit (or a robust fit) to weigh, as it would without
// the cut. An anchor that is itself such an outlier (both its neighbours
// beyond its ball) is replaced by the next nearest observation. The anchor
// may be an observation that cross-validation holds out: the held-out
// window is then the full data's window without it, which is what
// leave-one-out should imitate.
template <class G>
typename G::Scalar turn_radius(const std::vector<typename G::Element>& f,
                               const std::vector<typename G::Scalar>& t, typename G::Scalar tau,
                               typename G::Scalar reach, std::size_t begin, std::size_t end,
                               typename G::Scalar max_turn) {
  using Scalar = typename G::Scalar;
  if constexpr (!has_turn_angle_v<G>) {
    return reach;
  } else {
    using std::abs;
    if (end - begin < 2) return reach;
    const Scalar ball = max_turn / Scalar(2);
    const auto beyond = [&](std::size_t a, std::size_t j) {
      return G::turn_angle(G::compose(G::inverse(f[a]), f[j])) > ball;
    };
    // The nearest observation, or the next nearest when the nearest is
    // beyond the ball of both its neighbours in the window.
    std::size_t anchor = begin;
    for (std::size_t i = begin + 1; i < end; ++i) {
      if (abs(t[i] - tau) < abs(t[anchor] - tau)) anchor = i;
    }
    const bool has_left = anchor > begin, has_right = anchor + 1 < end;
    if ((!has_left || beyond(anchor, anchor - 1)) && (!has_right || beyond(anchor, anchor + 1))) {
      if (!has_left) {
        anchor = anchor + 1;
      } else if (!has_right) {
        anchor = anchor - 1;
      } else {
        anchor = abs(t[anchor - 1] - tau) <= abs(t[anchor + 1] - tau) ? anchor - 1 : anchor + 1;
      }
    }
    Scalar radius = reach;
    // One side: `next` steps j outward while `more(j)`; the bound is the
    // first of two consecutive observations beyond the ball.
    const auto walk = [&](auto next, auto more) {
      bool previous_beyond = false;
      std::size_t first = anchor;
      for (std::size_t j = next(anchor); more(j); j = next(j)) {
        if (!beyond(anchor, j)) {
          previous_beyond = false;
          continue;
        }
        if (previous_beyond) {
          radius = std::min(radius, abs(t[first] - tau));
          return;
        }
        previous_beyond = true;
        first = j;
      }
    };
    walk([](std::size_t j) { return j + 1; }, [&](std::size_t j) { return j < end; });
    // Leftward, j - 1 wraps to the largest size_t past 0, where j + 1 = 0.
    walk([](std::size_t j) { return j - 1; }, [&](std::size_t j) { return j + 1 > begin; });
    return radius;
  }
}

// The observations with positive kernel weight at tau, ascending, cut
// where the window would turn by more than `shape.max_turn` (turn_radius).
// `excluded` and `also_excluded`: sorted indices held out
// (cross-validation), or any index past the end for none.
template <class G>
void fill_window(const std::vector<typename G::Element>& f,
                 const std::vector<typename G::Scalar>& t, typename G::Scalar tau,
                 const WindowShape<typename G::Scalar>& shape, LocalWindow<G>& window,
                 std::size_t excluded, std::size_t also_excluded = std::size_t(-1)) {
  using Scalar = typename G::Scalar;
  const Scalar reach = shape.reach();
  window.clear();
  const auto first = std::lower_bound(t.begin(), t.end(), tau - reach);
  const auto last = std::upper_bound(t.begin(), t.end(), tau + reach);
  const std::size_t begin = static_cast<std::size_t>(first - t.begin());
  const std::size_t end = static_cast<std::size_t>(last - t.begin());
  const Scalar radius = turn_radius<G>(f, t, tau, reach, begin, end, shape.max_turn);
  for (std::size_t i = begin; i < end; ++i) {
    if (i == excluded || i == also_excluded) continue;
    const Scalar offset = t[i] - tau;
    if (radius < reach && !(std::abs(offset) < radius)) continue;
    const Scalar weight = kernel_weight(shape.kernel, offset / shape.bandwidth);
    if (!(weight > 0)) continue;
    window.observations.push_back(f[i]);
    window.covariates.push_back(t[i]);
    window.weights.push_back(weight);
  }
}

// The slope of a quadratic fit of a local geodesic's residuals (below).
template <class G>
struct QuadraticSlope {
  bool defined = false;
  typename G::Tangent slope = G::Tangent::Zero();  // per covariate unit
  typename G::Scalar error_ratio = 1;              // quadratic over linear slope standard error
};

// LocalRegressionOptions::quadratic_velocity: with u_i = (t_i - tau) / s (s the
// window's half-width, for conditioning), z_i = (1, u_i, u_i^2) and the
// normal matrix M = sum w_i z_i z_i^T, the quadratic fit of the residuals
// has slope beta = (e_1^T M^{-1} sum w_i z_i r_i^T) / s, which the local
// regression adds to the geodesic's velocity. Its variance for residuals of equal variance is
// sigma^2 e_1^T M^{-1} (sum w_i^2 z_i z_i^T) M^{-1} e_1 / s^2, the
// geodesic's (a local line's) the same with z_i = (1, u_i): error_ratio is
// the square root of their ratio, by which the standard errors are scaled.
// Not defined when the window has fewer than three distinct covariates or
// M is singular to working precision.
template <class G>
QuadraticSlope<G> quadratic_slope(const Geodesic<G>& local, const LocalWindow<G>& window,
                                  typename G::Scalar tau) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Matrix2 = Eigen::Matrix<Scalar, 2, 2>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using std::abs;
  using std::sqrt;
  QuadraticSlope<G> result;
  const std::size_t m = window.covariates.size();
  if (m < 3) return result;
  const Scalar scale =
      std::max(abs(window.covariates.front() - tau), abs(window.covariates.back() - tau));
  Matrix3 normal = Matrix3::Zero();
  Matrix3 squared_weights = Matrix3::Zero();
  Eigen::Matrix<Scalar, 3, G::dof> moments = Eigen::Matrix<Scalar, 3, G::dof>::Zero();
  for (std::size_t i = 0; i < m; ++i) {
    const Scalar u = (window.covariates[i] - tau) / scale;
    const Vector3 z(Scalar(1), u, u * u);
    const Scalar w = window.weights[i];
    const Tangent r =
        G::log(G::compose(G::inverse(local(window.covariates[i])), window.observations[i]));
    normal.noalias() += w * z * z.transpose();
    squared_weights.noalias() += (w * w) * z * z.transpose();
    moments.noalias() += w * z * r.transpose();
  }
  const Eigen::FullPivLU<Matrix3> quadratic(normal);
  if (quadratic.rank() < 3) return result;
  const Vector3 slope_row = quadratic.solve(Vector3::UnitY());  // M^{-1} e_1 (M symmetric)
  const Tangent slope = (moments.transpose() * slope_row) / scale;
  if (!slope.allFinite()) return result;
  result.defined = true;
  result.slope = slope;
  const Eigen::FullPivLU<Matrix2> linear(normal.template topLeftCorner<2, 2>());
  if (linear.rank() < 2) return result;
  const Eigen::Matrix<Scalar, 2, 1> line_row = linear.solve(Eigen::Matrix<Scalar, 2, 1>::UnitY());
  const Scalar quadratic_variance = slope_row.dot(squared_weights * slope_row);
  const Scalar line_variance =
      line_row.dot(squared_weights.template topLeftCorner<2, 2>() * line_row);
  if (line_variance > 0) result.error_ratio = sqrt(quadratic_variance / line_variance);
  return result;
}

// The weight l of the observation at `covariate` in the local slope at
// tau, in the window's weighted least-squares fit on (1, u, u^2)
// (`quadratic`) or (1, u), u = t - tau: the slope is sum_j l_j y_j, with
// l_j = w_j e_1^T M^{-1} z_j. 0 when the covariate is not in the window or
// the design is singular.
template <class G>
typename G::Scalar slope_weight(const LocalWindow<G>& window, typename G::Scalar tau,
                                typename G::Scalar covariate, bool quadratic) {
  using Scalar = typename G::Scalar;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using std::abs;
  const std::size_t m = window.covariates.size();
  const int size = quadratic && m >= 3 ? 3 : 2;
  if (m < 2) return Scalar(0);
  const Scalar scale =
      std::max(abs(window.covariates.front() - tau), abs(window.covariates.back() - tau));
  const auto design = [&](Scalar t) {
    const Scalar u = (t - tau) / scale;
    return Vector3(Scalar(1), u, size == 3 ? u * u : Scalar(0));
  };
  Matrix3 normal = Matrix3::Zero();
  Scalar weight = 0;
  bool found = false;
  for (std::size_t i = 0; i < m; ++i) {
    const Vector3 z = design(window.covariates[i]);
    normal.noalias() += window.weights[i] * z * z.transpose();
    if (!found && window.covariates[i] == covariate) {
      weight = window.weights[i];
      found = true;
    }
  }
  if (!found) return Scalar(0);
  if (size == 2) normal(2, 2) = Scalar(1);  // the unused quadratic column
  const Eigen::FullPivLU<Matrix3> lu(normal);
  if (lu.rank() < 3) return Scalar(0);
  const Vector3 row = lu.solve(Vector3::UnitY());
  return weight * row.dot(design(covariate)) / scale;
}

}  // namespace bireg
