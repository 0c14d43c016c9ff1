// bireg: cumulative B-spline curves on a Lie group (docs/splines.md §1, §8,
// §9), the smooth curve beside the geodesic (geodesic.hpp).
//
// Uniform knots tau_m = tau_0 + m h, degree k in {1, 2, 3}, control points
// P_0 .. P_{M-1}, increments Omega_j = log(P_{j-1}^{-1} P_j). On segment i
// (tau_i <= t <= tau_{i+1}, i = 0 .. M-1-k), with u = (t - tau_i) / h,
//
//   T(t) = P_i A_1 ... A_k,   A_j = exp(b_j(u) Omega_{i+j})          (splines.md (1))
//
// with b_j the cumulative basis. Left translation of every control point
// by g gives g T, right translation T g (§2); inversion is respected for
// k = 1 only (§3). Degree 1 is the piecewise geodesic through the control
// points; with two control points it is the paper's geodesic.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "bireg/concept.hpp"

namespace bireg {

// The largest degree the splines support.
inline constexpr int kMaxSplineDegree = 3;

// The uniform B-spline basis of degree k on one segment at u in [0, 1]:
// the ordinary basis functions B_{i+j}(u), j = 0..k, of the control points
// alive there, the cumulative b_j = sum_{l >= j} B_{i+l}, j = 1..k (b_0 = 1),
// and their first and second derivatives in u.
template <class Scalar>
struct SplineBasis {
  std::array<Scalar, kMaxSplineDegree + 1> ordinary{};
  std::array<Scalar, kMaxSplineDegree + 1> cumulative{};
  std::array<Scalar, kMaxSplineDegree + 1> cumulative_d1{};
  std::array<Scalar, kMaxSplineDegree + 1> cumulative_d2{};
};

// Precondition: 1 <= degree <= kMaxSplineDegree.
template <class Scalar>
SplineBasis<Scalar> spline_basis(int degree, Scalar u) {
  std::array<Scalar, kMaxSplineDegree + 1> d1{}, d2{};
  SplineBasis<Scalar> basis;
  auto& b = basis.ordinary;
  const Scalar v = 1 - u;
  if (degree == 1) {
    b[0] = v, b[1] = u;
    d1[0] = -1, d1[1] = 1;
  } else if (degree == 2) {
    b[0] = v * v / 2, b[1] = (1 + 2 * u - 2 * u * u) / 2, b[2] = u * u / 2;
    d1[0] = -v, d1[1] = 1 - 2 * u, d1[2] = u;
    d2[0] = 1, d2[1] = -2, d2[2] = 1;
  } else {
    b[0] = v * v * v / 6, b[1] = (4 - 6 * u * u + 3 * u * u * u) / 6;
    b[2] = (1 + 3 * u + 3 * u * u - 3 * u * u * u) / 6, b[3] = u * u * u / 6;
    d1[0] = -v * v / 2, d1[1] = u * (Scalar(1.5) * u - 2);
    d1[2] = Scalar(0.5) + u - Scalar(1.5) * u * u, d1[3] = u * u / 2;
    d2[0] = v, d2[1] = 3 * u - 2, d2[2] = 1 - 3 * u, d2[3] = u;
  }
  // Cumulative sums from the top, so that b_k = B_k exactly and b_1 = 1 - B_0
  // keeps its small values (near u = 1) without cancellation.
  Scalar sum = 0, sum1 = 0, sum2 = 0;
  for (int j = degree; j >= 1; --j) {
    sum += b[j], sum1 += d1[j], sum2 += d2[j];
    basis.cumulative[j] = sum, basis.cumulative_d1[j] = sum1, basis.cumulative_d2[j] = sum2;
  }
  basis.cumulative[0] = 1;
  return basis;
}

// Where t lies on a uniform knot grid: the segment i (clamped to the first
// and last, so that the ends and points just outside by rounding are
// served by them) and u = (t - tau_i) / h, clamped to [0, 1].
template <class Scalar>
struct KnotPosition {
  std::size_t segment = 0;
  Scalar u = 0;
};

template <class Scalar>
KnotPosition<Scalar> knot_position(Scalar t, Scalar tau0, Scalar h, std::size_t segments) {
  using std::floor;
  const Scalar x = (t - tau0) / h;
  const Scalar last = Scalar(segments - 1);
  const Scalar i = std::clamp(floor(x), Scalar(0), last);
  return {static_cast<std::size_t>(i), std::clamp(x - i, Scalar(0), Scalar(1))};
}

// The factors of one segment's product at u (splines.md §4): the
// increments Omega_j, the factors A_j = exp(b_j Omega_j) and the suffix
// products S_j = A_{j+1} ... A_k (S_k = I), j = 1..k (index 0 unused for
// Omega and A; S_0 = A_1 ... A_k).
template <class G>
struct SegmentProduct {
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  std::array<Tangent, kMaxSplineDegree + 1> omega;
  std::array<Element, kMaxSplineDegree + 1> factor;
  std::array<Element, kMaxSplineDegree + 1> suffix;
};

template <class G>
void evaluate_segment(int degree, const typename G::Tangent* increments,
                      const SplineBasis<typename G::Scalar>& basis, SegmentProduct<G>& product) {
  product.suffix[degree] = G::identity();
  for (int j = degree; j >= 1; --j) {
    product.omega[j] = increments[j - 1];
    product.factor[j] = G::exp(basis.cumulative[j] * product.omega[j]);
    // S_{k-1} = A_k I = A_k exactly: the product with the identity is skipped.
    product.suffix[j - 1] =
        j == degree ? product.factor[j] : G::compose(product.factor[j], product.suffix[j]);
  }
}

// A cumulative B-spline in the user's covariate units. A t outside
// [t_min, t_max] is evaluated at the nearer end (value, velocity and
// acceleration alike): the curve does not extrapolate.
template <class G>
class Spline {
  static_assert(check_lie_group<G>());

