// bireg: the closed-form force of SO(3) and SE(3) batched across
// observations (issue "Speed toward the hardware", item 1). The
// per-observation work of estimating_detail::closed_form_force
// (estimating_equations.hpp),
//
//   angles       sin, cos of t theta/2 and (1 - t) theta/2   (half_angle_pair)
//   prediction   E = exp(-t X) from that pair                 (ClosedFormPsi::exp)
//   residual     r = log(E g0^{-1} f)                         (the group's log)
//   coefficients c_k of psi_s in both directions              (ClosedFormPsi::coefficients)
//   sums         sum_i w_i c_k(s_i) r_i for v0 and v1,
//
// is the same straight-line arithmetic on every observation, so it is done
// here on L observations at once, one per lane of a SIMD vector (L = 8
// doubles with AVX-512, 4 with AVX2), with Highway's vector sin, cos and
// atan (hwy/contrib/math, at most 3 ulp each). Observations are copied into
// a lane-major block (structure of arrays) L at a time; the partial sums
// stay in vectors until the range's end.
//
// Branches are per lane. The coefficients at s = 0 (psi_0 = 0) are zero by
// a blend, as in the scalar coefficients. The residual's rotation log takes
// SO3::log's first branch (angle below pi/2, trace > 1) in the vector code,
// where SE(3)'s log needs only its series (squared angle below 4); a lane
// outside that (a residual turning pi/2 or more, a trace that is not
// finite, or an off-group matrix whose first branch gives a larger angle)
// is evaluated by the group's own log on that lane's element, so it gets
// the scalar path's answer (near pi included) while the other lanes stay
// vectorised. Other non-finite entries stay in the vector path and give
// non-finite residuals, as the scalar path does. Lanes at s = 0 and
// atan(y)/y at y = 0 divide by zero before their blend discards the
// quotient: a program that traps floating-point exceptions must not use
// the kernels. The kernels are used where the closed form is (rotation
// angle theta of X at least kExactMinAngle, covariates in [0, 1]); the
// series path stays scalar.
//
// Availability: with BIREG_USE_HIGHWAY defined, Highway's headers found and
// AVX2 or AVX-512 enabled by the compiler (-march=haswell -maes,
// -march=skylake-avx512, -march=native), for that instruction set
// (Highway's static target); for float and double. Otherwise
// BIREG_HAS_BATCHED_FORCE is 0 and the scalar loop is used, also on
// Highway's 128-bit targets (SSSE3, SSE4, NEON: untested) and its scalable
// ones (SVE, RVV: arrays of sizeless vectors do not compile). A program
// must not mix translation units built with and without the kernels (the
// same closed_form_force<G> instantiated differently breaks the one
// definition rule), nor exchange Eigen objects between code built for
// different vector widths: Eigen aligns its fixed-size types to the width
// the compiler targets (bireg_precompiled is built for the baseline).
//
// Agreement with the scalar loop: each lane performs the scalar loop's
// operations in the same order, so a residual differs from the scalar one
// only through the vector sin, cos and atan (a few ulp each) and fused
// multiply-adds where the compiler forms them; the sums differ by their
// order of addition (lane-wise partial sums). tests/test_batched_force.cpp
// bounds both.
#pragma once

#include <array>
#include <cstddef>
#include <type_traits>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/math/psi_closed_form.hpp"
#include "bireg/math/small_angle.hpp"

// x86 with AVX2 or AVX-512 only: the targets tested and measured. Highway
// picks its AVX2 target only with AES and PCLMUL enabled as well, so
// -march=x86-64-v3 or -v4 alone (which leave them out) select its SSSE3
// target, where the scalar loop is kept; add -maes -mpclmul.
#if defined(BIREG_USE_HIGHWAY) && defined(__has_include) && defined(__AVX2__)
#if __has_include(<hwy/highway.h>)
#include <hwy/highway.h>
// After highway.h: these depend on it.
#include <hwy/cache_control.h>
#include <hwy/contrib/math/math-inl.h>
#if HWY_ARCH_X86 && !HWY_HAVE_SCALABLE && HWY_STATIC_TARGET <= HWY_AVX2
#define BIREG_HAS_BATCHED_FORCE 1
#endif
#endif
#endif
#ifndef BIREG_HAS_BATCHED_FORCE
#define BIREG_HAS_BATCHED_FORCE 0
#endif

