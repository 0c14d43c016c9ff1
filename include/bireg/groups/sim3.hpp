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
#include <utility>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include "bireg/groups/affine.hpp"
#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/groups/tolerance.hpp"
#include "bireg/math/psi_closed_form.hpp"
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

// ---- The closed-form psi (Sim3::ClosedFormPsi) ------------------------------
//
// Complex numbers written out, so that a product is four multiplications
// (std::complex's operator* checks for infinities through a library call).
template <class Scalar>
struct Complex {
  Scalar re, im;
  Complex conj() const { return {re, -im}; }
  Scalar abs() const {
    using std::sqrt;
    return sqrt(re * re + im * im);
  }
  friend Complex operator+(const Complex& a, const Complex& b) {
    return {a.re + b.re, a.im + b.im};
  }
  friend Complex operator-(const Complex& a, const Complex& b) {
    return {a.re - b.re, a.im - b.im};
  }
  friend Complex operator-(const Complex& a) { return {-a.re, -a.im}; }
  friend Complex operator*(const Complex& a, const Complex& b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
  }
  friend Complex operator*(Scalar k, const Complex& a) { return {k * a.re, k * a.im}; }
  friend Complex operator/(const Complex& a, const Complex& b) {
    const Scalar inverse_norm2 = 1 / (b.re * b.re + b.im * b.im);
    return {(a.re * b.re + a.im * b.im) * inverse_norm2,
            (a.im * b.re - a.re * b.im) * inverse_norm2};
  }
};

// Below this modulus the functions below are their first-order Taylor
// polynomials, exact to rounding (the next term is |w|^2 / 12 < epsilon).
template <class Scalar>
Scalar taylor_radius() {
  using std::sqrt;
  return sqrt(std::numeric_limits<Scalar>::epsilon());
}

// e^w - 1 from expm1 of Re w and sin and cos of Im w / 2:
//   Re = expm1(a) - 2 sin^2(b/2) e^a,  Im = 2 e^a sin(b/2) cos(b/2),
// accurate relative to |e^w - 1| for every w (no cancellation near w = 0).
template <class Scalar>
Complex<Scalar> expm1_from(Scalar expm1_re, Scalar half_sin, Scalar half_cos) {
  const Scalar exp_re = 1 + expm1_re;
  return {expm1_re - 2 * half_sin * half_sin * exp_re, 2 * exp_re * half_sin * half_cos};
}
template <class Scalar>
Complex<Scalar> expm1(const Complex<Scalar>& w) {
  using std::cos;
  using std::expm1;
  using std::sin;
  return expm1_from(expm1(w.re), sin(w.im / 2), cos(w.im / 2));
}
template <class Scalar>
Complex<Scalar> exp(const Complex<Scalar>& w) {
  using std::cos;
  using std::exp;
  using std::sin;
  const Scalar modulus = exp(w.re);
  return {modulus * cos(w.im), modulus * sin(w.im)};
}

// q(w) = (1 - e^{-w}) / w = int_0^1 e^{-u w} du, from e = e^{-w} - 1.
template <class Scalar>
Complex<Scalar> q_from(const Complex<Scalar>& w, const Complex<Scalar>& e) {
  if (w.abs() < taylor_radius<Scalar>()) return {1 - w.re / 2, -w.im / 2};
  return -e / w;
}
// R(w) = 1 / q(w) = w / (1 - e^{-w}), from e = e^{-w} - 1.
template <class Scalar>
Complex<Scalar> r_from(const Complex<Scalar>& w, const Complex<Scalar>& e) {
  if (w.abs() < taylor_radius<Scalar>()) return {1 + w.re / 2, w.im / 2};
  return -w / e;
}
// (e^w - 1) / w.
template <class Scalar>
Complex<Scalar> phi1(const Complex<Scalar>& w) {
  if (w.abs() < taylor_radius<Scalar>()) return {1 + w.re / 2, w.im / 2};
  return expm1(w) / w;
}

