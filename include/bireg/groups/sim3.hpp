// bireg: Sim(3), similarities (scale, rotation, translation), as 4x4
// matrices [s R  t; 0 1] with s > 0.
//
// Tangent coordinates, translation first: x = (rho, omega, sigma), with
// hat(x) = [hat(omega) + sigma I  rho; 0 0]; sigma is the log-scale.
//
// exp: s = e^sigma, R = exp_SO3(omega), t = V rho with
//      V = int_0^1 e^(u sigma) exp(u W) du = A I + B W + C W^2,
// W = hat(omega), theta = |omega|. With E(z) = (e^z - 1)/z and
// z = sigma + i theta (the eigenvalues of sigma I + W are sigma, sigma +- i theta),
//      A = E(sigma),  B = Im E(z) / theta,  C = (E(sigma) - Re E(z)) / theta^2.
// log: sigma = log s, omega = log_SO3(R), rho = V^{-1} t with
//      V^{-1} = a I + b W + c W^2 (coefficients from A, B, C below).
//
// Numerics. A, B and C are entire in (sigma, theta) but their textbook forms
// divide by sigma, theta and |z|^2. Near z = 0 we sum their Taylor series
// (all terms share one sign for sigma >= 0, so nothing cancels); elsewhere
// we use closed forms arranged so that only bounded cancellation occurs for
// sigma >= 0. Negative log-scales are reflected to positive ones through
// exp(x) = exp(-x)^{-1}, i.e. V(sigma, omega) = e^sigma R V(-sigma, -omega),
// which only costs one rotation of a vector; without the reflection the
// series and the closed forms both cancel like e^-|sigma| against 1.
// Measured accuracy (tests/test_sim3.cpp, docs/accuracy.md): a few epsilon
// for log-scales up to +-20 and angles from 0 to pi.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include "bireg/groups/affine.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/small_angle.hpp"

