// Two SIMD libraries on SE(3)'s batched closed-form force (issue "Speed
// toward the hardware": measure two candidate libraries on the SE(3)
// kernel, choose, and record the comparison and the reasons).
//
// regression/batched_force.hpp writes the kernel with Google Highway. This
// file writes the same kernel with xsimd 8.1 (Debian 12's libxsimd-dev; its
// hadd is reduce_add in later releases, which have since removed hadd),
// the same arithmetic step for step: the half angles (the smaller one by
// sin and cos, the other by the difference formulas), E = exp(-t X) by
// Rodrigues with the (x - sin x)/x^3 series, M = E g0^{-1} f, the rotation
// log's first branch with atan, SE(3) log's translation series, the group's
// own log on lanes whose trace is at most 1, the five psi coefficients of
// each direction and the 5 x 6 per-direction sums, reduced across lanes at
// the end of each chunk of kChunkSize observations. Only the library calls
// differ (and where xsimd offers sincos, one call for both).
//
//   BM_ForceSE3/kernel:K/n:N  one evaluation of SE(3)'s force at the fitted
//       endpoints of bench_batched's BM_Force data (a geodesic of length 1,
//       noise 0.1), N observations; time_per_obs = time / N.
//       K = 0 scalar (closed_form_force, batched = false)
//           1 Highway (closed_form_force, batched = true)
//           2 xsimd, sin and cos of the half angle by one sincos call
//           3 xsimd, sin and cos by two calls (as Highway, which has no
//             vector sincos)
//
// Before timing, main() checks each kernel against the scalar loop on the
// benchmark's data and on data whose residuals turn up to pi (the lanes of
// the group's own log; t = 0 and 1 exactly; N not a multiple of the lane
// count), and aborts if one is outside: every residual entry within
// 64 eps (1 + |w| / sin|w|) (4 + |r|) of the scalar one (w its rotation
// part; tests/test_batched_force.cpp's bound); the force within 1e-12 of
// the size of its terms (sum_i w_i |c_k(t_i)| |r_i| combined as the force
// is) and, on the second data, within 1e-12 of the scalar force's norm. At
// a fit's answer the force is what is left of terms that cancel to about
// 1e-13 of their size, so relative to its own norm the comparison measures
// the order of addition alone (2e-5 to 3e-4 there, for Highway and xsimd
// alike): that figure is printed, not required.
//
// bench/CMakeLists.txt builds it where xsimd is found
// (bench_simd_libraries_avx2, _avx512); by hand, one binary per
// instruction set (static dispatch from -march for both libraries), from
// the repository's root:
//   g++ -std=c++17 -O3 -DNDEBUG -march=skylake-avx512 -DBIREG_USE_HIGHWAY
//       -Iinclude -isystem /usr/include/eigen3 bench/bench_simd_libraries.cpp
//       -lbenchmark -lpthread
// and the same with -march=haswell -maes for AVX2.
// BIREG_BENCH_SIMD_KERNEL_ONLY leaves out the benchmarks and the checks
// (the xsimd kernel alone, to time its compilation).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/small_angle.hpp"
#include "bireg/regression/batched_force.hpp"
#include "bireg/regression/estimating_equations.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/regression/problem.hpp"

#ifndef BIREG_BENCH_SIMD_KERNEL_ONLY
#include <map>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include "bireg/regression.hpp"
#endif

// GCC 12's AVX-512 intrinsics initialise their "undefined" operand from
// itself (_mm512_undefined_pd: __m512d __Y = __Y), which -Wuninitialized
// and -Wmaybe-uninitialized report wherever xsimd's nearbyint, floor, sqrt
// and hadd inline them. Highway silences the two in its own x86 headers
// (its issue 710); xsimd 8.1 does not, so they are silenced here, for
// xsimd and its kernel alone.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <xsimd/xsimd.hpp>

namespace xsimd_kernel {

using bireg::SE3d;
using Element = SE3d::Element;
using Tangent = SE3d::Tangent;
using Prepared = SE3d::ClosedFormPsi::Prepared;

// The kernel on one instruction set Arch (xsimd::default_arch: the best
// that -march enables). kSincos: the half angle's sin and cos by one call.
template <class Arch, bool kSincos>
struct Kernel {
  using V = xsimd::batch<double, Arch>;
  using Mask = xsimd::batch_bool<double, Arch>;
  using Index = xsimd::batch<std::int64_t, Arch>;
  static constexpr std::size_t kLanes = V::size;

