// bireg: the window of a local regression query (statistics/smoothing/local_geodesic.hpp):
// which observations it holds, how far it may reach on fast rotation, and
// the polynomial correction of its velocity (DESIGN.md section 5).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "bireg/geodesic.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/statistics/smoothing/kernel.hpp"

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
// window may turn (LocalRegressionOptions). A `wide` window may turn by
// max_turn on each side of the query (path_radius) instead of max_turn in
// all (turn_radius), for the wide fit (statistics/smoothing/local_wide.hpp).
template <class Scalar>
struct WindowShape {
  Kernel kernel = Kernel::gaussian;
  Scalar bandwidth = Scalar(1);
  Scalar max_turn = Scalar(2.5);
  bool wide = false;
  Scalar reach() const { return Scalar(kernel_support(kernel)) * bandwidth; }
};

// The index in [begin, end) whose covariate is nearest tau (the first of
// equals); `begin` when the range is empty.
template <class Scalar>
std::size_t nearest_observation(const std::vector<Scalar>& t, Scalar tau, std::size_t begin,
                                std::size_t end) {
  using std::abs;
  std::size_t nearest = begin;
  for (std::size_t i = begin + 1; i < end; ++i) {
    if (abs(t[i] - tau) < abs(t[nearest] - tau)) nearest = i;
  }
  return nearest;
}

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
// the cut. Its successor is looked at past the kernel's reach too, and an
// observation beyond the ball that ends the data counts as a turn: else a
// window whose reach ends one sample past the ball kept a turn of up to
// twice max_turn (a spin of 0.8 rad per sample at a bandwidth of 0.66
// spacings: five samples over 3.2 rad, every fit failing). An anchor that is itself such an outlier
// (both its neighbours beyond its ball) is replaced by the next nearest observation. The anchor may
// be an observation that cross-validation holds out: the held-out window is then the full data's
// window without it, which is what leave-one-out should imitate.
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
    std::size_t anchor = nearest_observation(t, tau, begin, end);
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
    // One side: `next` steps j outward while `in_reach(j)`; the bound is
    // the first of two consecutive observations beyond the ball. The
    // second may lie past the reach (the data goes on there): the last
    // observation in reach beyond the ball is a turn when the next one is
    // beyond it too, or when the data ends there.
    const auto walk = [&](auto next, auto in_reach, auto in_data) {
      bool previous_beyond = false;
      std::size_t first = anchor;
      for (std::size_t j = next(anchor);; j = next(j)) {
        if (!in_data(j) || !in_reach(j)) {
          if (previous_beyond && (!in_data(j) || beyond(anchor, j))) {
            radius = std::min(radius, abs(t[first] - tau));
          }
          return;
        }
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
    walk([](std::size_t j) { return j + 1; }, [&](std::size_t j) { return j < end; },
         [&](std::size_t j) { return j < t.size(); });
    // Leftward, j - 1 wraps to the largest size_t past 0, where j + 1 = 0.
    walk([](std::size_t j) { return j - 1; }, [&](std::size_t j) { return j + 1 > begin; },
         [](std::size_t j) { return j + 1 > 0; });
    return radius;
  }
}

// How far from tau a wide window may reach: on each side of the
// observation nearest tau, the motion's path, the sum of the turn angles
// between consecutive observations, may grow to max_turn; the radius is
// the smaller side's distance |t_j - tau| to the first observation j past
// that (symmetric in time, as turn_radius), or `reach`. The path, unlike
// turn_radius's distance from the anchor, does not fold back past pi (a
// spin of 0.8 rad per sample is 4.0 rad from the anchor after five
// samples and 2.28 rad by the principal angle), so the motion within the
// window turns by at most 2 max_turn (below 2 pi for max_turn <= 2.5, the
// wide fit's domain). A sum of bi-invariant distances: left and right
// invariant. Noise lengthens the path, so the window can only come out
// narrower than the motion allows, never wider.
template <class G>
typename G::Scalar path_radius(const std::vector<typename G::Element>& f,
                               const std::vector<typename G::Scalar>& t, typename G::Scalar tau,
                               typename G::Scalar reach, std::size_t begin, std::size_t end,
                               typename G::Scalar max_turn) {
  using Scalar = typename G::Scalar;
  if constexpr (!has_turn_angle_v<G>) {
    return reach;
  } else {
    using std::abs;
    if (end - begin < 2) return reach;
    const std::size_t anchor = nearest_observation(t, tau, begin, end);
    Scalar radius = reach;
    Scalar path = 0;
    for (std::size_t j = anchor + 1; j < end; ++j) {
      path += G::turn_angle(G::compose(G::inverse(f[j - 1]), f[j]));
      if (path > max_turn) {
        radius = std::min(radius, abs(t[j] - tau));
        break;
      }
    }
    path = 0;
    for (std::size_t j = anchor; j > begin; --j) {
      path += G::turn_angle(G::compose(G::inverse(f[j]), f[j - 1]));
      if (path > max_turn) {
        radius = std::min(radius, abs(t[j - 1] - tau));
        break;
      }
    }
    return radius;
  }
}