namespace bireg {
namespace sim3_detail {

// Below |z| = 2 the series are used. Their terms are bounded by
// (m + 1) |z|^m / (m + 2)!; 28 terms leave < 1e-21 relative at |z| = 2
// (below long double's epsilon), so one code path serves every precision.
constexpr std::size_t kSeriesTerms = 28;
constexpr long double kSeriesRadius = 2.0L;

// 1 / n! for n = 0 .. kSeriesTerms + 2.
constexpr std::array<long double, kSeriesTerms + 3> inverse_factorials() {
  std::array<long double, kSeriesTerms + 3> table{};
  long double factorial = 1.0L;
  for (std::size_t n = 0; n < table.size(); ++n) {
    if (n > 0) factorial *= static_cast<long double>(n);
    table[n] = 1.0L / factorial;
  }
  return table;
}

// V = A I + B W + C W^2 and V^{-1} = a I + b W + c W^2.
template <class Scalar>
struct Coefficients {
  Scalar A, B, C;
};

// A, B, C for sigma >= 0 and any theta >= 0.
//
// Series (|z| < 2). As divided differences of exp, A = exp[0, sigma],
// B = exp[0, z, conj z], C = exp[0, sigma, z, conj z], so
//   A = sum_m sigma^m / (m + 1)!,  B = sum_m h_m / (m + 2)!,  C = sum_m g_m / (m + 3)!
// with h_m = sum_j z^j conj(z)^(m - j) (real: h_0 = 1, h_1 = 2 sigma,
// h_m = 2 sigma h_{m-1} - |z|^2 h_{m-2}) and g_m = h_m + sigma g_{m-1}.
//
// Closed forms (|z| >= 2), from B |z|^2 = Im(conj z (e^z - 1)) / theta and
// C |z|^2 = (A |z|^2 - Re(conj z (e^z - 1))) / theta^2 with A sigma = e^sigma - 1:
//   B = (1 + e^sigma (sigma sinc(theta) - cos theta)) / |z|^2,
//   C = (A + e^sigma (sigma (1 - cos theta)/theta^2 - sinc(theta))) / |z|^2.
// For sigma >= 0 and |z| >= 2 the subtraction in C loses at most a factor
// ~2.5 (worst near sigma = 0.3, theta = 2) and the one in B less.
template <class Scalar>
Coefficients<Scalar> coefficients(Scalar sigma, Scalar theta) {
  using std::cos;
  using std::exp;
  using std::expm1;
  using std::sqrt;
  static constexpr auto kInverseFactorial = inverse_factorials();
  const Scalar modulus2 = sigma * sigma + theta * theta;
  if (modulus2 < Scalar(kSeriesRadius * kSeriesRadius)) {
    // The terms of index m are bounded by |z|^m / m! (h_m by (m + 1) |z|^m,
    // g_m by (m + 1)(m + 2) |z|^m / 2), a bound that falls from m = 2 on
    // and also bounds the rest of the series past m. For sigma >= 0 every
    // term is positive and A >= 1, B >= 1/2, C >= 1/6, so stopping once the
    // bound is below epsilon / 64 leaves less than epsilon / 10 relative:
    // in double 12 terms at |z| = 0.1, 21 at 1, 26 at 2 (of kSeriesTerms = 28).
    const Scalar modulus = sqrt(modulus2);
    const Scalar stop = std::numeric_limits<Scalar>::epsilon() / 64;
    Scalar sigma_power = 1, h_previous = 0, h = 1, g = 1, bound = 1;
    Coefficients<Scalar> c{0, 0, 0};
    for (std::size_t m = 0; m < kSeriesTerms; ++m) {
      if (m > 0) {
        const Scalar h_next = Scalar(2) * sigma * h - modulus2 * h_previous;
        h_previous = h;
        h = h_next;
        g = h + sigma * g;
        sigma_power *= sigma;
        bound *= modulus / static_cast<Scalar>(m);
      }
      c.A += sigma_power * static_cast<Scalar>(kInverseFactorial[m + 1]);
      c.B += h * static_cast<Scalar>(kInverseFactorial[m + 2]);
      c.C += g * static_cast<Scalar>(kInverseFactorial[m + 3]);
      if (m >= 2 && bound < stop) break;
    }
    return c;
  }
  const Scalar e_sigma = exp(sigma);
  const Scalar sinc = small_angle::sin_over_x(theta);
  const Scalar one_minus_cos_over_theta2 = small_angle::one_minus_cos_over_x2(theta);
  // |z| >= 2 with theta = 0 means sigma >= 2: no division by a small sigma.
  const Scalar a = sigma > Scalar(0) ? expm1(sigma) / sigma : Scalar(1);
  return {a, (Scalar(1) + e_sigma * (sigma * sinc - cos(theta))) / modulus2,
          (a + e_sigma * (sigma * one_minus_cos_over_theta2 - sinc)) / modulus2};
}

// V^{-1} = a I + b W + c W^2 from V's A, B, C. V is a function of W, whose
// eigenvalues are 0 and +-i theta, so V^{-1}'s coefficients follow from
// 1/A and 1/(P + i Q) with P = A - C theta^2, Q = B theta:
//   a = 1/A,  b = -B / (P^2 + Q^2),  c = (B^2 - C P) / (A (P^2 + Q^2)),
// the last free of theta^2 denominators. Computed with B, C, P, Q divided by
// A so that e^(2 sigma) never overflows. P^2 + Q^2 = |E(z)|^2 / A^2 > 0
// for theta < 2 pi.
template <class Scalar>
Coefficients<Scalar> inverse_coefficients(const Coefficients<Scalar>& v, Scalar theta) {
  const Scalar b = v.B / v.A;
  const Scalar c = v.C / v.A;
  const Scalar p = Scalar(1) - c * theta * theta;
  const Scalar q = b * theta;
  const Scalar modulus2 = p * p + q * q;
  return {Scalar(1) / v.A, -b / (v.A * modulus2), (b * b - c * p) / (v.A * modulus2)};
}

// (a I + b hat(omega) + c hat(omega)^2) v, with cross products.
template <class Vector3, class Scalar>
Vector3 apply(const Coefficients<Scalar>& k, const Vector3& omega, const Vector3& v) {
  const Vector3 w_v = omega.cross(v);
  return k.A * v + k.B * w_v + k.C * omega.cross(w_v);
}

}  // namespace sim3_detail

template <class Scalar_ = double>
struct Sim3 {
  using Scalar = Scalar_;
  static constexpr int dof = 7;
  static constexpr int matrix_size = 4;
  static constexpr const char* name = "Sim3";
  using Element = Eigen::Matrix<Scalar, 4, 4>;
  using Tangent = Eigen::Matrix<Scalar, 7, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, 7, 7>;
  using Algebra = Eigen::Matrix<Scalar, 4, 4>;
  using Rotation = SO3<Scalar>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

