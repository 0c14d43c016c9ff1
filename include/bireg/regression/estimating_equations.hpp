// bireg: the estimating equations, i.e. the net force (v0, v1) of the
// paper's Definition 2.1 and Section 2.2 in left-trivialised coordinates
// (DESIGN.md section 2): with X = log(g0^{-1} g1), A = ad_X, the residuals
// r_i = log(b_i^{-1} f_i) at the predictions b_i = g0 exp(t_i X),
//
//   v0 = sum_i w_i psi_{1 - t_i}(-A) r_i,   v1 = sum_i w_i psi_{t_i}(A) r_i,
//
// psi_s the weighted inverse differential of Lemma 3.1 and Corollary 3.2,
// evaluated by its series (math/psi_series.hpp) or in the group's closed
// form (groups/capabilities.hpp). The bi-invariant estimator is the zero of
// (v0, v1).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/psi_series.hpp"
#include "bireg/regression/batched_force.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"
#include "bireg/regression/status.hpp"

namespace bireg {

// How psi is evaluated (from the options).
struct PsiEvaluation {
  Method method = Method::exact;
  int series_order = 0;  // for Method::series; 0 = adaptive
  int max_series_order = kMaxSeriesOrder;
  bool batched = true;  // the batched kernels where built (batched_force.hpp)
};

template <class G>
struct Force {
  typename G::Tangent v0, v1;
  typename G::Scalar norm() const {
    using std::sqrt;
    return sqrt(v0.squaredNorm() + v1.squaredNorm());
  }
};

// Everything the iteration needs at one pair of endpoints.
template <class G>
struct State {
  typename G::Element g0, g1;
  typename G::Tangent x;   // log(g0^{-1} g1)
  typename G::AdMatrix a;  // ad_x
  int order = 0;           // series order used (0: closed form)
  typename G::Scalar truncation = 0;
  Force<G> force;
  bool series_converges = true;  // spectral radius of ad_x below 2 pi

  // Finite force inside the series' disc: a state the iteration may use.
  bool usable() const { return series_converges && force.v0.allFinite() && force.v1.allFinite(); }
};

// Where the force's chunk sums run (parallel.hpp): a pool, or none for the
// calling thread alone, and the per-chunk partial sums a pool writes,
// sized once per fit so that no evaluation allocates; and the second
// residual buffer the iteration evaluates trial steps into
// (iteration.hpp), kept here so that a workspace reused across fits
// allocates it once.
template <class G>
struct ForceWorkspace {
  static constexpr std::size_t kMomentsPerChunk = 2 * (kMaxSeriesOrder + 2);
  ChunkPool* pool = nullptr;
  std::vector<typename G::Tangent> partials;
  std::vector<typename G::Tangent> trial_residuals;