// The observations with positive kernel weight at tau, ascending, cut
// where the window would turn by more than `shape.max_turn` (turn_radius);
// a `wide` shape keeps the larger of that window and path_radius's.
// `excluded` and `also_excluded`: sorted indices held out
// (cross-validation), or any index past the end for none. Returns whether
// the turn cut left out an observation the kernel would have kept.
template <class G>
bool fill_window(const std::vector<typename G::Element>& f,
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
  Scalar radius = turn_radius<G>(f, t, tau, reach, begin, end, shape.max_turn);
  if (shape.wide && radius < reach) {
    radius = std::max(radius, path_radius<G>(f, t, tau, reach, begin, end, shape.max_turn));
  }
  bool cut = false;
  for (std::size_t i = begin; i < end; ++i) {
    if (i == excluded || i == also_excluded) continue;
    const Scalar offset = t[i] - tau;
    if (radius < reach && !(std::abs(offset) < radius)) {
      cut = cut || kernel_weight(shape.kernel, offset / shape.bandwidth) > 0;
      continue;
    }
    const Scalar weight = kernel_weight(shape.kernel, offset / shape.bandwidth);
    if (!(weight > 0)) continue;
    window.observations.push_back(f[i]);
    window.covariates.push_back(t[i]);
    window.weights.push_back(weight);
  }
  return cut;
}

// The slope of a polynomial fit of a local curve's residuals (below).
template <class G>
struct PolynomialSlope {
  bool defined = false;
  int degree = 0;                                  // the degree fitted
  typename G::Tangent slope = G::Tangent::Zero();  // per covariate unit
  typename G::Scalar error_ratio = 1;              // polynomial over linear slope standard error
};

namespace local_regression_detail {

// The normal matrix M = sum w_i z_i z_i^T of the weighted least-squares
// fit on z_i = (1, u_i, ..., u_i^degree), u_i = (t_i - tau) / scale, in the
// top-left (degree + 1) block of a 4 x 4 whose unused diagonal is 1 (so
// one LU serves every degree up to 3); also sum w_i^2 z_i z_i^T.
template <class G>
struct PolynomialDesign {
  using Scalar = typename G::Scalar;
  using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
  using Vector4 = Eigen::Matrix<Scalar, 4, 1>;
  int degree;
  Scalar tau;
  Scalar scale;
  Matrix4 normal = Matrix4::Zero();
  Matrix4 squared_weights = Matrix4::Zero();

  PolynomialDesign(const LocalWindow<G>& window, Scalar tau_, int degree_)
      : degree(degree_), tau(tau_) {
    using std::abs;
    scale = std::max(abs(window.covariates.front() - tau), abs(window.covariates.back() - tau));
    for (std::size_t i = 0; i < window.covariates.size(); ++i) {
      const Vector4 z = row(window.covariates[i]);
      const Scalar w = window.weights[i];
      normal.noalias() += w * z * z.transpose();
      squared_weights.noalias() += (w * w) * z * z.transpose();
    }
    for (int k = degree + 1; k < 4; ++k)
      normal(k, k) = Scalar(1);
  }