 public:
  using Scalar = typename G::Scalar;
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;

  Spline() = default;

  // Preconditions: 1 <= degree <= kMaxSplineDegree, spacing > 0,
  // control_points.size() > degree, consecutive control points within the
  // principal logarithm's domain. The regression guarantees them.
  Spline(int degree, Scalar first_knot, Scalar spacing, std::vector<Element> control_points)
      : degree_(degree), tau0_(first_knot), h_(spacing), points_(std::move(control_points)) {
    increments_.clear();
    increments_.reserve(points_.size() - 1);
    for (std::size_t j = 1; j < points_.size(); ++j)
      increments_.push_back(G::log(G::compose(G::inverse(points_[j - 1]), points_[j])));
  }

  int degree() const { return degree_; }
  Scalar first_knot() const { return tau0_; }
  Scalar knot_spacing() const { return h_; }
  std::size_t segments() const { return points_.size() - std::size_t(degree_); }
  Scalar t_min() const { return tau0_; }
  Scalar t_max() const { return tau0_ + Scalar(segments()) * h_; }
  const std::vector<Element>& control_points() const { return points_; }
  // Omega_j = log(P_{j-1}^{-1} P_j), j = 1..M-1, stored at j - 1.
  const std::vector<Tangent>& increments() const { return increments_; }

  KnotPosition<Scalar> position(Scalar t) const { return knot_position(t, tau0_, h_, segments()); }

  // T(t), splines.md (1).
  Element operator()(Scalar t) const {
    const KnotPosition<Scalar> at = position(t);
    SegmentProduct<G> product;
    evaluate_segment<G>(degree_, &increments_[at.segment], spline_basis(degree_, at.u), product);
    return G::compose(points_[at.segment], product.suffix[0]);
  }

  // Body velocity T^{-1} dT/dt per covariate unit, splines.md (8):
  // (1/h) sum_j b_j' Ad_{S_j^{-1}} Omega_j.
  Tangent body_velocity(Scalar t) const {
    const KnotPosition<Scalar> at = position(t);
    const SplineBasis<Scalar> basis = spline_basis(degree_, at.u);
    SegmentProduct<G> product;
    evaluate_segment<G>(degree_, &increments_[at.segment], basis, product);
    Tangent omega = Tangent::Zero();
    for (int j = 1; j <= degree_; ++j) {
      omega +=
          basis.cumulative_d1[j] * (G::Ad(G::inverse(product.suffix[j])) * product.omega[j]).eval();
    }
    return omega / h_;
  }

  // Spatial velocity dT/dt T^{-1} = Ad_T of the body velocity.
  Tangent spatial_velocity(Scalar t) const { return G::Ad((*this)(t)) * body_velocity(t); }

  // Body acceleration d/dt (T^{-1} dT/dt), splines.md (9): with
  // V_j = Ad_{S_j^{-1}} Omega_j and omega_j = (1/h) sum_{l > j} b_l' V_l
  // (the body velocity of S_j),
  // (1/h^2) sum_j [b_j'' V_j - h b_j' ad_{omega_j} V_j].
  Tangent body_acceleration(Scalar t) const {
    const KnotPosition<Scalar> at = position(t);
    const SplineBasis<Scalar> basis = spline_basis(degree_, at.u);
    SegmentProduct<G> product;
    evaluate_segment<G>(degree_, &increments_[at.segment], basis, product);
    Tangent suffix_velocity = Tangent::Zero();  // h omega_j, built from j = k down
    Tangent acceleration = Tangent::Zero();
    for (int j = degree_; j >= 1; --j) {
      const Tangent v = G::Ad(G::inverse(product.suffix[j])) * product.omega[j];
      acceleration +=
          basis.cumulative_d2[j] * v - basis.cumulative_d1[j] * (G::ad(suffix_velocity) * v).eval();
      suffix_velocity += basis.cumulative_d1[j] * v;
    }
    return acceleration / (h_ * h_);
  }

 private:
  int degree_ = 1;
  Scalar tau0_ = 0;
  Scalar h_ = 1;
  std::vector<Element> points_ = {G::identity(), G::identity()};
  std::vector<Tangent> increments_ = {Tangent::Zero()};
};

}  // namespace bireg