  ForceWorkspace() = default;
  ForceWorkspace(ChunkPool* chunk_pool, std::size_t n) : pool(chunk_pool) {
    if (pool) partials.resize(chunk_count(n) * kMomentsPerChunk);
  }
};

// r_i = log(b_i^{-1} f_i), the residual of one observation at the
// prediction b_i = g0 exp(t_i X), with b_i^{-1} = exp(-t_i X) g0^{-1}.
template <class G>
typename G::Tangent residual(const typename G::Element& g0_inverse, const typename G::Tangent& x,
                             typename G::Scalar t, const typename G::Element& f) {
  return G::log(G::compose(G::exp(-t * x), G::compose(g0_inverse, f)));
}

namespace estimating_detail {

// Moment form of the series: psi_s(z) = sum_m (-1)^m sum_k T[m][k] s^{k+1} z^m,
// and A is the same for every observation, so
//   v1 = sum_m (-A)^m u_m,  u_m = sum_k T[m][k] P_{k+1},  P_j = sum_i w_i t_i^j r_i,
//   v0 = sum_m   A^m z_m,   z_m = sum_k T[m][k] Q_{k+1},  Q_j = sum_i w_i (1 - t_i)^j r_i
// (psi_{1-t}(-A) flips the sign of z and of (-1)^m together). Each
// observation then costs one exp, one log, two compositions and
// 2 (M + 1) vector updates; the M matrix-vector products of Horner's rule
// are paid once per iteration, not once per observation.
template <class G, class Observations>
Force<G> series_force(const Observations& observations, const Problem<typename G::Scalar>& problem,
                      const typename G::Element& g0, const typename G::Tangent& x,
                      const typename G::AdMatrix& a, int order,
                      std::vector<typename G::Tangent>& residuals, ForceWorkspace<G>* workspace) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using Moments = std::array<Tangent, kMaxSeriesOrder + 2>;
  const typename G::Element g0_inverse = G::inverse(g0);
  // P_j, Q_j (j = 1 .. order + 1) of observations [begin, end), from zero.
  const auto accumulate = [&](std::size_t begin, std::size_t end, Tangent* p, Tangent* q) {
    for (int j = 1; j <= order + 1; ++j) {
      p[j].setZero();
      q[j].setZero();
    }
    for (std::size_t i = begin; i < end; ++i) {
      const Scalar t = problem.t[i];
      const Tangent r = residual<G>(g0_inverse, x, t, observations[i]);
      residuals[i] = r;
      Scalar t_power = problem.w[i];
      Scalar one_minus_t_power = problem.w[i];
      for (int j = 1; j <= order + 1; ++j) {
        t_power *= t;
        one_minus_t_power *= 1 - t;
        p[j] += t_power * r;
        q[j] += one_minus_t_power * r;
      }
    }
  };
  Moments p, q;
  const std::size_t n = observations.size();
  const std::size_t chunks = chunk_count(n);
  if (chunks <= 1) {
    accumulate(0, n, p.data(), q.data());
  } else {
    // Chunk partial sums added in chunk order (parallel.hpp): the same
    // arithmetic whether a pool computed them or this loop did.
    const auto chunk_end = [&](std::size_t chunk) { return std::min(n, (chunk + 1) * kChunkSize); };
    const auto combine = [&](const Tangent* chunk_p, const Tangent* chunk_q) {
      for (int j = 1; j <= order + 1; ++j) {
        p[j] += chunk_p[j];
        q[j] += chunk_q[j];
      }
    };
    for (int j = 1; j <= order + 1; ++j) {
      p[j].setZero();
      q[j].setZero();
    }
    if (workspace && workspace->pool) {
      constexpr std::size_t stride = ForceWorkspace<G>::kMomentsPerChunk;
      Tangent* partials = workspace->partials.data();
      workspace->pool->run(chunks, [&](std::size_t chunk) {
        Tangent* chunk_p = partials + chunk * stride;
        accumulate(chunk * kChunkSize, chunk_end(chunk), chunk_p, chunk_p + stride / 2);
      });
      for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
        combine(partials + chunk * stride, partials + chunk * stride + stride / 2);
      }
    } else {
      Moments chunk_p, chunk_q;
      for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
        accumulate(chunk * kChunkSize, chunk_end(chunk), chunk_p.data(), chunk_q.data());
        combine(chunk_p.data(), chunk_q.data());
      }
    }
  }
  const auto series_term = [&](const std::array<Tangent, kMaxSeriesOrder + 2>& moments, int m) {
    Tangent term = Tangent::Zero();
    for (int k = 0; k <= m; ++k)
      term += static_cast<Scalar>(kPsiSeriesTable[m][k]) * moments[k + 1];
    return term;
  };
  Force<G> force{series_term(q, order), series_term(p, order)};
  for (int m = order - 1; m >= 0; --m) {  // Horner's rule
    force.v0 = a * force.v0 + series_term(q, m);
    force.v1 = -(a * force.v1) + series_term(p, m);
  }
  return force;
}