  Vector4 row(Scalar t) const {
    const Scalar u = (t - tau) / scale;
    Vector4 z = Vector4::Zero();
    Scalar power = 1;
    for (int k = 0; k <= degree; ++k, power *= u)
      z[k] = power;
    return z;
  }
};

// The largest degree in [1, requested] whose design the window supports
// (more distinct covariates than the degree, M invertible), with M's LU;
// degree 0 when not even the line's is.
template <class G>
int supported_degree(const LocalWindow<G>& window, typename G::Scalar tau, int requested,
                     std::optional<PolynomialDesign<G>>& design,
                     std::optional<SmallLU<Eigen::Matrix<typename G::Scalar, 4, 4>>>& lu) {
  const int largest = static_cast<int>(std::min<std::size_t>(window.covariates.size(), 4)) - 1;
  for (int degree = std::min(requested, largest); degree >= 1; --degree) {
    design.emplace(window, tau, degree);
    lu.emplace(design->normal);
    if (lu->invertible()) return degree;
  }
  return 0;
}

}  // namespace local_regression_detail

// LocalRegressionOptions::velocity_degree p >= 2: with u_i = (t_i - tau) / s
// (s the window's half-width, for conditioning), z_i = (1, u_i, ..., u_i^p)
// and the normal matrix M = sum w_i z_i z_i^T, the degree-p fit of the
// residuals r_i = log(local(t_i)^{-1} f_i) has slope
// beta = (e_1^T M^{-1} sum w_i z_i r_i^T) / s, which the local regression
// adds to the geodesic's velocity. Its variance for residuals of equal
// variance is sigma^2 e_1^T M^{-1} (sum w_i^2 z_i z_i^T) M^{-1} e_1 / s^2,
// the geodesic's (a local line's) the same with z_i = (1, u_i): error_ratio
// is the square root of their ratio, by which the standard errors are
// scaled. A window with too few distinct covariates for degree p gets the
// largest degree it supports (`degree`); not defined below degree 2 or
// where the slope is not finite. `local(t)` is the local geodesic's pose
// at t (a Geodesic<G>, or the wide fit's curve).
template <class G, class Curve>
PolynomialSlope<G> polynomial_slope(const Curve& local, const LocalWindow<G>& window,
                                    typename G::Scalar tau, int degree) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using Matrix2 = Eigen::Matrix<Scalar, 2, 2>;
  using Vector4 = Eigen::Matrix<Scalar, 4, 1>;
  using std::sqrt;
  PolynomialSlope<G> result;
  if (window.covariates.size() < 3) return result;
  std::optional<local_regression_detail::PolynomialDesign<G>> design;
  std::optional<SmallLU<Eigen::Matrix<Scalar, 4, 4>>> lu;
  result.degree = local_regression_detail::supported_degree<G>(window, tau, degree, design, lu);
  if (result.degree < 2) return result;
  Eigen::Matrix<Scalar, 4, G::dof> moments = Eigen::Matrix<Scalar, 4, G::dof>::Zero();
  for (std::size_t i = 0; i < window.covariates.size(); ++i) {
    const Tangent r =
        G::log(G::compose(G::inverse(local(window.covariates[i])), window.observations[i]));
    moments.noalias() += window.weights[i] * design->row(window.covariates[i]) * r.transpose();
  }
  const Vector4 slope_row = lu->solve(Vector4::UnitY());  // M^{-1} e_1 (M symmetric)
  const Tangent slope = (moments.transpose() * slope_row) / design->scale;
  if (!slope.allFinite()) return result;
  result.defined = true;
  result.slope = slope;
  const SmallLU<Matrix2> linear(design->normal.template topLeftCorner<2, 2>());
  if (!linear.invertible()) return result;
  const Eigen::Matrix<Scalar, 2, 1> line_row = linear.solve(Eigen::Matrix<Scalar, 2, 1>::UnitY());
  const Scalar polynomial_variance = slope_row.dot(design->squared_weights * slope_row);
  const Scalar line_variance =
      line_row.dot(design->squared_weights.template topLeftCorner<2, 2>() * line_row);
  if (line_variance > 0) result.error_ratio = sqrt(polynomial_variance / line_variance);
  return result;
}

