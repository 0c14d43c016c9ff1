// bireg: the equivariant Gauss-Newton step (d0, d1) = K^{-1} (v0, v1)
// (DESIGN.md section 2, "Equivariant Gauss-Newton").
//
// K is the derivative of -v with respect to left-trivialised perturbations
// of (g0, g1) where the residuals vanish:
//
//   K = [ a I   K01 ]      K01 = sum_i w_i g_{t_i}(A),   g_t(z) = psi_{1-t}(-z) / phi_t(z)
//       [ K10   c I ],     K10 = sum_i w_i g_{1-t_i}(-A),
//
// It transforms like v under left and right translations, so the step
// keeps every equivariance, and reduces to H kron I on commutative groups.
// With u = 1 - t, g_t(z) = u t E(t z) B(-u z), E(w) = (e^w - 1)/w =
// sum_n w^n/(n+1)!, B(w) = w/(e^w - 1) = sum_k b_k w^k (the identity
// e^{uz} B(uz) = B(-uz) turns DESIGN.md's u^2 e^{uz} (e^{tz} - 1)/(e^{uz} - 1)
// into this product). Hence
//
//   [z^m] g_t = sum_{n+k=m} t^{n+1}/(n+1)! (-1)^k b_k u^{k+1},
//
// summed over the observations once per fit (mixed moments, O(N) with a
// constant of kGaussNewtonOrder^2); K then costs O(kGaussNewtonOrder d^3)
// per iteration, independent of N. The same K, at the estimate, is the
// Jacobian of the estimating equations that the covariance of the fit needs
// (matrix()).
#pragma once

#include <algorithm>
#include <array>
#include <optional>
#include <utility>

#include <Eigen/Core>

#include "bireg/math/psi_series.hpp"
#include "bireg/math/small_lu.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"

namespace bireg {

// Truncation order of the power series that build K. K only shapes the
// step, not the fixed point, so it needs modest accuracy: at the largest
// spectral radius of SO(3) and SE(3) (pi) the omitted terms are below
// 2^-16 ~ 2e-5 relative, which changes the contraction factor by as much
// and nothing else; at spectral radius 1 they are below (1/(2 pi))^16 ~ 6e-14.
inline constexpr int kGaussNewtonOrder = 16;

// The mixed moments S[p][q] = sum_i w_i t_i^p u_i^q (u = 1 - t), p, q >= 1,
// p + q <= kGaussNewtonOrder + 2, of a problem's observations: what K's
// off-diagonal blocks are built from. `add` joins two chunks' moments.
template <class Scalar>
struct GaussNewtonMoments {
  static constexpr int kMaxPowers = kGaussNewtonOrder + 2;
  std::array<std::array<Scalar, kMaxPowers + 1>, kMaxPowers + 1> s{};

  // Over observations [begin, end) of `problem`, to total power `powers`.
  static GaussNewtonMoments over(const Problem<Scalar>& problem, std::size_t begin, std::size_t end,
                                 int powers = kMaxPowers) {
    GaussNewtonMoments chunk;
    std::array<Scalar, kMaxPowers + 1> t_power{}, u_power{};
    for (std::size_t i = begin; i < end; ++i) {
      const Scalar t = problem.t[i], u = 1 - t;
      t_power[0] = problem.w[i];
      u_power[0] = 1;
      for (int j = 1; j <= powers; ++j) {
        t_power[j] = t_power[j - 1] * t;
        u_power[j] = u_power[j - 1] * u;
      }
      for (int p = 1; p < powers; ++p) {
        for (int q = 1; p + q <= powers; ++q)
          chunk.s[p][q] += t_power[p] * u_power[q];
      }
    }
    return chunk;
  }
  void add(const GaussNewtonMoments& other, int powers = kMaxPowers) {
    for (int p = 1; p < powers; ++p) {
      for (int q = 1; p + q <= powers; ++q)
        s[p][q] += other.s[p][q];
    }
  }
};

template <class G>
class GaussNewtonStep {
 public:
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  static constexpr int d = G::dof;
  using KMatrix = Eigen::Matrix<Scalar, 2 * d, 2 * d>;
  using KVector = Eigen::Matrix<Scalar, 2 * d, 1>;
  static constexpr bool safeguarded = true;