// The closed form: psi_s(-A) is psi_s of ad_{-X}. Both directions use the
// angles t theta/2 and (1 - t) theta/2 with their roles swapped, one sin/cos
// pair evaluated per observation and the other derived from it
// (psi_closed_form::half_angle_pair). Where G's closed form is a sum of
// coefficients times fixed maps (ClosedFormPsi::kTerms; not Sim(3)), the
// weighted residuals are summed per coefficient and the maps applied once
// per chunk (psi_closed_form::apply_by_coefficients); otherwise each
// observation's psi_s r is evaluated. With batched, SO(3)'s and SE(3)'s loops run
// across observations in SIMD lanes where this build has the kernel
// (batched_force.hpp).
template <class G, class Observations>
Force<G> closed_form_force(const Observations& observations,
                           const Problem<typename G::Scalar>& problem,
                           const typename G::Element& g0, const typename G::Tangent& x,
                           std::vector<typename G::Tangent>& residuals,
                           ForceWorkspace<G>* workspace, [[maybe_unused]] bool batched) {
  using Scalar = typename G::Scalar;
  using Tangent = typename G::Tangent;
  using Psi = typename G::ClosedFormPsi;
  using SinCos = psi_closed_form::SinCos<Scalar>;
  const auto forward = Psi::prepare(x);
  const auto backward = Psi::prepare(-x);
  const Scalar theta = forward.theta;
  const SinCos half = SinCos::of(theta / 2);
  const typename G::Element g0_inverse = G::inverse(g0);
  // The residual r_i (see residual()), with exp(-t x) from the half-angle
  // pair where G's closed form provides it.
  const auto residual_at = [&](std::size_t i, Scalar t, const SinCos& t_half) {
    if constexpr (provides_v<Psi, capability_detail::closed_form_exp>) {
      return G::log(
          G::compose(Psi::exp(backward, t, t_half), G::compose(g0_inverse, observations[i])));
    } else {
      static_cast<void>(t_half);
      return residual<G>(g0_inverse, x, t, observations[i]);
    }
  };
  // The force of observations [begin, end), from zero.
  const auto accumulate = [&](std::size_t begin, std::size_t end) {
    if constexpr (provides_v<Psi, capability_detail::closed_form_terms>) {
#if BIREG_HAS_BATCHED_FORCE
      if constexpr (batched::has_closed_form_sums_v<G>) {
        if (batched) {
          const auto sums = batched::closed_form_sums(G{}, observations, problem.t.data(),
                                                      problem.w.data(), begin, end, g0_inverse,
                                                      forward, backward, residuals.data());
          return Force<G>{Psi::combine(backward, sums.v0_sums),
                          Psi::combine(forward, sums.v1_sums)};
        }
      }
#endif
      // sums[k] = sum_i w_i c_k(s_i) r_i for each direction.
      std::array<Tangent, Psi::kTerms> v0_sums, v1_sums;
      for (int k = 0; k < Psi::kTerms; ++k) {
        v0_sums[k].setZero();
        v1_sums[k].setZero();
      }
      for (std::size_t i = begin; i < end; ++i) {
        const Scalar t = problem.t[i], w = problem.w[i];
        const auto angles = psi_closed_form::half_angle_pair(theta, half, t);
        const Tangent r = residual_at(i, t, angles.s_half);
        residuals[i] = r;
        const auto c0 = Psi::coefficients(backward, 1 - t, angles.u_half, angles.s_half);
        const auto c1 = Psi::coefficients(forward, t, angles.s_half, angles.u_half);
        for (int k = 0; k < Psi::kTerms; ++k) {
          v0_sums[k] += (w * c0[k]) * r;
          v1_sums[k] += (w * c1[k]) * r;
        }
      }
      return Force<G>{Psi::combine(backward, v0_sums), Psi::combine(forward, v1_sums)};
    } else {
      Force<G> force{Tangent::Zero(), Tangent::Zero()};
      for (std::size_t i = begin; i < end; ++i) {
        const Scalar t = problem.t[i], w = problem.w[i];
        const auto angles = psi_closed_form::half_angle_pair(theta, half, t);
        const Tangent r = residual_at(i, t, angles.s_half);
        residuals[i] = r;
        force.v0 += w * Psi::apply(backward, 1 - t, angles.u_half, angles.s_half, r);
        force.v1 += w * Psi::apply(forward, t, angles.s_half, angles.u_half, r);
      }
      return force;
    }
  };
  const std::size_t n = observations.size();
  const std::size_t chunks = chunk_count(n);
  if (chunks <= 1) return accumulate(0, n);
  // Chunk partial sums added in chunk order (parallel.hpp).
  const auto chunk_end = [&](std::size_t chunk) { return std::min(n, (chunk + 1) * kChunkSize); };
  Force<G> force{Tangent::Zero(), Tangent::Zero()};
  if (workspace && workspace->pool) {
    Tangent* partials = workspace->partials.data();
    constexpr std::size_t stride = ForceWorkspace<G>::kMomentsPerChunk;
    workspace->pool->run(chunks, [&](std::size_t chunk) {
      const Force<G> part = accumulate(chunk * kChunkSize, chunk_end(chunk));
      partials[chunk * stride] = part.v0;
      partials[chunk * stride + 1] = part.v1;
    });
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      force.v0 += partials[chunk * stride];
      force.v1 += partials[chunk * stride + 1];
    }
  } else {
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      const Force<G> part = accumulate(chunk * kChunkSize, chunk_end(chunk));
      force.v0 += part.v0;
      force.v1 += part.v1;
    }
  }
  return force;
}

}  // namespace estimating_detail