// The velocity's cross-validation target at the sorted observation i
// (LocalGeodesicRegression::held_out, HoldOut::chords): the derivative at
// t_i of the quartic through y_j = log(f_i^{-1} f_j), j = i-2 .. i+2 (so
// y_i = 0), sum_j a_j y_j with a_j = L_j'(t_i) the Lagrange basis'
// derivatives (sum_j a_j = 0). The body velocity at f_i is d/dt log(f_i^{-1}
// f(t)) at t_i, and that chart is a power series in t - t_i, so the target
// is the velocity up to O(dt^4) where the chord between i's neighbours is
// up to O(dt^2): on a spin of 20 rad/s at 25 Hz the chords alone are 0.22
// rad/s off, and cross-validation against them chose the bandwidth whose
// bias matched theirs (DESIGN.md section 5). Undefined at the two ends,
// where two of the five covariates coincide, or where f_j turns from f_i
// by more than max_turn (the chart would fold).
template <class G>
struct DerivativeTarget {
  bool defined = false;
  typename G::Tangent velocity = G::Tangent::Zero();
  typename G::Scalar weights[5] = {0, 0, 0, 0, 0};  // a_j, j = i-2 .. i+2
};

template <class G>
DerivativeTarget<G> five_point_target(const std::vector<typename G::Element>& f,
                                      const std::vector<typename G::Scalar>& t, std::size_t i,
                                      typename G::Scalar max_turn) {
  using Scalar = typename G::Scalar;
  DerivativeTarget<G> target;
  if (i < 2 || i + 2 >= t.size()) return target;
  for (std::size_t j = i - 2; j < i + 2; ++j) {
    if (!(t[j + 1] > t[j])) return target;
  }
  const typename G::Element origin_inverse = G::inverse(f[i]);
  for (int k = 0; k < 5; ++k) {
    const std::size_t j = i - 2 + static_cast<std::size_t>(k);
    Scalar weight = 0;
    if (j == i) {
      for (std::size_t m = i - 2; m <= i + 2; ++m) {
        if (m != i) weight += Scalar(1) / (t[i] - t[m]);
      }
    } else {
      Scalar numerator = 1, denominator = 1;
      for (std::size_t m = i - 2; m <= i + 2; ++m) {
        if (m == j) continue;
        denominator *= t[j] - t[m];
        if (m != i) numerator *= t[i] - t[m];
      }
      weight = numerator / denominator;
      const typename G::Element relative = G::compose(origin_inverse, f[j]);
      if constexpr (has_turn_angle_v<G>) {
        if (!(G::turn_angle(relative) <= max_turn)) return target;
      }
      target.velocity += weight * G::log(relative);
    }
    target.weights[k] = weight;
  }
  target.defined = target.velocity.allFinite();
  return target;
}

// The weights l of the observations in the local slope at tau, in the
// window's weighted least-squares fit on (1, u, ..., u^degree),
// u = t - tau, at the largest degree up to `degree` that the window
// supports (as polynomial_slope): the slope is sum_j l_j y_j, with
// l_j = w_j e_1^T M^{-1} z_j. The design is factored once; a covariate
// not in the window, or a window where not even the line's design is
// regular, has weight 0.
template <class G>
class SlopeWeights {
 public:
  using Scalar = typename G::Scalar;

  SlopeWeights(const LocalWindow<G>& window, Scalar tau, int degree) : window_(window) {
    if (window.covariates.size() < 2) return;
    std::optional<SmallLU<Eigen::Matrix<Scalar, 4, 4>>> lu;
    if (local_regression_detail::supported_degree<G>(window, tau, std::max(degree, 1), design_,
                                                     lu) < 1) {
      return;
    }
    slope_row_ = lu->solve(Eigen::Matrix<Scalar, 4, 1>::UnitY());
    regular_ = true;
  }

  Scalar operator()(Scalar covariate) const {
    if (!regular_) return Scalar(0);
    const auto& t = window_.covariates;
    const auto found = std::find(t.begin(), t.end(), covariate);
    if (found == t.end()) return Scalar(0);
    const Scalar weight = window_.weights[static_cast<std::size_t>(found - t.begin())];
    return weight * slope_row_.dot(design_->row(covariate)) / design_->scale;
  }

 private:
  const LocalWindow<G>& window_;
  std::optional<local_regression_detail::PolynomialDesign<G>> design_;
  Eigen::Matrix<Scalar, 4, 1> slope_row_ = Eigen::Matrix<Scalar, 4, 1>::Zero();
  bool regular_ = false;
};

}  // namespace bireg
