// bireg: the differentials of a cumulative B-spline with respect to its
// control points (docs/splines.md §4-§6), per observation.
//
// For an observation on segment i at u, with j = c - i the control point's
// place in the segment's product, S_j the suffix products, b_j the
// cumulative basis and E_j = Ad_{S_j^{-1}} b_j J_r(b_j Omega_j):
//
//   D_0 = Ad_{S_0^{-1}} - E_1 J_l(Omega_1)^{-1}                       (the anchor)
//   D_j = E_j J_r(Omega_j)^{-1} - E_{j+1} J_l(Omega_{j+1})^{-1},  0 < j < k
//   D_k = E_k J_r(Omega_k)^{-1}                                         (splines.md (4))
//
// T(t) exp(D_c delta) is the curve after P_c -> P_c exp(delta). The
// estimating equations weigh the residual by W_c = B_c^2 D_c^{-1} (§6), which
// is analytic where B_c vanishes (§5). Two of them have closed forms free of
// the cancellation that D_0 suffers as B_0 -> 0 (near the end of the
// anchor's support), the paper's psi at s = B_0 and s = b_k (splines.md §4,
// degree 1):
//
//   W_0 = s J_l(Omega_1) J_l(s Omega_1)^{-1} Ad_{S_1},  s = B_0 = 1 - b_1,
//   W_k = b_k J_r(Omega_k) J_r(b_k Omega_k)^{-1};
//
// the interior ones (0 < j < k, where B_j >= 1/6 for k = 3 and >= 1/2 for
// k = 2) are inverted as they stand (for F alone, D_j x = r is solved).
#pragma once

#include <array>

#include <Eigen/Core>

#include "bireg/groups/capabilities.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/spline.hpp"

namespace bireg {

// The Jacobians of one increment Omega, shared by every observation of
// the segments it enters.
template <class G>
struct IncrementJacobians {
  using AdMatrix = typename G::AdMatrix;
  AdMatrix right;          // J_r(Omega)
  AdMatrix right_inverse;  // J_r(Omega)^{-1}
  AdMatrix left;           // J_l(Omega) = J_r(-Omega)
  AdMatrix left_inverse;   // J_l(Omega)^{-1}