  // small_angle::polynomial's four chains, lane-wise.
  template <std::size_t Count>
  static V polynomial(const std::array<double, Count>& coefficients, V x) {
    constexpr std::size_t kChains = 4;
    constexpr std::size_t kRows = (Count + kChains - 1) / kChains;
    const V x2 = x * x;
    const V x4 = x2 * x2;
    V chain[kChains] = {V(0.0), V(0.0), V(0.0), V(0.0)};
    for (std::size_t row = kRows; row-- > 0;) {
      for (std::size_t j = 0; j < kChains; ++j) {
        const std::size_t k = row * kChains + j;
        if (k < Count) chain[j] = chain[j] * x4 + V(coefficients[k]);
      }
    }
    return chain[0] + x * (chain[1] + x * (chain[2] + x * chain[3]));
  }

  // One direction's angle quantities, broadcast.
  struct AngleVectors {
    V theta, half_sin, half_cos, cot_half, inverse, inverse2, inverse3, inverse4;
    explicit AngleVectors(const bireg::psi_closed_form::Angle<double>& a)
        : theta(a.theta),
          half_sin(a.half.sin),
          half_cos(a.half.cos),
          cot_half(a.cot_half),
          inverse(a.inverse),
          inverse2(a.inverse2),
          inverse3(a.inverse3),
          inverse4(a.inverse4) {}
  };

  struct SinCos {
    V sin, cos;
  };
  static SinCos sin_cos(V angle) {
    if constexpr (kSincos) {
      const std::pair<V, V> both = xsimd::sincos(angle);
      return {both.first, both.second};
    } else {
      return {xsimd::sin(angle), xsimd::cos(angle)};
    }
  }

  // sin and cos of t theta/2 and (1 - t) theta/2 (half_angle_pair).
  struct HalfAngles {
    V s_sin, s_cos, u_sin, u_cos;
  };
  static HalfAngles half_angles(const AngleVectors& a, bool within_pi, V t, V u) {
    const V half(0.5);
    if (!within_pi) {
      const SinCos s = sin_cos(t * a.theta * half), v = sin_cos(u * a.theta * half);
      return {s.sin, s.cos, v.sin, v.cos};
    }
    const Mask s_is_smaller = t <= u;
    const SinCos smaller = sin_cos(xsimd::select(s_is_smaller, t, u) * a.theta * half);
    const V larger_sin = a.half_sin * smaller.cos - a.half_cos * smaller.sin;
    const V larger_cos = a.half_cos * smaller.cos + a.half_sin * smaller.sin;
    return {xsimd::select(s_is_smaller, smaller.sin, larger_sin),
            xsimd::select(s_is_smaller, smaller.cos, larger_cos),
            xsimd::select(s_is_smaller, larger_sin, smaller.sin),
            xsimd::select(s_is_smaller, larger_cos, smaller.cos)};
  }

  // A 3-vector broadcast, with its squares.
  struct UniformVector {
    V v[3], square[3];
    explicit UniformVector(const Eigen::Vector3d& x) {
      for (int k = 0; k < 3; ++k) {
        v[k] = V(x[k]);
        square[k] = V(x[k] * x[k]);
      }
    }
  };

  // I + a W + b W^2, W = hat(omega), as SO3::rodrigues; e[3 row + col].
  static void rodrigues(const UniformVector& omega, V a, V b, V e[9]) {
    const V one(1.0);
    const V *o = omega.v, *sq = omega.square;
    const V b01 = b * o[0] * o[1], b02 = b * o[0] * o[2], b12 = b * o[1] * o[2];
    const V a0 = a * o[0], a1 = a * o[1], a2 = a * o[2];
    e[0] = one - b * (sq[1] + sq[2]);
    e[1] = b01 - a2;
    e[2] = b02 + a1;
    e[3] = b01 + a2;
    e[4] = one - b * (sq[0] + sq[2]);
    e[5] = b12 - a0;
    e[6] = b02 - a1;
    e[7] = b12 + a0;
    e[8] = one - b * (sq[0] + sq[1]);
  }

  // out = a b (3 x 3 blocks, row-major).
  static void multiply(const V a[9], const V b[9], V out[9]) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  }

  // out = a v + shift.
  static void transform(const V a[9], const V v[3], const V shift[3], V out[3]) {
    for (int r = 0; r < 3; ++r)
      out[r] = a[3 * r] * v[0] + a[3 * r + 1] * v[1] + a[3 * r + 2] * v[2] + shift[r];
  }