  static Element identity() { return Element::Identity(); }
  static Element compose(const Element& a, const Element& b) { return affine::compose(a, b); }
  // (s R)^{-1} = R^T / s = (s R)^T / s^2.
  static Element inverse(const Element& g) {
    const Matrix3 scaled_rotation = g.template topLeftCorner<3, 3>();
    const Matrix3 inverse_block = scaled_rotation.transpose() / scale_squared(scaled_rotation);
    Element inv = Element::Identity();
    inv.template topLeftCorner<3, 3>() = inverse_block;
    inv.template topRightCorner<3, 1>() = -inverse_block * g.template topRightCorner<3, 1>();
    return inv;
  }

  static Element exp(const Tangent& x) {
    using std::exp;
    using std::sqrt;
    const Vector3 rho = x.template head<3>();
    const Vector3 omega = x.template segment<3>(3);
    const Scalar sigma = x[6];
    const Scalar theta = sqrt(omega.squaredNorm());
    const Scalar scale = exp(sigma);
    const Matrix3 rotation = Rotation::exp(omega);
    Vector3 translation;
    if (sigma >= Scalar(0)) {
      translation = sim3_detail::apply(sim3_detail::coefficients(sigma, theta), omega, rho);
    } else {  // V(sigma, omega) rho = e^sigma R V(-sigma, -omega) rho
      const Vector3 reflected =
          sim3_detail::apply(sim3_detail::coefficients(-sigma, theta), Vector3(-omega), rho);
      translation = scale * (rotation * reflected);
    }
    Element g = Element::Identity();
    g.template topLeftCorner<3, 3>() = scale * rotation;
    g.template topRightCorner<3, 1>() = translation;
    return g;
  }

  // Principal logarithm: |omega| in [0, pi]. The scale is the RMS column
  // norm of the 3x3 block, which is exact on the group and the nearest
  // similarity's scale for slightly perturbed input.
  static Tangent log(const Element& g) {
    using std::log;
    using std::sqrt;
    const Matrix3 scaled_rotation = g.template topLeftCorner<3, 3>();
    const Vector3 translation = g.template topRightCorner<3, 1>();
    const Scalar s2 = scale_squared(scaled_rotation);
    const Scalar scale = sqrt(s2);
    const Scalar sigma = log(s2) / Scalar(2);
    const Matrix3 rotation = scaled_rotation / scale;
    const Vector3 omega = Rotation::log(rotation);
    const Scalar theta = sqrt(omega.squaredNorm());
    Tangent x;
    if (sigma >= Scalar(0)) {
      const auto inverse =
          sim3_detail::inverse_coefficients(sim3_detail::coefficients(sigma, theta), theta);
      x.template head<3>() = sim3_detail::apply(inverse, omega, translation);
    } else {  // V^{-1}(sigma, omega) = V^{-1}(-sigma, -omega) R^T / s
      const auto inverse =
          sim3_detail::inverse_coefficients(sim3_detail::coefficients(-sigma, theta), theta);
      const Vector3 unrotated = rotation.transpose() * translation / scale;
      x.template head<3>() = sim3_detail::apply(inverse, Vector3(-omega), unrotated);
    }
    x.template segment<3>(3) = omega;
    x[6] = sigma;
    return x;
  }