// e[0, w1, w2], the second divided difference of exp at 0, w1 and w2.
// Both |w| < 1: its series sum_m h_m / (m + 2)!, h_m = sum_j w1^j w2^(m-j)
// (|h_m| <= (m + 1) r^m with r the larger modulus; stopped once that bound
// is below epsilon / 64, which also bounds the rest). Otherwise, with
// |w1| >= |w2| >= 0 and |w1| >= 1,
//   e[0, w1, w2] = (e^{w2} phi1(w1 - w2) - phi1(w2)) / w1,
// whose subtraction loses at most a few digits' worth of |w1| >= 1.
template <class Scalar>
Complex<Scalar> exp_second_divided_difference(Complex<Scalar> w1, Complex<Scalar> w2) {
  Scalar r1 = w1.abs();
  const Scalar r2 = w2.abs();
  if (r2 > r1) {
    std::swap(w1, w2);
    r1 = r2;
  }
  if (r1 >= 1) return (exp(w2) * phi1(w1 - w2) - phi1(w2)) / w1;
  // (m + 1) r^m / (m + 2)! < 1e-30 for r < 1 at m = kSeriesTerms.
  static constexpr auto kInverseFactorial = inverse_factorials();
  const Scalar stop = std::numeric_limits<Scalar>::epsilon() / 64;
  Complex<Scalar> sum{0, 0}, h{1, 0}, w2_power{1, 0};
  Scalar r_power = 1;
  for (std::size_t m = 0; m <= kSeriesTerms; ++m) {
    const Scalar inverse_factorial = static_cast<Scalar>(kInverseFactorial[m + 2]);
    sum = sum + inverse_factorial * h;
    if (Scalar(m + 1) * r_power * inverse_factorial < stop) break;
    w2_power = w2_power * w2;
    h = w1 * h + w2_power;
    r_power *= r1;
  }
  return sum;
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

  // The angle of R in the block s R, in [0, pi] (capabilities.hpp,
  // turn_angle; the block is divided by s first, since SO3::turn_angle reads
  // the trace of a rotation). Conjugation by (s', R', t') conjugates R by R'.
  static Scalar turn_angle(const Element& g) {
    using std::sqrt;
    const Matrix3 scaled_rotation = g.template topLeftCorner<3, 3>();
    return Rotation::turn_angle(scaled_rotation / sqrt(scale_squared(scaled_rotation)));
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

  // psi_s(ad_x) r in closed form (DESIGN.md section 2, "Exact form"), exact
  // to rounding for every log-scale and angle in the principal domain.
  //
  // ad_x = [W + sigma I, P, -rho; 0, W, 0; 0, 0, 0] (W = hat(omega),
  // P = hat(rho)). In an orthonormal frame (e1, e2, e3 = omega / theta),
  // write plane components as complex numbers, v_+ = e1.v + i e2.v, and
  // v_0 = e3.v. W is normal with eigenvalues 0 and +-i theta, and P has no
  // entry between the +i theta and -i theta eigenvectors, so with
  // F = psi_s, F[z1, z2] its divided difference, G(z) = F[z, 0],
  // z = sigma + i theta and r = (a, b, c):
  //   out_rho,0   = F(sigma) a_0 + Im(F[sigma, i theta] conj(rho_+) b_+) - c G(sigma) rho_0
  //   out_rho,+   = F(z) a_+ + i rho_0 F[z, i theta] b_+ - G(z) rho_+ (c + i b_0)
  //   out_omega,0 = s b_0,  out_omega,+ = F(i theta) b_+,  out_sigma = s c.
  // Nothing divides by theta. F(w) = s q(w) R(s w) with q(w) = (1 - e^{-w})/w
  // and R = 1/q; a divided difference with |z1 - z2| >= 1 is the quotient
  // (F(z1) - F(z2)) / (z1 - z2), a closer one the product rule
  //   F[z1, z2] = s R(s z2) (q[z1, z2] - F(z1) q[s z1, s z2]),
  // q[u, v] = -e[0, -u, -v] (sim3_detail::exp_second_divided_difference),
  // free of the cancellation the quotient has there. Checked against a
  // 40-digit reference for log-scales 0 .. +-20, angles 0 .. pi and
  // s from 1e-8 to 1 (tests/test_exact_inverse_differential.cpp).
  struct ClosedFormPsi {
    using SinCos = psi_closed_form::SinCos<Scalar>;
    using Complex = sim3_detail::Complex<Scalar>;
    // The four divided differences: (sigma, 0), (z, 0), (sigma, i theta), (z, i theta).
    static constexpr int kPairs = 4;
    struct Prepared {
      Scalar theta, sigma;
      Vector3 e1, e2, e3;
      Scalar rho_0;
      Complex rho_plus;
      Complex q_sigma, q_z, q_i;           // q at sigma, z and i theta
      std::array<bool, kPairs> quotient;   // |z1 - z2| >= 1
      std::array<Complex, kPairs> q_pair;  // q[z1, z2] where not a quotient
    };
    // The exact method uses the closed form from |sigma + i theta| (the
    // spectral radius of ad_x) = kMinAngle on. Per observation-iteration of
    // a fit (paper solver, N = 1000, measured on the 2-core VM while it
    // compiled, so coarse), the closed form costs 4x the series at 0.5 and
    // about the same from 1 to 2. From ~3.6 on the series needs more than
    // its kMaxSeriesOrder = 64 terms for epsilon, so only the closed form
    // stays exact there.
    static constexpr double kMinAngle = 2.0;
    static Scalar angle(const Tangent& x) { return ad_spectral_radius(x); }
    static Prepared prepare(const Tangent& x) {
      using std::abs;
      using std::copysign;
      using std::cos;
      using std::expm1;
      using std::sin;
      using std::sqrt;
      Prepared p;
      const Vector3 rho = x.template head<3>(), omega = x.template segment<3>(3);
      p.sigma = x[6];
      p.theta = sqrt(omega.squaredNorm());
      // A right-handed frame around omega (Duff et al., "Building an
      // orthonormal basis, revisited", 2017); any frame when omega = 0.
      p.e3 = p.theta > 0 ? Vector3(omega / p.theta) : Vector3(0, 0, 1);
      const Scalar sign = copysign(Scalar(1), p.e3.z());
      const Scalar a = -1 / (sign + p.e3.z()), b = p.e3.x() * p.e3.y() * a;
      p.e1 = Vector3(1 + sign * p.e3.x() * p.e3.x() * a, sign * b, -sign * p.e3.x());
      p.e2 = Vector3(b, sign + p.e3.y() * p.e3.y() * a, -p.e3.y());
      p.rho_0 = p.e3.dot(rho);
      p.rho_plus = {p.e1.dot(rho), p.e2.dot(rho)};
      const Complex sigma{p.sigma, 0}, z{p.sigma, p.theta}, i_theta{0, p.theta};
      const Scalar expm1_sigma = expm1(-p.sigma);
      const Scalar half_sin = sin(p.theta / 2), half_cos = cos(p.theta / 2);
      p.q_sigma = sim3_detail::q_from(sigma, Complex{expm1_sigma, 0});
      p.q_z = sim3_detail::q_from(z, sim3_detail::expm1_from(expm1_sigma, -half_sin, half_cos));
      p.q_i = sim3_detail::q_from(i_theta, sim3_detail::expm1_from(Scalar(0), -half_sin, half_cos));
      const std::array<std::pair<Complex, Complex>, kPairs> pairs = {
          {{sigma, Complex{0, 0}}, {z, Complex{0, 0}}, {sigma, i_theta}, {z, i_theta}}};
      for (int k = 0; k < kPairs; ++k) {
        const auto& [z1, z2] = pairs[static_cast<std::size_t>(k)];
        const auto index = static_cast<std::size_t>(k);
        p.quotient[index] = (z1 - z2).abs() >= 1;
        p.q_pair[index] = p.quotient[index] ? Complex{0, 0}
                                            : -sim3_detail::exp_second_divided_difference(-z1, -z2);
      }
      return p;
    }
    static Tangent apply(const Prepared& p, Scalar s, const SinCos& s_half, const SinCos&,
                         const Tangent& r) {
      using std::expm1;
      if (s == 0) return Tangent::Zero();
      const Complex sigma{p.sigma, 0}, z{p.sigma, p.theta}, i_theta{0, p.theta}, zero{0, 0};
      // e^{-s w} - 1 for w = sigma, z, i theta: one expm1 and s theta / 2's sin and cos.
      const Scalar expm1_sigma = expm1(-s * p.sigma);
      const Complex r_sigma = sim3_detail::r_from(s * sigma, Complex{expm1_sigma, 0});
      const Complex r_z =
          sim3_detail::r_from(s * z, sim3_detail::expm1_from(expm1_sigma, -s_half.sin, s_half.cos));
      const Complex r_i = sim3_detail::r_from(
          s * i_theta, sim3_detail::expm1_from(Scalar(0), -s_half.sin, s_half.cos));
      const Complex f_sigma = s * (p.q_sigma * r_sigma), f_z = s * (p.q_z * r_z),
                    f_i = s * (p.q_i * r_i), f_0{s, 0};
      const Complex one{1, 0};
      const auto divided = [&](int k, const Complex& z1, const Complex& z2, const Complex& f1,
                               const Complex& f2, const Complex& r2) {
        const auto index = static_cast<std::size_t>(k);
        if (p.quotient[index]) return (f1 - f2) / (z1 - z2);
        const Complex q_s = -sim3_detail::exp_second_divided_difference(-(s * z1), -(s * z2));
        return s * (r2 * (p.q_pair[index] - f1 * q_s));
      };
      const Complex g_sigma = divided(0, sigma, zero, f_sigma, f_0, one);
      const Complex g_z = divided(1, z, zero, f_z, f_0, one);
      const Complex d_sigma_i = divided(2, sigma, i_theta, f_sigma, f_i, r_i);
      const Complex d_z_i = divided(3, z, i_theta, f_z, f_i, r_i);

      const Vector3 a = r.template head<3>(), b = r.template segment<3>(3);
      const Scalar c = r[6];
      const Scalar a_0 = p.e3.dot(a), b_0 = p.e3.dot(b);
      const Complex a_plus{p.e1.dot(a), p.e2.dot(a)}, b_plus{p.e1.dot(b), p.e2.dot(b)};
      const Scalar rho_out_0 =
          f_sigma.re * a_0 + (d_sigma_i * p.rho_plus.conj() * b_plus).im - c * g_sigma.re * p.rho_0;
      const Complex rho_out_plus = f_z * a_plus + Complex{0, p.rho_0} * (d_z_i * b_plus) -
                                   g_z * p.rho_plus * Complex{c, b_0};
      const Complex omega_out_plus = f_i * b_plus;
      Tangent out;
      out.template head<3>() = rho_out_0 * p.e3 + rho_out_plus.re * p.e1 + rho_out_plus.im * p.e2;
      out.template segment<3>(3) =
          s * b_0 * p.e3 + omega_out_plus.re * p.e1 + omega_out_plus.im * p.e2;
      out[6] = s * c;
      return out;
    }
  };

 private:
  // s^2 = ||s R||_F^2 / 3.
  static Scalar scale_squared(const Matrix3& scaled_rotation) {
    return scaled_rotation.squaredNorm() / Scalar(3);
  }
};

using Sim3d = Sim3<double>;
using Sim3f = Sim3<float>;

}  // namespace bireg