  static void cross(const V a[3], const V b[3], V out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  }

  // SO3::log's first branch (trace > 1, the returned mask):
  // omega = (2 / (1 + trace)) (atan(y) / y) d, d = vee(m - m^T),
  // y = |d| / (1 + trace).
  static Mask rotation_log(const V m[9], V omega[3]) {
    const V one(1.0), two(2.0);
    const V trace = m[0] + m[4] + m[8];
    const V d0 = m[7] - m[5], d1 = m[2] - m[6], d2 = m[3] - m[1];
    const V one_plus_trace = one + trace;
    const V y = xsimd::sqrt(d0 * d0 + d1 * d1 + d2 * d2) / one_plus_trace;
    const V tiny(bireg::small_angle::tiny_angle<double>());
    const V third(1.0 / 3.0);
    const V atan_over_y =
        xsimd::select(xsimd::abs(y) < tiny, one - y * y * third, xsimd::atan(y) / y);
    const V factor = two / one_plus_trace * atan_over_y;
    omega[0] = factor * d0;
    omega[1] = factor * d1;
    omega[2] = factor * d2;
    return trace > one;
  }

  // psi_closed_form::psi_coefficients lane-wise, zero where s = 0.
  struct Coefficients {
    V f1, f2, g1, g2;
  };
  static Coefficients psi_coefficients(const AngleVectors& a, V s, V sin_s, V cos_s, V sin_u,
                                       V cos_u) {
    const V zero(0.0), one(1.0), half(0.5), two(2.0);
    const Mask nonzero = s != zero;
    const V inverse_s_sin = one / sin_s;
    const V modulus = s * s * a.half_sin * inverse_s_sin;
    const V alpha = modulus * cos_u, beta = (-modulus) * sin_u;
    const V p = (s - one) * half;
    const V q = (-(a.cot_half - s * cos_s * inverse_s_sin)) * half;
    const V alpha_d = alpha * p - beta * q, beta_d = alpha * q + beta * p;
    Coefficients c;
    c.f1 = xsimd::select(nonzero, beta * a.inverse, zero);
    c.f2 = xsimd::select(nonzero, (s - alpha) * a.inverse2, zero);
    c.g1 = xsimd::select(nonzero, (a.theta * alpha_d - beta) * a.inverse3, zero);
    c.g2 = xsimd::select(nonzero, (a.theta * beta_d - two * (s - alpha)) * a.inverse4, zero);
    return c;
  }

  // Entry e of the 12 read (rotation row-major, then translation) sits at
  // column-major offset col * 4 + row of a 4 x 4 element.
  static constexpr int entry_offset(int e) { return e < 9 ? (e % 3) * 4 + e / 3 : 12 + (e - 9); }

  // Observations [i0, i0 + count) as lanes; lanes beyond count hold the
  // identity at t = 1/2 with weight 0.
  static void load_block(const std::vector<Element>& observations, const double* t_values,
                         const double* w_values, std::size_t i0, std::size_t count,
                         const Index& offsets, V& t, V& w, V (&entries)[12]) {
    static_assert(sizeof(Element) == 16 * sizeof(double) && !(Element::Flags & Eigen::RowMajorBit));
    if (count == kLanes) {
      const double* base = observations.data()[i0].data();
      // Gathers do not start the hardware prefetcher: the block two ahead by
      // hand, as Highway's kernel does (xsimd has no prefetch of its own).
#ifdef __GNUC__
      if (i0 + 3 * kLanes <= observations.size()) {
        const char* ahead = reinterpret_cast<const char*>(base + 2 * kLanes * 16);
        for (std::size_t byte = 0; byte < kLanes * sizeof(Element); byte += 64)
          __builtin_prefetch(ahead + byte);
      }
#endif
      t = V::load_unaligned(t_values + i0);
      w = V::load_unaligned(w_values + i0);
      // xsimd 8.1's gather of doubles never reaches vgatherqpd (its AVX2 and
      // AVX-512 overloads have one template parameter, and batch::gather
      // names two): it inserts lane by lane. The intrinsics instead changed
      // nothing measurable here.
      for (int e = 0; e < 12; ++e)
        entries[e] = V::gather(base + entry_offset(e), offsets);
      return;
    }
    alignas(64) double t_lanes[kLanes], w_lanes[kLanes], lanes[12][kLanes];
    for (std::size_t l = 0; l < kLanes; ++l) {
      const bool real = l < count;
      t_lanes[l] = real ? t_values[i0 + l] : 0.5;
      w_lanes[l] = real ? w_values[i0 + l] : 0.0;
      for (int e = 0; e < 12; ++e) {
        const int row = e < 9 ? e / 3 : e - 9, col = e < 9 ? e % 3 : 3;
        lanes[e][l] = real ? observations[i0 + l](row, col) : (row == col ? 1.0 : 0.0);
      }
    }
    t = V::load_aligned(t_lanes);
    w = V::load_aligned(w_lanes);
    for (int e = 0; e < 12; ++e)
      entries[e] = V::load_aligned(lanes[e]);
  }