namespace bireg {
namespace batched {

// The closed form's per-coefficient sums over a range of observations:
// v0_sums[k] = sum_i w_i c_k(1 - t_i; -X) r_i, v1_sums[k] = sum_i w_i c_k(t_i; X) r_i,
// which closed_form_force combines with ClosedFormPsi::combine.
template <class G>
struct ForceSums {
  std::array<typename G::Tangent, G::ClosedFormPsi::kTerms> v0_sums, v1_sums;
};

#if BIREG_HAS_BATCHED_FORCE

namespace detail {
namespace hn = hwy::HWY_NAMESPACE;

template <class Scalar>
using Tag = hn::ScalableTag<Scalar>;
template <class Scalar>
using Vec = hn::Vec<Tag<Scalar>>;
template <class Scalar>
using Mask = hn::Mask<Tag<Scalar>>;

// At most 8 doubles or 16 floats per vector (AVX-512).
template <class Scalar>
inline constexpr std::size_t kMaxLanes = 64 / sizeof(Scalar);
static_assert(HWY_LANES(double) <= kMaxLanes<double> && HWY_LANES(float) <= kMaxLanes<float>);

// small_angle::polynomial's four chains, lane-wise: the same operations in
// the same order.
template <class Scalar, std::size_t Count>
HWY_INLINE Vec<Scalar> polynomial(const std::array<Scalar, Count>& coefficients, Vec<Scalar> x) {
  const Tag<Scalar> d;
  constexpr std::size_t kChains = 4;
  constexpr std::size_t kRows = (Count + kChains - 1) / kChains;
  const Vec<Scalar> x2 = x * x;
  const Vec<Scalar> x4 = x2 * x2;
  Vec<Scalar> chain[kChains] = {hn::Zero(d), hn::Zero(d), hn::Zero(d), hn::Zero(d)};
  for (std::size_t row = kRows; row-- > 0;) {
    for (std::size_t j = 0; j < kChains; ++j) {
      const std::size_t k = row * kChains + j;
      if (k < Count) chain[j] = chain[j] * x4 + hn::Set(d, coefficients[k]);
    }
  }
  return chain[0] + x * (chain[1] + x * (chain[2] + x * chain[3]));
}

// What the kernels need of one direction's prepared X, as vectors.
template <class Scalar>
struct AngleVectors {
  Vec<Scalar> theta, half_sin, half_cos, cot_half, inverse, inverse2, inverse3, inverse4;
  explicit AngleVectors(const psi_closed_form::Angle<Scalar>& a)
      : theta(hn::Set(Tag<Scalar>(), a.theta)),
        half_sin(hn::Set(Tag<Scalar>(), a.half.sin)),
        half_cos(hn::Set(Tag<Scalar>(), a.half.cos)),
        cot_half(hn::Set(Tag<Scalar>(), a.cot_half)),
        inverse(hn::Set(Tag<Scalar>(), a.inverse)),
        inverse2(hn::Set(Tag<Scalar>(), a.inverse2)),
        inverse3(hn::Set(Tag<Scalar>(), a.inverse3)),
        inverse4(hn::Set(Tag<Scalar>(), a.inverse4)) {}
};

// sin and cos of t theta/2 and (1 - t) theta/2
// (psi_closed_form::half_angle_pair): within pi the smaller angle directly
// and the other by the difference formulas; beyond pi both directly.
template <class Scalar>
struct HalfAngles {
  Vec<Scalar> s_sin, s_cos, u_sin, u_cos;
};

template <class Scalar>
HWY_INLINE HalfAngles<Scalar> half_angles(const AngleVectors<Scalar>& a, bool within_pi,
                                          Vec<Scalar> t, Vec<Scalar> u) {
  const Tag<Scalar> d;
  const Vec<Scalar> half = hn::Set(d, Scalar(0.5));
  if (!within_pi) {
    const Vec<Scalar> s_angle = t * a.theta * half, u_angle = u * a.theta * half;
    return {hn::Sin(d, s_angle), hn::Cos(d, s_angle), hn::Sin(d, u_angle), hn::Cos(d, u_angle)};
  }
  const Mask<Scalar> s_is_smaller = hn::Le(t, u);
  const Vec<Scalar> smaller_angle = hn::IfThenElse(s_is_smaller, t, u) * a.theta * half;
  const Vec<Scalar> smaller_sin = hn::Sin(d, smaller_angle);
  const Vec<Scalar> smaller_cos = hn::Cos(d, smaller_angle);
  const Vec<Scalar> larger_sin = a.half_sin * smaller_cos - a.half_cos * smaller_sin;
  const Vec<Scalar> larger_cos = a.half_cos * smaller_cos + a.half_sin * smaller_sin;
  return {hn::IfThenElse(s_is_smaller, smaller_sin, larger_sin),
          hn::IfThenElse(s_is_smaller, smaller_cos, larger_cos),
          hn::IfThenElse(s_is_smaller, larger_sin, smaller_sin),
          hn::IfThenElse(s_is_smaller, larger_cos, smaller_cos)};
}

// A uniform 3-vector (the same in every lane), with its squares.
template <class Scalar>
struct UniformVector {
  Vec<Scalar> v[3], square[3];
  explicit UniformVector(const Eigen::Matrix<Scalar, 3, 1>& x) {
    const Tag<Scalar> d;
    for (int k = 0; k < 3; ++k) {
      v[k] = hn::Set(d, x[k]);
      square[k] = hn::Set(d, x[k] * x[k]);
    }
  }
};

// I + a W + b W^2 with W = hat(omega), entry by entry as SO3::rodrigues;
// e[3 row + col].
template <class Scalar>
HWY_INLINE void rodrigues(const UniformVector<Scalar>& omega, Vec<Scalar> a, Vec<Scalar> b,
                          Vec<Scalar> e[9]) {
  const Vec<Scalar> one = hn::Set(Tag<Scalar>(), Scalar(1));
  const Vec<Scalar>*o = omega.v, *sq = omega.square;
  const Vec<Scalar> b01 = b * o[0] * o[1], b02 = b * o[0] * o[2], b12 = b * o[1] * o[2];
  const Vec<Scalar> a0 = a * o[0], a1 = a * o[1], a2 = a * o[2];
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

// out = a b for 3 x 3 blocks a[3 row + col]; out must not alias.
template <class Scalar>
HWY_INLINE void multiply(const Vec<Scalar> a[9], const Vec<Scalar> b[9], Vec<Scalar> out[9]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
}

// out = a v + shift for a 3 x 3 block a and 3-vectors.
template <class Scalar>
HWY_INLINE void transform(const Vec<Scalar> a[9], const Vec<Scalar> v[3],
                          const Vec<Scalar> shift[3], Vec<Scalar> out[3]) {
  for (int r = 0; r < 3; ++r)
    out[r] = a[3 * r] * v[0] + a[3 * r + 1] * v[1] + a[3 * r + 2] * v[2] + shift[r];
}

template <class Scalar>
HWY_INLINE void cross(const Vec<Scalar> a[3], const Vec<Scalar> b[3], Vec<Scalar> out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// omega = log(m) by SO3::log's first branch, valid in the lanes of the
// returned mask (trace > 1: angle below pi/2): d = vee(m - m^T),
// y = |d| / (1 + trace), omega = (2 / (1 + trace)) (atan(y) / y) d.
template <class Scalar>
HWY_INLINE Mask<Scalar> rotation_log(const Vec<Scalar> m[9], Vec<Scalar> omega[3]) {
  const Tag<Scalar> d;
  const Vec<Scalar> one = hn::Set(d, Scalar(1)), two = hn::Set(d, Scalar(2));
  const Vec<Scalar> trace = m[0] + m[4] + m[8];
  const Vec<Scalar> d0 = m[7] - m[5], d1 = m[2] - m[6], d2 = m[3] - m[1];
  const Vec<Scalar> one_plus_trace = one + trace;
  const Vec<Scalar> y = hn::Sqrt(d0 * d0 + d1 * d1 + d2 * d2) / one_plus_trace;
  const Vec<Scalar> tiny = hn::Set(d, small_angle::tiny_angle<Scalar>());
  const Vec<Scalar> three = hn::Set(d, Scalar(3));
  // small_angle::atan_over_y: 1 - y^2 / 3 below tiny_angle, divided as there.
  const Vec<Scalar> atan_over_y = hn::IfThenElse(
      hn::Lt(hn::Abs(y), tiny), hn::Sub(one, hn::Div(y * y, three)), hn::Atan(d, y) / y);
  const Vec<Scalar> factor = two / one_plus_trace * atan_over_y;
  omega[0] = factor * d0;
  omega[1] = factor * d1;
  omega[2] = factor * d2;
  return hn::Gt(trace, one);
}

// psi_closed_form::psi_coefficients lane-wise, zero where s = 0
// (rotation_block_coefficients); g1 and g2 only when asked for.
template <class Scalar>
struct Coefficients {
  Vec<Scalar> f1, f2, g1, g2;
};

template <class Scalar, bool kDerivatives>
HWY_INLINE Coefficients<Scalar> psi_coefficients(const AngleVectors<Scalar>& a, Vec<Scalar> s,
                                                 Vec<Scalar> sin_s, Vec<Scalar> cos_s,
                                                 Vec<Scalar> sin_u, Vec<Scalar> cos_u) {
  const Tag<Scalar> d;
  const Vec<Scalar> zero = hn::Zero(d), one = hn::Set(d, Scalar(1));
  const Vec<Scalar> half = hn::Set(d, Scalar(0.5));
  const Mask<Scalar> nonzero = hn::Ne(s, zero);
  const Vec<Scalar> inverse_s_sin = one / sin_s;
  const Vec<Scalar> modulus = s * s * a.half_sin * inverse_s_sin;
  const Vec<Scalar> alpha = modulus * cos_u, beta = hn::Neg(modulus) * sin_u;
  Coefficients<Scalar> c;
  c.f1 = hn::IfThenElseZero(nonzero, beta * a.inverse);
  c.f2 = hn::IfThenElseZero(nonzero, (s - alpha) * a.inverse2);
  if constexpr (kDerivatives) {
    // F'/F = p + i q, p = (s - 1)/2, q = -(cot(theta/2) - s cot(s theta/2))/2.
    const Vec<Scalar> p = (s - one) * half;
    const Vec<Scalar> q = hn::Neg(a.cot_half - s * cos_s * inverse_s_sin) * half;
    const Vec<Scalar> alpha_d = alpha * p - beta * q, beta_d = alpha * q + beta * p;
    const Vec<Scalar> two = hn::Set(d, Scalar(2));
    c.g1 = hn::IfThenElseZero(nonzero, (a.theta * alpha_d - beta) * a.inverse3);
    c.g2 = hn::IfThenElseZero(nonzero, (a.theta * beta_d - two * (s - alpha)) * a.inverse4);
  } else {
    static_cast<void>(cos_s);
  }
  return c;
}

// The entries of an element the kernels read, as (row, column): the
// rotation block row-major, then (SE(3)) the translation column.
template <int kEntries>
struct EntryLayout {
  int row[kEntries], col[kEntries];
  constexpr EntryLayout() : row(), col() {
    for (int e = 0; e < kEntries; ++e) {
      row[e] = e < 9 ? e / 3 : e - 9;
      col[e] = e < 9 ? e % 3 : 3;
    }
  }
};

// Whether observations[i] are Eigen matrices stored one after another
// (std::vector<Element> and the like): then a block's entries are gathered
// straight from memory.
template <class Observations, class Element, class = void>
struct Contiguous : std::false_type {};
template <class Observations, class Element>
struct Contiguous<Observations, Element,
                  std::void_t<decltype(std::declval<const Observations&>().data())>>
    : std::is_same<std::decay_t<decltype(*std::declval<const Observations&>().data())>, Element> {};

// The covariates, weights and entries (EntryLayout) of observations
// [i0, i0 + count) as vectors, lane l holding observation i0 + l. Lanes
// beyond count hold the identity at t = 1/2 with weight 0: finite, and
// adding nothing to the sums.
template <class Scalar, int kEntries, class Element, class Observations>
HWY_INLINE void load_block(const Observations& observations, const Scalar* t_values,
                           const Scalar* w_values, std::size_t i0, std::size_t count,
                           Vec<Scalar>& t, Vec<Scalar>& w, Vec<Scalar> (&entries)[kEntries]) {
  const Tag<Scalar> d;
  constexpr EntryLayout<kEntries> layout;
  constexpr int kRows = Element::RowsAtCompileTime;
  const std::size_t lane_count = hn::Lanes(d);
  if constexpr (Contiguous<Observations, Element>::value) {
    static_assert(sizeof(Element) == sizeof(Scalar) * Element::SizeAtCompileTime &&
                  !(Element::Flags & Eigen::RowMajorBit));
    if (count == lane_count) {
      const hn::RebindToSigned<Tag<Scalar>> di;
      constexpr std::size_t kSize = Element::SizeAtCompileTime;
      const auto stride = hn::Set(di, static_cast<hn::TFromD<decltype(di)>>(kSize));
      const auto offsets = hn::Iota(di, 0) * stride;
      const Scalar* base = observations.data()[i0].data();
      // Gathers do not start the hardware prefetcher: the block two ahead
      // is fetched by hand (it halves SE(3)'s time on 1e5 observations).
      if (i0 + 3 * lane_count <= observations.size()) {
        const char* ahead = reinterpret_cast<const char*>(base + 2 * lane_count * kSize);
        for (std::size_t byte = 0; byte < lane_count * sizeof(Element); byte += 64)
          hwy::Prefetch(ahead + byte);
      }
      t = hn::LoadU(d, t_values + i0);
      w = hn::LoadU(d, w_values + i0);
      for (int e = 0; e < kEntries; ++e)
        entries[e] = hn::GatherIndex(d, base + layout.col[e] * kRows + layout.row[e], offsets);
      return;
    }
  }
  alignas(64) Scalar t_lanes[kMaxLanes<Scalar>], w_lanes[kMaxLanes<Scalar>];
  alignas(64) Scalar lanes[kEntries][kMaxLanes<Scalar>];
  for (std::size_t l = 0; l < lane_count; ++l) {
    if (l < count) {
      const Element& f = observations[i0 + l];
      t_lanes[l] = t_values[i0 + l];
      w_lanes[l] = w_values[i0 + l];
      for (int e = 0; e < kEntries; ++e)
        lanes[e][l] = f(layout.row[e], layout.col[e]);
    } else {
      t_lanes[l] = Scalar(0.5);
      w_lanes[l] = Scalar(0);
      for (int e = 0; e < kEntries; ++e)
        lanes[e][l] = layout.row[e] == layout.col[e] ? Scalar(1) : Scalar(0);
    }
  }
  t = hn::Load(d, t_lanes);
  w = hn::Load(d, w_lanes);
  for (int e = 0; e < kEntries; ++e)
    entries[e] = hn::Load(d, lanes[e]);
}

// What both kernels set up once per range: X's angle, whether it is
// within pi (half_angles), exp(-t X)'s axis backward.omega = -omega, and
// the rotation block of g0^{-1}, as vectors.
template <class Scalar>
struct RotationSetup {
  AngleVectors<Scalar> angle;
  bool within_pi;
  UniformVector<Scalar> omega_back;
  Vec<Scalar> g[9];

  template <class Prepared, class Inverse>
  RotationSetup(const Prepared& forward, const Prepared& backward, const Inverse& g0_inverse)
      : angle(forward.angle),
        within_pi(forward.theta <= Scalar(3.141592653589793238462643383279502884L)),
        omega_back(backward.omega) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        g[3 * r + c] = hn::Set(Tag<Scalar>(), g0_inverse(r, c));
  }
};

// Zero partial sums.
template <class Scalar, int kTerms, int kDof>
HWY_INLINE void set_zero(Vec<Scalar> (&sums)[kTerms][kDof]) {
  for (int k = 0; k < kTerms; ++k)
    for (int j = 0; j < kDof; ++j)
      sums[k][j] = hn::Zero(Tag<Scalar>());
}

// The group's own log on the lanes outside `first` (the vector path's
// domain), of the element whose entries (EntryLayout) are `entries`, into
// those lanes of r; the other lanes keep their values.
template <class Group, int kEntries>
HWY_INLINE void log_outside(Mask<typename Group::Scalar> first,
                            const Vec<typename Group::Scalar> (&entries)[kEntries],
                            Vec<typename Group::Scalar> (&r)[Group::dof]) {
  using Scalar = typename Group::Scalar;
  const Tag<Scalar> d;
  if (hn::AllTrue(d, first)) return;
  constexpr EntryLayout<kEntries> layout;
  alignas(64) Scalar lane_entries[kEntries][kMaxLanes<Scalar>];
  alignas(64) Scalar in_domain[kMaxLanes<Scalar>];
  alignas(64) Scalar lane_r[Group::dof][kMaxLanes<Scalar>];
  for (int e = 0; e < kEntries; ++e)
    hn::Store(entries[e], d, lane_entries[e]);
  hn::Store(hn::IfThenElseZero(first, hn::Set(d, Scalar(1))), d, in_domain);
  for (int k = 0; k < Group::dof; ++k)
    hn::Store(r[k], d, lane_r[k]);
  for (std::size_t l = 0; l < hn::Lanes(d); ++l) {
    if (in_domain[l] != Scalar(0)) continue;
    typename Group::Element element = Group::Element::Identity();
    for (int e = 0; e < kEntries; ++e)
      element(layout.row[e], layout.col[e]) = lane_entries[e][l];
    const typename Group::Tangent log = Group::log(element);
    for (int k = 0; k < Group::dof; ++k)
      lane_r[k][l] = log[k];
  }
  for (int k = 0; k < Group::dof; ++k)
    r[k] = hn::Load(d, lane_r[k]);
}

// residuals[l] = r's lane l for the count real lanes.
template <class Group>
HWY_INLINE void store_residuals(const Vec<typename Group::Scalar> (&r)[Group::dof],
                                std::size_t count, typename Group::Tangent* residuals) {
  using Scalar = typename Group::Scalar;
  const Tag<Scalar> d;
  alignas(64) Scalar lanes[Group::dof][kMaxLanes<Scalar>];
  for (int k = 0; k < Group::dof; ++k)
    hn::Store(r[k], d, lanes[k]);
  for (std::size_t l = 0; l < count; ++l)
    for (int k = 0; k < Group::dof; ++k)
      residuals[l][k] = lanes[k][l];
}

// sums[k][j] += (w c_k) r_j.
template <class Scalar, int kTerms, int kDof>
HWY_INLINE void accumulate(Vec<Scalar> (&sums)[kTerms][kDof], Vec<Scalar> w,
                           const Vec<Scalar> (&c)[kTerms], const Vec<Scalar> (&r)[kDof]) {
  for (int k = 0; k < kTerms; ++k) {
    const Vec<Scalar> wc = w * c[k];
    for (int j = 0; j < kDof; ++j)
      sums[k][j] = hn::MulAdd(wc, r[j], sums[k][j]);
  }
}

template <class G, int kTerms, int kDof>
HWY_INLINE ForceSums<G> reduce(const Vec<typename G::Scalar> (&v0)[kTerms][kDof],
                               const Vec<typename G::Scalar> (&v1)[kTerms][kDof]) {
  const Tag<typename G::Scalar> d;
  ForceSums<G> sums;
  for (int k = 0; k < kTerms; ++k) {
    for (int j = 0; j < kDof; ++j) {
      sums.v0_sums[k][j] = hn::GetLane(hn::SumOfLanes(d, v0[k][j]));
      sums.v1_sums[k][j] = hn::GetLane(hn::SumOfLanes(d, v1[k][j]));
    }
  }
  return sums;
}

}  // namespace detail

// The name of the instruction set the kernels were compiled for ("AVX3",
// "AVX2", ...), for benchmarks and reports.
inline const char* target_name() {
  return hwy::TargetName(HWY_STATIC_TARGET);
}

// SO(3): the sums of observations [begin, end) at g0^{-1} = g0_inverse and
// X prepared in both directions (ClosedFormPsi::prepare(x) and (-x), theta
// at least kExactMinAngle: up to pi by the difference formulas, beyond pi
// with both half angles evaluated directly, as half_angles), writing each
// residual into residuals[i]; t and w are the problem's covariates on
// [0, 1] and weights.
template <class Scalar, class Observations>
ForceSums<SO3<Scalar>> closed_form_sums(
    const SO3<Scalar>&, const Observations& observations, const Scalar* t_values,
    const Scalar* w_values, std::size_t begin, std::size_t end,
    const typename SO3<Scalar>::Element& g0_inverse,
    const typename SO3<Scalar>::ClosedFormPsi::Prepared& forward,
    const typename SO3<Scalar>::ClosedFormPsi::Prepared& backward,
    typename SO3<Scalar>::Tangent* residuals) {
  namespace hn = detail::hn;
  using Group = SO3<Scalar>;
  using V = detail::Vec<Scalar>;
  const detail::Tag<Scalar> d;
  const std::size_t lane_count = hn::Lanes(d);
  const V one = hn::Set(d, Scalar(1)), two = hn::Set(d, Scalar(2));
  const detail::RotationSetup<Scalar> setup(forward, backward, g0_inverse);
  const auto& angle = setup.angle;
  V v0[3][3], v1[3][3];  // [term][component]
  detail::set_zero<Scalar>(v0);
  detail::set_zero<Scalar>(v1);

  for (std::size_t i0 = begin; i0 < end; i0 += lane_count) {
    const std::size_t count = end - i0 < lane_count ? end - i0 : lane_count;
    V t, w, f[9];
    detail::load_block<Scalar, 9, typename Group::Element>(observations, t_values, w_values, i0,
                                                           count, t, w, f);
    const V u = one - t;
    const detail::HalfAngles<Scalar> h = detail::half_angles(angle, setup.within_pi, t, u);

    // E = exp(-t X): Rodrigues with a = 2 sin cos / theta, b = 2 sin^2 / theta^2
    // of t theta/2 (SO3::ClosedFormPsi::exp); M = E (g0^{-1} f).
    V e[9], p[9], m[9];
    detail::rodrigues(setup.omega_back, two * h.s_sin * h.s_cos * angle.inverse,
                      two * h.s_sin * h.s_sin * angle.inverse2, e);
    detail::multiply<Scalar>(setup.g, f, p);
    detail::multiply<Scalar>(e, p, m);

    V r[3];
    const auto first = detail::rotation_log<Scalar>(m, r);
    // Lanes at or beyond pi/2, or not finite: SO3::log on the lane.
    detail::log_outside<Group, 9>(first, m, r);
    detail::store_residuals<Group>(r, count, residuals + i0);

    // (s, f1, f2) forward at s = t, backward at s = 1 - t with the pair swapped.
    const auto c1 =
        detail::psi_coefficients<Scalar, false>(angle, t, h.s_sin, h.s_cos, h.u_sin, h.u_cos);
    const auto c0 =
        detail::psi_coefficients<Scalar, false>(angle, u, h.u_sin, h.u_cos, h.s_sin, h.s_cos);
    const V forward_c[3] = {t, c1.f1, c1.f2};
    const V backward_c[3] = {u, c0.f1, c0.f2};
    detail::accumulate<Scalar, 3, 3>(v0, w, backward_c, r);
    detail::accumulate<Scalar, 3, 3>(v1, w, forward_c, r);
  }
  return detail::reduce<Group, 3, 3>(v0, v1);
}

// SE(3): as for SO(3), with the residual's translation part and the five
// coefficients (s, f1, f2, (omega . rho) g1, (omega . rho) g2).
template <class Scalar, class Observations>
ForceSums<SE3<Scalar>> closed_form_sums(
    const SE3<Scalar>&, const Observations& observations, const Scalar* t_values,
    const Scalar* w_values, std::size_t begin, std::size_t end,
    const typename SE3<Scalar>::Element& g0_inverse,
    const typename SE3<Scalar>::ClosedFormPsi::Prepared& forward,
    const typename SE3<Scalar>::ClosedFormPsi::Prepared& backward,
    typename SE3<Scalar>::Tangent* residuals) {
  namespace hn = detail::hn;
  using Group = SE3<Scalar>;
  using V = detail::Vec<Scalar>;
  const detail::Tag<Scalar> d;
  const std::size_t lane_count = hn::Lanes(d);
  constexpr const auto& kExpSeries = small_angle::kXMinusSinSeries<Scalar>;
  static constexpr auto kLogSeries =
      small_angle::in_precision<Scalar>(small_angle::detail::one_minus_half_cot_series<20>());

  const V one = hn::Set(d, Scalar(1)), two = hn::Set(d, Scalar(2));
  const V half = hn::Set(d, Scalar(0.5));
  const detail::RotationSetup<Scalar> setup(forward, backward, g0_inverse);
  const auto& angle = setup.angle;
  // exp(-t X)'s translation on backward = prepare(-x) (SE3::ClosedFormPsi::exp).
  V rho_back[3], w_rho_back[3], w_w_rho_back[3];
  for (int k = 0; k < 3; ++k) {
    rho_back[k] = hn::Set(d, backward.rho[k]);
    w_rho_back[k] = hn::Set(d, backward.w_rho[k]);
    w_w_rho_back[k] = hn::Set(d, backward.w_w_rho[k]);
  }
  const V omega_dot_rho_forward = hn::Set(d, forward.omega_dot_rho);
  const V omega_dot_rho_backward = hn::Set(d, backward.omega_dot_rho);
  V g_shift[3];
  for (int r = 0; r < 3; ++r)
    g_shift[r] = hn::Set(d, g0_inverse(r, 3));
  V v0[5][6], v1[5][6];  // [term][component]
  detail::set_zero<Scalar>(v0);
  detail::set_zero<Scalar>(v1);

  for (std::size_t i0 = begin; i0 < end; i0 += lane_count) {
    const std::size_t count = end - i0 < lane_count ? end - i0 : lane_count;
    V t, w, entries[12];
    detail::load_block<Scalar, 12, typename Group::Element>(observations, t_values, w_values, i0,
                                                            count, t, w, entries);
    const V u = one - t;
    const detail::HalfAngles<Scalar> h = detail::half_angles(angle, setup.within_pi, t, u);

    // E = exp(-t X) = [I + a W + b W^2, t rho + b W rho + c W^2 rho] on the
    // backward direction, c = t^3 (x - sin x)/x^3 at x = t theta
    // (small_angle::x_minus_sin_over_x3: its series below 2).
    const V b = two * h.s_sin * h.s_sin * angle.inverse2;
    V e[9], e_shift[3];
    detail::rodrigues(setup.omega_back, two * h.s_sin * h.s_cos * angle.inverse, b, e);
    const V x = t * angle.theta;
    const auto series = hn::Lt(hn::Abs(x), two);
    V x_minus_sin = detail::polynomial(kExpSeries, x * x);
    if (!hn::AllTrue(d, series)) {
      x_minus_sin = hn::IfThenElse(series, x_minus_sin, (x - hn::Sin(d, x)) / (x * x * x));
    }
    const V c = t * t * t * x_minus_sin;
    for (int k = 0; k < 3; ++k)
      e_shift[k] = t * rho_back[k] + b * w_rho_back[k] + c * w_w_rho_back[k];

    // M = E (g0^{-1} f) (affine::compose: rotation a b, shift a t_b + t_a).
    // entries: f's rotation block, then its translation.
    // m: M's rotation block, then its translation (EntryLayout).
    V p[9], p_shift[3], m[12];
    V* const m_shift = m + 9;
    detail::multiply<Scalar>(setup.g, entries, p);
    detail::transform<Scalar>(setup.g, entries + 9, g_shift, p_shift);
    detail::multiply<Scalar>(e, p, m);
    detail::transform<Scalar>(e, p_shift, e_shift, m_shift);

    // r = log(M) (SE3::log): omega from the rotation, then
    // rho = t - W t / 2 + e(|omega|) W (W t), e's series (|omega|^2 < 4).
    V r[6];
    V* const r_rho = r;
    V* const r_omega = r + 3;
    const auto in_first_branch = detail::rotation_log<Scalar>(m, r_omega);
    const V angle2 = r_omega[0] * r_omega[0] + r_omega[1] * r_omega[1] + r_omega[2] * r_omega[2];
    // SE3::log takes e's series below 4, which the first branch keeps to
    // on the group (angle below pi/2); off it, the lane takes SE3::log.
    const auto first = hn::And(in_first_branch, hn::Lt(angle2, hn::Set(d, Scalar(4))));
    const V e_value = detail::polynomial(kLogSeries, angle2);
    V w_t[3], w_w_t[3];
    detail::cross<Scalar>(r_omega, m_shift, w_t);
    detail::cross<Scalar>(r_omega, w_t, w_w_t);
    for (int k = 0; k < 3; ++k)
      r_rho[k] = m_shift[k] - w_t[k] * half + e_value * w_w_t[k];
    // Lanes at or beyond pi/2, or not finite: SE3::log on the lane.
    detail::log_outside<Group, 12>(first, m, r);
    detail::store_residuals<Group>(r, count, residuals + i0);

    const auto c1 =
        detail::psi_coefficients<Scalar, true>(angle, t, h.s_sin, h.s_cos, h.u_sin, h.u_cos);
    const auto c0 =
        detail::psi_coefficients<Scalar, true>(angle, u, h.u_sin, h.u_cos, h.s_sin, h.s_cos);
    const V forward_c[5] = {t, c1.f1, c1.f2, omega_dot_rho_forward * c1.g1,
                            omega_dot_rho_forward * c1.g2};
    const V backward_c[5] = {u, c0.f1, c0.f2, omega_dot_rho_backward * c0.g1,
                             omega_dot_rho_backward * c0.g2};
    detail::accumulate<Scalar, 5, 6>(v0, w, backward_c, r);
    detail::accumulate<Scalar, 5, 6>(v1, w, forward_c, r);
  }
  return detail::reduce<Group, 5, 6>(v0, v1);
}

#endif  // BIREG_HAS_BATCHED_FORCE

// Whether closed_form_sums exists for G in this build.
template <class G>
inline constexpr bool has_closed_form_sums_v = BIREG_HAS_BATCHED_FORCE &&
                                               (std::is_same_v<G, SO3<typename G::Scalar>> ||
                                                std::is_same_v<G, SE3<typename G::Scalar>>);

}  // namespace batched
}  // namespace bireg