// The state at (g0, g1) without its force: x, ad_x, whether the series
// converges and, where the force is evaluated by the series, its order.
// closed_form says the force is evaluated in G's closed form. Every
// evaluation of the force starts here, so sums over separate chunks of
// the observations (chunked_fit.hpp) are made with the same choices.
template <class G>
State<G> prepare_state(const PsiEvaluation& psi, const typename G::Element& g0,
                       const typename G::Element& g1, bool& closed_form) {
  using Scalar = typename G::Scalar;
  constexpr Scalar kTwoPi = Scalar(6.283185307179586476925286766559L);
  State<G> state;
  state.g0 = g0;
  state.g1 = g1;
  state.x = log_at<G>(g0, g1);
  state.a = G::ad(state.x);
  closed_form = false;
  if (!(ad_spectral_radius<G>(state.x) < kTwoPi)) {
    state.series_converges = false;
    return state;
  }
  if constexpr (has_closed_form_psi_v<G>) {
    if (psi.method == Method::exact && uses_closed_form_psi<G>(state.x)) {
      closed_form = true;
      return state;
    }
  }
  if (psi.method == Method::series && psi.series_order > 0) {
    state.order = psi.series_order;
  } else {
    std::tie(state.order, state.truncation) = adaptive_series_order(
        state.a, std::numeric_limits<Scalar>::epsilon(), psi.max_series_order);
  }
  return state;
}

// Evaluates x, ad_x, the series order and the force at (g0, g1), writing
// the residuals there into `residuals` (sized N). Outside the series' disc
// (spectral radius of ad_x at or above 2 pi) only x and ad_x are set.
template <class G, class Observations>
State<G> evaluate(const Observations& observations, const Problem<typename G::Scalar>& problem,
                  const PsiEvaluation& psi, const typename G::Element& g0,
                  const typename G::Element& g1, std::vector<typename G::Tangent>& residuals,
                  ForceWorkspace<G>* workspace = nullptr) {
  bool closed_form = false;
  State<G> state = prepare_state<G>(psi, g0, g1, closed_form);
  if (!state.series_converges) return state;
  if constexpr (has_closed_form_psi_v<G>) {
    if (closed_form) {
      state.force = estimating_detail::closed_form_force<G>(observations, problem, g0, state.x,
                                                            residuals, workspace, psi.batched);
      return state;
    }
  }
  state.force = estimating_detail::series_force<G>(observations, problem, g0, state.x, state.a,
                                                   state.order, residuals, workspace);
  return state;
}

// The residuals at a state's endpoints alone, into `residuals` (sized N):
// for a state outside the series' disc, where evaluate() computed none.
template <class G, class Observations>
void residuals_alone(const Observations& observations, const Problem<typename G::Scalar>& problem,
                     const State<G>& state, std::vector<typename G::Tangent>& residuals) {
  const std::size_t n = observations.size();
  const typename G::Element g0_inverse = G::inverse(state.g0);
  for (std::size_t i = 0; i < n; ++i)
    residuals[i] = residual<G>(g0_inverse, state.x, problem.t[i], observations[i]);
}

}  // namespace bireg