  // sums[k][j] += (w c_k) r_j.
  static void accumulate(V (&sums)[5][6], V w, const V (&c)[5], const V (&r)[6]) {
    for (int k = 0; k < 5; ++k) {
      const V wc = w * c[k];
      for (int j = 0; j < 6; ++j)
        sums[k][j] = xsimd::fma(wc, r[j], sums[k][j]);
    }
  }

  // batched::closed_form_sums for SE(3): the sums of observations
  // [begin, end), writing each residual.
  static bireg::batched::ForceSums<SE3d> closed_form_sums(
      const std::vector<Element>& observations, const double* t_values, const double* w_values,
      std::size_t begin, std::size_t end, const Element& g0_inverse, const Prepared& forward,
      const Prepared& backward, Tangent* residuals) {
    constexpr double kPi = 3.141592653589793238462643383279502884;
    constexpr const auto& kExpSeries = bireg::small_angle::kXMinusSinSeries<double>;
    static constexpr auto kLogSeries = bireg::small_angle::in_precision<double>(
        bireg::small_angle::detail::one_minus_half_cot_series<20>());

    const AngleVectors angle(forward.angle);
    const bool within_pi = forward.theta <= kPi;
    const V zero(0.0), one(1.0), two(2.0), half(0.5);
    const UniformVector omega_back(backward.omega);
    V rho_back[3], w_rho_back[3], w_w_rho_back[3];
    for (int k = 0; k < 3; ++k) {
      rho_back[k] = V(backward.rho[k]);
      w_rho_back[k] = V(backward.w_rho[k]);
      w_w_rho_back[k] = V(backward.w_w_rho[k]);
    }
    const V omega_dot_rho_forward(forward.omega_dot_rho);
    const V omega_dot_rho_backward(backward.omega_dot_rho);
    V g[9], g_shift[3];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        g[3 * r + c] = V(g0_inverse(r, c));
      g_shift[r] = V(g0_inverse(r, 3));
    }
    alignas(64) std::int64_t offset_values[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l)
      offset_values[l] = static_cast<std::int64_t>(16 * l);
    const Index offsets = Index::load_aligned(offset_values);

    V v0[5][6], v1[5][6];  // [term][component]
    for (int k = 0; k < 5; ++k)
      for (int j = 0; j < 6; ++j)
        v0[k][j] = v1[k][j] = zero;