  static Algebra hat(const Tangent& x) {
    Algebra m = Algebra::Zero();
    m.template topLeftCorner<3, 3>() =
        Rotation::hat(x.template segment<3>(3)) + x[6] * Matrix3::Identity();
    m.template topRightCorner<3, 1>() = x.template head<3>();
    return m;
  }
  // Reads back the entries hat writes (like SO3::vee, no projection), so
  // vee(hat(x)) == x exactly.
  static Tangent vee(const Algebra& m) {
    Tangent x;
    x.template head<3>() = m.template topRightCorner<3, 1>();
    x.template segment<3>(3) = Rotation::vee(m.template topLeftCorner<3, 3>());
    x[6] = m(0, 0);
    return x;
  }

  // [x1, x2] = ((W1 + s1) rho2 - (W2 + s2) rho1, omega1 x omega2, 0), so
  // ad_x = [hat(omega) + sigma I, hat(rho), -rho; 0, hat(omega), 0; 0, 0, 0].
  static AdMatrix ad(const Tangent& x) {
    const Vector3 rho = x.template head<3>();
    const Matrix3 w = Rotation::hat(x.template segment<3>(3));
    AdMatrix m = AdMatrix::Zero();
    m.template block<3, 3>(0, 0) = w + x[6] * Matrix3::Identity();
    m.template block<3, 3>(0, 3) = Rotation::hat(rho);
    m.template block<3, 1>(0, 6) = -rho;
    m.template block<3, 3>(3, 3) = w;
    return m;
  }

  // ad_x is block triangular with eigenvalues sigma, sigma +- i theta, 0,
  // +-i theta and 0: its spectral radius is |sigma + i theta|.
  static Scalar ad_spectral_radius(const Tangent& x) {
    using std::sqrt;
    return sqrt(x.template segment<3>(3).squaredNorm() + x[6] * x[6]);
  }

  // g hat(x) g^{-1} = hat(s R rho + t x (R omega) - sigma t, R omega, sigma):
  // Ad_g = [s R, hat(t) R, -t; 0, R, 0; 0, 0, 1].
  static AdMatrix Ad(const Element& g) {
    using std::sqrt;
    const Matrix3 scaled_rotation = g.template topLeftCorner<3, 3>();
    const Vector3 t = g.template topRightCorner<3, 1>();
    const Matrix3 r = scaled_rotation / sqrt(scale_squared(scaled_rotation));
    AdMatrix m = AdMatrix::Zero();
    m.template block<3, 3>(0, 0) = scaled_rotation;
    m.template block<3, 3>(0, 3) = Rotation::hat(t) * r;
    m.template block<3, 1>(0, 6) = -t;
    m.template block<3, 3>(3, 3) = r;
    m(6, 6) = Scalar(1);
    return m;
  }

  // The 3x3 block is s R with s > 0 and R in SO(3): (sR)^T (sR) / s^2 = I
  // and det > 0, to within tol (max-norm, relative to the scale), and the
  // last row is (0, 0, 0, 1); all finite.
  static bool is_element(const Element& g, Scalar tol = default_element_tolerance<Scalar>()) {
    if (!g.allFinite()) return false;
    const Scalar last_row = (g.template bottomRows<1>() - Eigen::Matrix<Scalar, 1, 4>(0, 0, 0, 1))
                                .cwiseAbs()
                                .maxCoeff();
    const Matrix3 block = g.template topLeftCorner<3, 3>();
    const Scalar s2 = scale_squared(block);
    if (!(s2 > Scalar(0)) || !(last_row <= tol)) return false;
    const Scalar orthogonality =
        (block.transpose() * block / s2 - Matrix3::Identity()).cwiseAbs().maxCoeff();
    return orthogonality <= tol && block.determinant() > Scalar(0);
  }

 private:
  // s^2 = ||s R||_F^2 / 3.
  static Scalar scale_squared(const Matrix3& scaled_rotation) {
    return scaled_rotation.squaredNorm() / Scalar(3);
  }
};

using Sim3d = Sim3<double>;
using Sim3f = Sim3<float>;

}  // namespace bireg