  static IncrementJacobians of(const typename G::Tangent& omega) {
    const RightJacobianPair<AdMatrix> right_pair = right_jacobian_pair<G>(omega);
    const RightJacobianPair<AdMatrix> left_pair = right_jacobian_pair<G>((-omega).eval());
    return {right_pair.jacobian, right_pair.inverse, left_pair.jacobian, left_pair.inverse};
  }
};

// One covariate's segment of a spline: the knot position, the basis, the
// segment's product of exponentials, and the Jacobians of its first k
// increments (for the differentials below, away from the fit's loop,
// which shares them across observations).
template <class G>
struct SegmentAt {
  KnotPosition<typename G::Scalar> at;
  SplineBasis<typename G::Scalar> basis;
  SegmentProduct<G> product;
  std::array<IncrementJacobians<G>, kMaxSplineDegree> jacobians;
};

template <class G>
void segment_at(const Spline<G>& spline, typename G::Scalar t, SegmentAt<G>& out) {
  const int k = spline.degree();
  out.at = spline.position(t);
  out.basis = spline_basis(k, out.at.u);
  const typename G::Tangent* increments = &spline.increments()[out.at.segment];
  evaluate_segment<G>(k, increments, out.basis, out.product);
  for (int j = 0; j < k; ++j)
    out.jacobians[std::size_t(j)] = IncrementJacobians<G>::of(increments[j]);
}

// D_j and W_j, j = 0..k, for one observation.
template <class G>
struct ControlPointDifferentials {
  using AdMatrix = typename G::AdMatrix;
  std::array<AdMatrix, kMaxSplineDegree + 1> derivative;  // D_j
  std::array<AdMatrix, kMaxSplineDegree + 1> weight;      // W_j = B_j^2 D_j^{-1}
};

// The terms W_j r_i, j = 0..k, of the estimating equations for one
// observation with residual r, and D_j and W_j into `matrices` when given
// (for K and the covariance). The terms are formed from products of
// vectors where a closed form allows (W_0 r and W_k r); the interior ones
// solve D_j x = r (by LU, or for d = 3 by inverse_3x3's adjugate, which
// costs less than LU's branches). They
// are the same arithmetic whether or not the matrices are asked for, so F
// does not depend on whether K is assembled with it. `jacobians` points at
// the Jacobians of the segment's first increment (Omega_{i+1}); `product`
// is the segment's product at the observation.
template <class G>
void weighted_residuals(int degree, const SplineBasis<typename G::Scalar>& basis,
                        const SegmentProduct<G>& product, const IncrementJacobians<G>* jacobians,
                        const typename G::Tangent& residual,
                        std::array<typename G::Tangent, kMaxSplineDegree + 1>& terms,
                        ControlPointDifferentials<G>* matrices = nullptr) {
  using AdMatrix = typename G::AdMatrix;
  using Tangent = typename G::Tangent;
  const int k = degree;
  const auto& b = basis.ordinary;
  // E_j = Ad_{S_j^{-1}} b_j J_r(b_j Omega_j), and J_r(b_k Omega_k)^{-1} for
  // W_k. Degree 1 has no interior point, and its E_1 enters only D_0 and
  // D_1 (the matrices).
  std::array<AdMatrix, kMaxSplineDegree + 1> e;
  for (AdMatrix& block : e)
    block.setZero();  // e[0] is unused; GCC cannot tell that the rest are set
  AdMatrix last_inverse = AdMatrix::Identity();  // set at j = k; GCC cannot tell
  const bool need_e = k > 1 || matrices;
  for (int j = 1; j <= k; ++j) {
    const Tangent scaled = basis.cumulative[j] * product.omega[j];
    AdMatrix right;
    if (j == k) {
      const RightJacobianPair<AdMatrix> pair = right_jacobian_pair<G>(scaled);
      right = pair.jacobian;
      last_inverse = pair.inverse;
    } else {
      right = right_jacobian<G>(scaled);
    }
    if (need_e) e[j] = basis.cumulative[j] * (G::Ad(G::inverse(product.suffix[j])) * right);
  }
  const IncrementJacobians<G>& first = jacobians[0];
  const IncrementJacobians<G>& last = jacobians[k - 1];
  // W_0 r = s J_l(Omega_1) J_l(s Omega_1)^{-1} Ad_{S_1} r, s = B_0, with
  // J_l(s Omega_1)^{-1} = J_r(-s Omega_1)^{-1}.
  const AdMatrix anchor_inverse = right_jacobian_inverse<G>((-b[0] * product.omega[1]).eval());
  const AdMatrix carry = G::Ad(product.suffix[1]);
  terms[0] = b[0] * (first.left * (anchor_inverse * (carry * residual)));
  // Interior: D_j = E_j J_r(Omega_j)^{-1} - E_{j+1} J_l(Omega_{j+1})^{-1},
  // W_j r = B_j^2 D_j^{-1} r.
  for (int j = 1; j < k; ++j) {
    const AdMatrix derivative =
        e[j] * jacobians[j - 1].right_inverse - e[j + 1] * jacobians[j].left_inverse;
    const auto square = b[j] * b[j];
    if constexpr (AdMatrix::RowsAtCompileTime == 3) {
      const AdMatrix inverse = inverse_3x3(derivative);
      terms[j] = square * (inverse * residual);
      if (matrices) matrices->weight[j] = square * inverse;
    } else {
      const SmallLU<AdMatrix> lu(derivative);
      terms[j] = square * lu.solve(residual);
      if (matrices) matrices->weight[j] = square * lu.inverse();
    }
    if (matrices) matrices->derivative[j] = derivative;
  }
  // W_k r = b_k J_r(Omega_k) J_r(b_k Omega_k)^{-1} r.
  terms[k] = b[k] * (last.right * (last_inverse * residual));
  if (!matrices) return;
  matrices->derivative[0] = G::Ad(G::inverse(product.suffix[0])) - e[1] * first.left_inverse;
  matrices->derivative[k] = e[k] * last.right_inverse;
  matrices->weight[0] = b[0] * (first.left * anchor_inverse) * carry;
  matrices->weight[k] = b[k] * (last.right * last_inverse);
}

// D_j and W_j, j = 0..k, for one observation (weighted_residuals' matrices).
template <class G>
void control_point_differentials(int degree, const SplineBasis<typename G::Scalar>& basis,
                                 const SegmentProduct<G>& product,
                                 const IncrementJacobians<G>* jacobians,
                                 ControlPointDifferentials<G>& out) {
  std::array<typename G::Tangent, kMaxSplineDegree + 1> unused;
  weighted_residuals<G>(degree, basis, product, jacobians, G::Tangent::Zero(), unused, &out);
}

// The body velocity's differential in the segment's control points
// (splines.md (11)): omega(t) after P_{i+j} -> P_{i+j} exp(delta) is
// omega(t) + V_j delta + O(delta^2), per covariate unit for knot spacing h.
// With E_m as above and y_j = Ad_{S_j^{-1}} Omega_j,
//
//   G_m = b_m' Ad_{S_m^{-1}} + ad(sum_{j < m} b_j' y_j) E_m,
//   V_j = ([j >= 1] G_j J_r(Omega_j)^{-1} - [j < k] G_{j+1} J_l(Omega_{j+1})^{-1}) / h.
template <class G>
void velocity_differentials(int degree, typename G::Scalar h,
                            const SplineBasis<typename G::Scalar>& basis,
                            const SegmentProduct<G>& product,
                            const IncrementJacobians<G>* jacobians,
                            std::array<typename G::AdMatrix, kMaxSplineDegree + 1>& out) {
  using AdMatrix = typename G::AdMatrix;
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  const int k = degree;
  std::array<AdMatrix, kMaxSplineDegree + 1> g;
  for (AdMatrix& block : g)
    block.setZero();                  // g[0] is unused
  Tangent earlier = Tangent::Zero();  // sum_{j < m} b_j' y_j
  for (int m = 1; m <= k; ++m) {
    const AdMatrix carry = G::Ad(G::inverse(product.suffix[m]));
    const Scalar b = basis.cumulative[m];
    const AdMatrix e = b * (carry * right_jacobian<G>((b * product.omega[m]).eval()));
    g[m] = basis.cumulative_d1[m] * carry + G::ad(earlier) * e;
    earlier += basis.cumulative_d1[m] * (carry * product.omega[m]);
  }
  for (int j = 0; j <= k; ++j) {
    AdMatrix v = AdMatrix::Zero();
    if (j >= 1) v += g[j] * jacobians[j - 1].right_inverse;
    if (j < k) v -= g[j + 1] * jacobians[j].left_inverse;
    out[std::size_t(j)] = v / h;
  }
}

}  // namespace bireg