    alignas(64) double lane_values[12][kLanes];
    for (std::size_t i0 = begin; i0 < end; i0 += kLanes) {
      const std::size_t count = std::min(end - i0, kLanes);
      V t, w, entries[12];
      load_block(observations, t_values, w_values, i0, count, offsets, t, w, entries);
      const V u = one - t;
      const HalfAngles h = half_angles(angle, within_pi, t, u);

      // E = exp(-t X) on the backward direction, c = t^3 (x - sin x)/x^3.
      const V b = two * h.s_sin * h.s_sin * angle.inverse2;
      V e[9], e_shift[3];
      rodrigues(omega_back, two * h.s_sin * h.s_cos * angle.inverse, b, e);
      const V x = t * angle.theta;
      const Mask series = xsimd::abs(x) < two;
      V x_minus_sin = polynomial(kExpSeries, x * x);
      if (!xsimd::all(series))
        x_minus_sin = xsimd::select(series, x_minus_sin, (x - xsimd::sin(x)) / (x * x * x));
      const V c = t * t * t * x_minus_sin;
      for (int k = 0; k < 3; ++k)
        e_shift[k] = t * rho_back[k] + b * w_rho_back[k] + c * w_w_rho_back[k];

      // M = E (g0^{-1} f).
      V p[9], p_shift[3], m[9], m_shift[3];
      multiply(g, entries, p);
      transform(g, entries + 9, g_shift, p_shift);
      multiply(e, p, m);
      transform(e, p_shift, e_shift, m_shift);

      // r = log(M): omega, then rho = t - W t / 2 + e(|omega|) W (W t).
      V r[6];
      V* const r_rho = r;
      V* const r_omega = r + 3;
      const Mask first = rotation_log(m, r_omega);
      const V e_value = polynomial(
          kLogSeries, r_omega[0] * r_omega[0] + r_omega[1] * r_omega[1] + r_omega[2] * r_omega[2]);
      V w_t[3], w_w_t[3];
      cross(r_omega, m_shift, w_t);
      cross(r_omega, w_t, w_w_t);
      for (int k = 0; k < 3; ++k)
        r_rho[k] = m_shift[k] - w_t[k] * half + e_value * w_w_t[k];
      if (!xsimd::all(first)) {
        // Lanes at or beyond pi/2, or not finite: SE3::log on the lane.
        for (int k = 0; k < 9; ++k)
          m[k].store_aligned(lane_values[k]);
        for (int k = 0; k < 3; ++k)
          m_shift[k].store_aligned(lane_values[9 + k]);
        alignas(64) bool in_branch[kLanes];
        first.store_aligned(in_branch);
        alignas(64) double lane_r[6][kLanes];
        for (int k = 0; k < 6; ++k)
          r[k].store_aligned(lane_r[k]);
        for (std::size_t l = 0; l < kLanes; ++l) {
          if (in_branch[l]) continue;
          Element lane_m = Element::Identity();
          for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 3; ++col)
              lane_m(row, col) = lane_values[3 * row + col][l];
            lane_m(row, 3) = lane_values[9 + row][l];
          }
          const Tangent lane_log = SE3d::log(lane_m);
          for (int k = 0; k < 6; ++k)
            lane_r[k][l] = lane_log[k];
        }
        for (int k = 0; k < 6; ++k)
          r[k] = V::load_aligned(lane_r[k]);
      }
      for (int k = 0; k < 6; ++k)
        r[k].store_aligned(lane_values[k]);
      for (std::size_t l = 0; l < count; ++l) {
        Tangent& out = residuals[i0 + l];
        for (int k = 0; k < 6; ++k)
          out[k] = lane_values[k][l];
      }

      const Coefficients c1 = psi_coefficients(angle, t, h.s_sin, h.s_cos, h.u_sin, h.u_cos);
      const Coefficients c0 = psi_coefficients(angle, u, h.u_sin, h.u_cos, h.s_sin, h.s_cos);
      const V forward_c[5] = {t, c1.f1, c1.f2, omega_dot_rho_forward * c1.g1,
                              omega_dot_rho_forward * c1.g2};
      const V backward_c[5] = {u, c0.f1, c0.f2, omega_dot_rho_backward * c0.g1,
                               omega_dot_rho_backward * c0.g2};
      accumulate(v0, w, backward_c, r);
      accumulate(v1, w, forward_c, r);
    }
    bireg::batched::ForceSums<SE3d> sums;
    for (int k = 0; k < 5; ++k) {
      for (int j = 0; j < 6; ++j) {
        sums.v0_sums[k][j] = xsimd::hadd(v0[k][j]);
        sums.v1_sums[k][j] = xsimd::hadd(v1[k][j]);
      }
    }
    return sums;
  }
};

// closed_form_force's closed-form branch with the xsimd sums: the same
// preparation, chunks of kChunkSize combined in chunk order.
template <bool kSincos, class Arch = xsimd::default_arch>
bireg::Force<SE3d> force(const std::vector<Element>& observations,
                         const bireg::Problem<double>& problem, const Element& g0, const Tangent& x,
                         std::vector<Tangent>& residuals) {
  using Psi = SE3d::ClosedFormPsi;
  const Prepared forward = Psi::prepare(x);
  const Prepared backward = Psi::prepare(-x);
  const Element g0_inverse = SE3d::inverse(g0);
  const std::size_t n = observations.size();
  bireg::Force<SE3d> total{Tangent::Zero(), Tangent::Zero()};
  for (std::size_t chunk = 0; chunk < bireg::chunk_count(n); ++chunk) {
    const std::size_t begin = chunk * bireg::kChunkSize;
    const std::size_t end = std::min(n, begin + bireg::kChunkSize);
    const auto sums = Kernel<Arch, kSincos>::closed_form_sums(
        observations, problem.t.data(), problem.w.data(), begin, end, g0_inverse, forward, backward,
        residuals.data());
    total.v0 += Psi::combine(backward, sums.v0_sums);
    total.v1 += Psi::combine(forward, sums.v1_sums);
  }
  return total;
}