  static std::optional<Rejection> refuse(const Problem<Scalar>&, Scalar) { return std::nullopt; }

  // The coefficients of K's off-diagonal blocks from the mixed moments
  // S[p][q] = sum_i w_i t_i^p u_i^q, p, q >= 1, p + q <= order + 2:
  // [z^m] sum_i w_i g_{t_i} = sum_k (-1)^k T[m][k] S[m-k+1][k+1]
  // (T[m][k] = b_k / (m-k+1)!), and the mirror block swaps p and q.
  // `order` (at most kGaussNewtonOrder) truncates the series, at a cost
  // O(N order^2) here and O(order d^3) per matrix(): a caller that knows
  // the iterates' spectral radius stays small (the local regression's warm
  // fits) takes fewer terms. Truncation changes K, hence the contraction
  // factor, never the fixed point.
  // By chunks of observations on `pool` when one is given (parallel.hpp:
  // the same sums for any thread count).
  GaussNewtonStep(const Problem<Scalar>& problem, Scalar, int order = kGaussNewtonOrder,
                  ChunkPool* pool = nullptr)
      : GaussNewtonStep(problem, moments(problem, std::clamp(order, 0, kGaussNewtonOrder), pool),
                        order) {}

  // From the moments of all observations (GaussNewtonMoments, summed over
  // chunks elsewhere: chunked_fit.hpp), to total power order + 2 at least.
  GaussNewtonStep(const Problem<Scalar>& problem, const GaussNewtonMoments<Scalar>& moments,
                  int order = kGaussNewtonOrder)
      : a_(problem.a), c_(problem.c), order_(std::clamp(order, 0, kGaussNewtonOrder)) {
    for (int m = 0; m <= order_; ++m) {
      Scalar start = 0, end = 0;
      for (int k = 0; k <= m; ++k) {
        const Scalar coefficient = static_cast<Scalar>(kPsiSeriesTable[m][k]);
        const Scalar signed_coefficient = k % 2 == 0 ? coefficient : -coefficient;
        start += signed_coefficient * moments.s[m - k + 1][k + 1];
        end += signed_coefficient * moments.s[k + 1][m - k + 1];
      }
      k01_[m] = start;
      k10_[m] = m % 2 == 0 ? end : -end;
    }
  }

  Scalar step_size() const { return 1; }

  // K at A = ad_X, the blocks by Horner's rule. Fixed-size: no allocation.
  KMatrix matrix(const AdMatrix& a) const {
    const AdMatrix identity = AdMatrix::Identity();
    AdMatrix k01 = k01_[order_] * identity;
    AdMatrix k10 = k10_[order_] * identity;
    for (int m = order_ - 1; m >= 0; --m) {
      k01 = a * k01 + k01_[m] * identity;
      k10 = a * k10 + k10_[m] * identity;
    }
    KMatrix k;
    k.template topLeftCorner<d, d>() = a_ * identity;
    k.template topRightCorner<d, d>() = k01;
    k.template bottomLeftCorner<d, d>() = k10;
    k.template bottomRightCorner<d, d>() = c_ * identity;
    return k;
  }

  std::pair<Tangent, Tangent> operator()(const State<G>& state) const {
    KVector v;
    v.template head<d>() = state.force.v0;
    v.template tail<d>() = state.force.v1;
    const KVector delta = SmallLU<KMatrix>(matrix(state.a)).solve(v);
    return {delta.template head<d>(), delta.template tail<d>()};
  }

  Scalar convergence_norm(Scalar step_norm, const State<G>&) const { return step_norm; }

 private:
  static GaussNewtonMoments<Scalar> moments(const Problem<Scalar>& problem, int order,
                                            ChunkPool* pool) {
    const int powers = order + 2;
    return reduce_chunks<GaussNewtonMoments<Scalar>>(
        problem.size(), pool,
        [&](std::size_t begin, std::size_t end) {
          return GaussNewtonMoments<Scalar>::over(problem, begin, end, powers);
        },
        [powers](GaussNewtonMoments<Scalar>& total, const GaussNewtonMoments<Scalar>& next) {
          total.add(next, powers);
        });
  }

  Scalar a_, c_;
  int order_;
  std::array<Scalar, kGaussNewtonOrder + 1> k01_{}, k10_{};
};

}  // namespace bireg