// The instruction set xsimd compiled the kernel for.
inline const char* target_name() {
  return xsimd::default_arch::name();
}

}  // namespace xsimd_kernel

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#ifndef BIREG_BENCH_SIMD_KERNEL_ONLY

namespace {

using bireg::SE3d;
using Element = SE3d::Element;
using Tangent = SE3d::Tangent;
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = 3.141592653589793238462643383279502884;

enum KernelId { kScalar = 0, kHighway = 1, kXsimdSincos = 2, kXsimdSinAndCos = 3 };
constexpr int kKernels = 4;
const char* const kKernelNames[kKernels] = {"scalar", "Highway", "xsimd (sincos)",
                                            "xsimd (sin, cos)"};

bool kernel_available(int kernel) {
  return kernel != kHighway || bireg::batched::has_closed_form_sums_v<SE3d>;
}

// Which instruction set a kernel runs on, for the label.
const char* kernel_target(int kernel) {
  switch (kernel) {
    case kHighway:
#if BIREG_HAS_BATCHED_FORCE
      return bireg::batched::target_name();
#else
      return "absent";
#endif
    case kXsimdSincos:
    case kXsimdSinAndCos:
      return xsimd_kernel::target_name();
    default:
      return "scalar";
  }
}

// The observations, the problem and the endpoints a force is evaluated at.
struct Data {
  std::vector<Element> f;
  bireg::Problem<double> problem;
  Element g0;
  Tangent x;
};

bireg::Force<SE3d> evaluate(int kernel, const Data& data, std::vector<Tangent>& residuals) {
  switch (kernel) {
    case kXsimdSincos:
      return xsimd_kernel::force<true>(data.f, data.problem, data.g0, data.x, residuals);
    case kXsimdSinAndCos:
      return xsimd_kernel::force<false>(data.f, data.problem, data.g0, data.x, residuals);
    default:
      return bireg::estimating_detail::closed_form_force<SE3d>(
          data.f, data.problem, data.g0, data.x, residuals, nullptr, kernel == kHighway);
  }
}

// bench_batched's BM_Force data: make_problem (a geodesic of length 1 from
// a random start, noise entries uniform in [-0.1, 0.1], seed 3), evaluated
// at the endpoints of its fit. Built once per n.
const Data& fitted_data(int n) {
  static std::map<int, Data> cache;
  const auto found = cache.find(n);
  if (found != cache.end()) return found->second;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Tangent start, x;
  for (int k = 0; k < SE3d::dof; ++k) {
    start[k] = uniform(rng);
    x[k] = uniform(rng);
  }
  x *= 1.0 / x.norm();
  const Element g0 = SE3d::exp(start);
  std::vector<Element> f;
  std::vector<double> t;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    Tangent e;
    for (int k = 0; k < SE3d::dof; ++k)
      e[k] = 0.1 * uniform(rng);
    f.push_back(SE3d::compose(SE3d::compose(g0, SE3d::exp(s * x)), SE3d::exp(e)));
    t.push_back(s);
  }
  const auto fit = bireg::GeodesicRegression<SE3d>().fit(f, t);
  if (!fit.ok()) {
    std::fprintf(stderr, "bench_simd_libraries: the fit of %d observations failed\n", n);
    std::exit(1);
  }
  Data data;
  data.f = std::move(f);
  data.problem.t = t;  // already on [0, 1]
  data.problem.w.assign(t.size(), 1.0);
  data.g0 = fit.geodesic->start();
  data.x = SE3d::log(SE3d::compose(SE3d::inverse(data.g0), fit.geodesic->end()));
  if (!bireg::uses_closed_form_psi<SE3d>(data.x)) {
    std::fprintf(stderr, "bench_simd_libraries: the fit is outside the closed form's range\n");
    std::exit(1);
  }
  return cache.emplace(n, std::move(data)).first->second;
}

Eigen::Vector3d random_axis(std::mt19937& rng) {
  std::normal_distribution<double> normal(0, 1);
  const Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  return v / v.norm();
}

Tangent tangent(const Eigen::Vector3d& rho, const Eigen::Vector3d& omega) {
  Tangent x;
  x << rho, omega;
  return x;
}

// tests/test_batched_force.cpp's data: f_i = g0 exp(t_i x) exp(noise_i),
// one residual in ten turned by an angle uniform in [0, pi - 1e-6), t = 0
// and t = 1 exactly at some observations, weights in [0.05, 1.05).
Data edge_data(std::size_t n, double theta, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  Data data;
  data.g0 =
      SE3d::exp(tangent(Eigen::Vector3d(normal(rng), normal(rng), 0.5), 2.0 * random_axis(rng)));
  data.x = tangent(1.3 * random_axis(rng), theta * random_axis(rng));
  for (std::size_t i = 0; i < n; ++i) {
    double t = uniform(rng);
    if (i % 97 == 0) t = 0;
    if (i % 89 == 0) t = 1;
    Eigen::Vector3d omega = 0.05 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    if (i % 10 == 3) omega = (kPi - 1e-6) * uniform(rng) * random_axis(rng);
    const Eigen::Vector3d rho = 0.05 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    data.f.push_back(SE3d::compose(SE3d::compose(data.g0, SE3d::exp(t * data.x)),
                                   SE3d::exp(tangent(rho, omega))));
    data.problem.t.push_back(t);
    data.problem.w.push_back(0.05 + uniform(rng));
  }
  return data;
}

// tests/test_batched_force.cpp's bound on a residual's entries.
double residual_bound(const Tangent& r) {
  const double angle = r.tail<3>().norm();
  const double condition = angle < 1e-8 ? 1 : angle / std::sin(angle);
  return 64 * kEps * (1 + condition) * (4 + r.norm());
}

// The size of the force's terms per direction: sum_i w_i |c_k(t_i)| |r_i|
// placed in sums[k] of every component and combined as the force is, with
// absolute values (|B_k| applied to a vector of sizes): a bound on the
// force's magnitude that does not cancel, against which the order of
// addition is measured.
std::pair<double, double> force_scales(const Data& data, const std::vector<Tangent>& residuals) {
  using Psi = SE3d::ClosedFormPsi;
  const auto forward = Psi::prepare(data.x), backward = Psi::prepare(-data.x);
  const auto half = bireg::psi_closed_form::SinCos<double>::of(forward.theta / 2);
  double size0 = 0, size1 = 0;
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    const double t = data.problem.t[i], w = data.problem.w[i];
    const auto angles = bireg::psi_closed_form::half_angle_pair(forward.theta, half, t);
    const auto c0 = Psi::coefficients(backward, 1 - t, angles.u_half, angles.s_half);
    const auto c1 = Psi::coefficients(forward, t, angles.s_half, angles.u_half);
    const double r = residuals[i].norm();
    for (int k = 0; k < Psi::kTerms; ++k) {
      size0 += w * std::abs(c0[k]) * r;
      size1 += w * std::abs(c1[k]) * r;
    }
  }
  const double combine = (1 + data.x.norm()) * (1 + data.x.norm());
  return {combine * size0, combine * size1};
}

struct Agreement {
  double residual_ratio = 0;          // max over entries of |dr| / residual_bound
  double residual_relative = 0;       // max over i of |dr|_inf / max(|r|_inf, tiny)
  double residual_absolute = 0;       // max over entries of |dr|
  double force_relative[2] = {0, 0};  // |dF| / |F| per direction (v0, v1)
  double force_scaled[2] = {0, 0};    // |dF| / force_scales per direction
  double force_norm[2] = {0, 0};      // |F| (scalar) per direction
  double force_terms[2] = {0, 0};     // force_scales per direction
  std::size_t turned = 0;             // residuals of angle >= pi/2
};

Agreement compare(int kernel, const Data& data) {
  std::vector<Tangent> scalar_r(data.f.size(), Tangent::Constant(-7));
  std::vector<Tangent> kernel_r(data.f.size(), Tangent::Constant(-7));
  const bireg::Force<SE3d> scalar = evaluate(kScalar, data, scalar_r);
  const bireg::Force<SE3d> other = evaluate(kernel, data, kernel_r);
  Agreement a;
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    const Tangent d = kernel_r[i] - scalar_r[i];
    const double dr = d.lpNorm<Eigen::Infinity>();
    const double ratio = dr / residual_bound(scalar_r[i]);
    a.residual_ratio = std::max(a.residual_ratio, std::isnan(ratio) ? HUGE_VAL : ratio);
    a.residual_absolute = std::max(a.residual_absolute, dr);
    a.residual_relative =
        std::max(a.residual_relative, dr / std::max(scalar_r[i].lpNorm<Eigen::Infinity>(), 1e-300));
    a.turned += scalar_r[i].tail<3>().norm() >= kPi / 2;
  }
  const auto [scale0, scale1] = force_scales(data, scalar_r);
  const double d0 = (other.v0 - scalar.v0).norm(), d1 = (other.v1 - scalar.v1).norm();
  a.force_relative[0] = d0 / scalar.v0.norm();
  a.force_relative[1] = d1 / scalar.v1.norm();
  a.force_scaled[0] = d0 / scale0;
  a.force_scaled[1] = d1 / scale1;
  a.force_norm[0] = scalar.v0.norm();
  a.force_norm[1] = scalar.v1.norm();
  a.force_terms[0] = scale0;
  a.force_terms[1] = scale1;
  if (!other.v0.allFinite() || !other.v1.allFinite()) a.force_scaled[0] = HUGE_VAL;
  return a;
}

// Checks every kernel against the scalar loop and prints the agreement:
// residual entries within residual_bound; the force within 1e-12 of the
// size of its terms and, where the force does not vanish (every data set
// but a fit's answer), within 1e-12 of its own norm. False where a kernel
// is outside.
bool check(const char* what, const Data& data, bool force_vanishes) {
  bool ok = true;
  for (int kernel = kHighway; kernel < kKernels; ++kernel) {
    if (!kernel_available(kernel)) continue;
    const Agreement a = compare(kernel, data);
    const bool residuals_ok = a.residual_ratio <= 1;
    const bool force_ok =
        a.force_scaled[0] <= 1e-12 && a.force_scaled[1] <= 1e-12 &&
        (force_vanishes || (a.force_relative[0] <= 1e-12 && a.force_relative[1] <= 1e-12));
    std::printf(
        "%-17s %-16s r: max|dr| %.1e max|dr|/|r| %.1e max|dr|/bound %.3f (%4zu >= pi/2) | "
        "|F| %.1e %.1e terms %.1e %.1e | |dF|/|F| %.1e %.1e |dF|/terms %.1e %.1e %s\n",
        what, kKernelNames[kernel], a.residual_absolute, a.residual_relative, a.residual_ratio,
        a.turned, a.force_norm[0], a.force_norm[1], a.force_terms[0], a.force_terms[1],
        a.force_relative[0], a.force_relative[1], a.force_scaled[0], a.force_scaled[1],
        residuals_ok && force_ok ? "ok" : "OUT OF BOUNDS");
    ok = ok && residuals_ok && force_ok;
  }
  return ok;
}

void BM_ForceSE3(benchmark::State& state) {
  const int kernel = static_cast<int>(state.range(0));
  if (!kernel_available(kernel)) {
    state.SkipWithError("Highway's kernel is absent from this build");
    return;
  }
  const Data& data = fitted_data(static_cast<int>(state.range(1)));
  std::vector<Tangent> residuals(data.f.size());
  for (auto _ : state) {
    const bireg::Force<SE3d> force = evaluate(kernel, data, residuals);
    benchmark::DoNotOptimize(force);
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string(kKernelNames[kernel]) + " " + kernel_target(kernel));
  state.counters["time_per_obs"] = benchmark::Counter(
      static_cast<double>(data.f.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ForceSE3)
    ->ArgNames({"kernel", "n"})
    ->ArgsProduct({{kScalar, kHighway, kXsimdSincos, kXsimdSinAndCos}, {1000, 100000}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  std::printf("xsimd %d.%d.%d on %s (%zu doubles per batch); Highway on %s\n", XSIMD_VERSION_MAJOR,
              XSIMD_VERSION_MINOR, XSIMD_VERSION_PATCH, xsimd_kernel::target_name(),
              xsimd::batch<double>::size, kernel_target(kHighway));
  if (!(xsimd::available_architectures().best >= xsimd::default_arch::version())) {
    std::fprintf(stderr, "bench_simd_libraries: this machine lacks %s\n",
                 xsimd_kernel::target_name());
    return 1;
  }
  bool ok = true;
  for (const int n : {1000, 100000}) {
    char what[64];
    std::snprintf(what, sizeof what, "fitted n=%d", n);
    ok = check(what, fitted_data(n), true) && ok;
  }
  int seed = 0;
  for (const double theta : {bireg::kExactMinAngle, 1.5, 3.0, kPi}) {
    char what[64];
    std::snprintf(what, sizeof what, "edges theta=%.3g", theta);
    ok = check(what, edge_data(10007, theta, static_cast<unsigned>(++seed)), false) && ok;
  }
  if (!ok) {
    std::fprintf(stderr, "bench_simd_libraries: a kernel disagrees with the scalar loop\n");
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

#endif  // BIREG_BENCH_SIMD_KERNEL_ONLY
