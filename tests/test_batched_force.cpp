// The batched SO(3) and SE(3) forces (regression/batched_force.hpp) against
// the scalar loop they replace (estimating_equations.hpp, closed_form_force
// with batched = false), in builds that force one instruction set each
// (tests/CMakeLists.txt: AVX2 and AVX-512, with -march). Bounds derived
// from what the kernels change:
//   - a residual: the vector sin, cos and atan differ from the scalar ones
//     by a few ulp, so E = exp(-t X) and M = E g0^{-1} f differ by a few ulp
//     of their entries' scale (rotation entries in [-1, 1]; translations
//     here below 4), and r = log(M) by that times log's condition number,
//     |w| / sin|w| at the rotation angle |w| (the axis is ill-conditioned
//     near pi) and, for the translation, the scale (4 + |r|):
//     |dr| <= 64 eps (1 + |w| / sin|w|) (4 + |r|);
//   - the sums: each term w c_k r moves by w |c_k| |dr|, and reordering a
//     sum of n terms moves it by at most n eps sum |w c_k r|; combine
//     multiplies by at most (1 + |x|)^2.
// A fit is the zero of the force: its endpoints agree to 1e-13 (issue
// "Speed toward the hardware", point 3), and with 1 and 2 threads the
// batched fit is bit-identical (chunks of kChunkSize either way). So do
// the layers above fit() that pass RegressionOptions on: the permutation
// trend test (its statistic to 1e-13, its counts exactly) and local
// regression (every query's velocity to 1e-13 relative).
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/batched_force.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "catch.hpp"

// This file is compiled only for SIMD targets (tests/CMakeLists.txt): a
// flag that stopped selecting the instruction set would otherwise leave it
// testing nothing.
#if !BIREG_HAS_BATCHED_FORCE
#error "built for a SIMD target, but the batched kernel is absent"
#endif

namespace {

constexpr double kPi = 3.141592653589793238462643383279502884;
using Vector3 = Eigen::Vector3d;

// The rounding unit of G's scalar.
template <class G>
constexpr double eps_of() {
  return std::numeric_limits<typename G::Scalar>::epsilon();
}

// The same group in double precision.
template <class G>
struct InDouble;
template <template <class> class Group, class Scalar>
struct InDouble<Group<Scalar>> {
  using type = Group<double>;
};

// tests/CMakeLists.txt builds this file only for the instruction sets
// this machine executes; a binary run elsewhere fails rather than passing
// without checking anything.
void require_target() {
  if ((hwy::SupportedTargets() & HWY_STATIC_TARGET) != 0) return;
  FAIL("this machine lacks " << bireg::batched::target_name());
}

Vector3 random_axis(std::mt19937& rng) {
  std::normal_distribution<double> normal(0, 1);
  Vector3 v(normal(rng), normal(rng), normal(rng));
  return v / v.norm();
}

// The rotation part of a tangent vector, and a tangent of rotation part
// `omega` with translation part `rho` (SE(3): (rho, omega)).
template <class G>
auto rotation_of(const typename G::Tangent& x) {
  return x.template tail<3>();
}
template <class G>
typename G::Tangent tangent(const Vector3& omega, const Vector3& rho) {
  using Scalar = typename G::Scalar;
  if constexpr (G::dof == 3) {
    static_cast<void>(rho);
    return omega.cast<Scalar>();
  } else {
    typename G::Tangent x;
    x << rho.cast<Scalar>(), omega.cast<Scalar>();
    return x;
  }
}

template <class G>
struct Data {
  std::vector<typename G::Element> f;
  bireg::Problem<typename G::Scalar> problem;
};

// f_i = g0 exp(t_i x) exp(noise_i), drawn in double and rounded to G's
// scalar: mostly small residuals, one in ten of rotation angle uniform in
// [0, pi - 1e-6) (the lanes beyond pi/2 take the group's log); t = 0 and
// t = 1 exactly at some observations.
template <class G, class D = typename InDouble<G>::type>
Data<G> make_data(std::size_t n, const typename D::Element& g0, const typename D::Tangent& x,
                  unsigned seed) {
  using Scalar = typename G::Scalar;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  Data<G> data;
  for (std::size_t i = 0; i < n; ++i) {
    double t = uniform(rng);
    if (i % 97 == 0) t = 0;
    if (i % 89 == 0) t = 1;
    Vector3 omega = 0.05 * Vector3(normal(rng), normal(rng), normal(rng));
    if (i % 10 == 3) omega = (kPi - 1e-6) * uniform(rng) * random_axis(rng);
    const Vector3 rho = 0.05 * Vector3(normal(rng), normal(rng), normal(rng));
    const typename D::Element f =
        D::compose(D::compose(g0, D::exp(t * x)), D::exp(tangent<D>(omega, rho)));
    data.f.push_back(f.template cast<Scalar>());
    data.problem.t.push_back(Scalar(t));
    data.problem.w.push_back(Scalar(0.05 + uniform(rng)));
  }
  return data;
}

template <class G>
struct Evaluation {
  bireg::Force<G> force;
  std::vector<typename G::Tangent> residuals;
};

template <class G, class Observations>
Evaluation<G> evaluate(const Observations& f, const bireg::Problem<typename G::Scalar>& problem,
                       const typename G::Element& g0, const typename G::Tangent& x, bool batched) {
  Evaluation<G> e;
  e.residuals.assign(f.size(), G::Tangent::Constant(-7));
  e.force = bireg::estimating_detail::closed_form_force<G>(f, problem, g0, x, e.residuals, nullptr,
                                                           batched);
  return e;
}

template <class G>
double residual_bound(const typename G::Tangent& r) {
  const double angle = double(rotation_of<G>(r).norm());
  // |w| / sin|w|, floored at 1e-6 where a rounded angle reaches pi.
  const double condition = angle < 1e-8 ? 1 : angle / std::max(std::abs(std::sin(angle)), 1e-6);
  return 64 * eps_of<G>() * (1 + condition) * (4 + double(r.norm()));
}

// The bound of the file's comment on |F_batched - F_scalar| per direction,
// from the scalar path's coefficients.
template <class G>
std::pair<double, double> force_bounds(const Data<G>& data, const typename G::Tangent& x,
                                       const std::vector<typename G::Tangent>& residuals) {
  using Scalar = typename G::Scalar;
  using Psi = typename G::ClosedFormPsi;
  const auto forward = Psi::prepare(x), backward = Psi::prepare(-x);
  const Scalar theta = forward.theta;
  const auto half = bireg::psi_closed_form::SinCos<Scalar>::of(theta / 2);
  const double n = double(data.f.size());
  double moved0 = 0, moved1 = 0, size0 = 0, size1 = 0;
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    const Scalar t = data.problem.t[i];
    const double w = double(data.problem.w[i]);
    const auto angles = bireg::psi_closed_form::half_angle_pair(theta, half, t);
    const auto c0 = Psi::coefficients(backward, 1 - t, angles.u_half, angles.s_half);
    const auto c1 = Psi::coefficients(forward, t, angles.s_half, angles.u_half);
    const double r = double(residuals[i].norm()), dr = residual_bound<G>(residuals[i]);
    for (int k = 0; k < Psi::kTerms; ++k) {
      moved0 += w * std::abs(double(c0[k])) * dr;
      moved1 += w * std::abs(double(c1[k])) * dr;
      size0 += w * std::abs(double(c0[k])) * r;
      size1 += w * std::abs(double(c1[k])) * r;
    }
  }
  const double combine = (1 + double(x.norm())) * (1 + double(x.norm()));
  const double eps = eps_of<G>();
  return {combine * (moved0 + n * eps * size0), combine * (moved1 + n * eps * size1)};
}

const char* precision_of(double eps) {
  return eps > 1e-10 ? "float" : "double";
}

// tooth: how small the force's bound must be against the force for the
// comparison to catch a wrong coefficient or a lost lane: 1e-7 in double.
// In float (tooth 0: not checked) the worst case of reordering 1e4 terms,
// n eps = 1e-3 of their size, exceeds the force itself, so there the
// per-residual comparison is what catches a wrong lane.
template <class G>
void check_random_data(double tooth) {
  using D = typename InDouble<G>::type;
  using Scalar = typename G::Scalar;
  INFO(G::name << " in " << precision_of(eps_of<G>()) << ", target "
               << bireg::batched::target_name());
  std::mt19937 rng(41);
  std::normal_distribution<double> normal(0, 1);
  // Angles of X across the closed form's range, pi itself (or an ulp
  // above) and 3.3 beyond it (both half angles directly); n not a
  // multiple of any lane count and above one chunk.
  for (const double theta : {bireg::kExactMinAngle, 0.7, 1.5, 2.5, 3.0, kPi - 1e-9, kPi, 3.3}) {
    const typename D::Element g0 =
        D::exp(tangent<D>(2.0 * random_axis(rng), Vector3(normal(rng), normal(rng), 0.5)));
    const typename D::Tangent x = tangent<D>(theta * random_axis(rng), 1.3 * random_axis(rng));
    const Data<G> data = make_data<G>(10007, g0, x, unsigned(theta * 1000));
    const typename G::Element g0_s = g0.template cast<Scalar>();
    const typename G::Tangent x_s = x.template cast<Scalar>();
    const Evaluation<G> scalar = evaluate<G>(data.f, data.problem, g0_s, x_s, false);
    const Evaluation<G> batched = evaluate<G>(data.f, data.problem, g0_s, x_s, true);
    INFO("theta " << theta);
    std::size_t beyond = 0;
    for (std::size_t i = 0; i < data.f.size(); ++i) {
      INFO("observation " << i << " t " << data.problem.t[i]);
      const auto& s = scalar.residuals[i];
      REQUIRE(double((batched.residuals[i] - s).template lpNorm<Eigen::Infinity>()) <=
              residual_bound<G>(s));
      beyond += rotation_of<G>(s).norm() >= Scalar(kPi / 2);
    }
    CHECK(beyond > 300);  // the lanes of the group's own log were exercised
    const auto [bound0, bound1] = force_bounds(data, x_s, scalar.residuals);
    CHECK(double((batched.force.v0 - scalar.force.v0).norm()) <= bound0);
    CHECK(double((batched.force.v1 - scalar.force.v1).norm()) <= bound1);
    if (tooth > 0) {
      CHECK(bound0 < tooth * double(scalar.force.v0.norm()));
      CHECK(bound1 < tooth * double(scalar.force.v1.norm()));
    }
    // A container without data() takes the lane-by-lane copy instead of
    // the gathers: the same numbers in the lanes, so the same results.
    const std::deque<typename G::Element> deque(data.f.begin(), data.f.end());
    const Evaluation<G> from_deque = evaluate<G>(deque, data.problem, g0_s, x_s, true);
    CHECK(from_deque.residuals == batched.residuals);
    CHECK(from_deque.force.v0 == batched.force.v0);
    CHECK(from_deque.force.v1 == batched.force.v1);
  }
}

template <class G>
void check_edges() {
  using D = typename InDouble<G>::type;
  using Scalar = typename G::Scalar;
  INFO(G::name << " in " << precision_of(eps_of<G>()));
  std::mt19937 rng(7);
  const typename D::Element g0 = D::exp(tangent<D>(Vector3(0.3, -1.2, 0.4), Vector3(1, 2, -1)));
  const typename D::Tangent x = tangent<D>(1.9 * random_axis(rng), Vector3(0.5, -0.2, 0.9));
  const Vector3 axis = random_axis(rng);
  // Residual angles: tiny (atan(y)/y's series), pi/2 (a trace of 1 up to
  // rounding: either branch), near pi, pi; t at 0, 1 and next to them.
  const std::vector<double> angles = {0, 1e-300, 1e-9, 1e-5, 0.3, kPi / 2, 2.0, kPi - 1e-3, kPi};
  const std::vector<double> ts = {0, 1, 0.5, 0.25, 1e-12, 1 - 1e-12};
  Data<G> data;
  for (const double angle : angles) {
    for (const double t : ts) {
      const typename D::Element f = D::compose(
          D::compose(g0, D::exp(t * x)), D::exp(tangent<D>(angle * axis, Vector3(0.1, 0.2, 0.3))));
      data.f.push_back(f.template cast<Scalar>());
      data.problem.t.push_back(Scalar(t));
      // At pi the two paths may take opposite logarithms: weight 0 keeps
      // those residuals out of the forces compared below.
      data.problem.w.push_back(angle > kPi - 1e-6 ? 0 : 1);
    }
  }
  const typename G::Element g0_s = g0.template cast<Scalar>();
  const typename G::Tangent x_s = x.template cast<Scalar>();
  const Evaluation<G> scalar = evaluate<G>(data.f, data.problem, g0_s, x_s, false);
  const Evaluation<G> batched = evaluate<G>(data.f, data.problem, g0_s, x_s, true);
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    INFO("observation " << i << " angle " << angles[i / ts.size()] << " t " << data.problem.t[i]);
    const auto& s = scalar.residuals[i];
    const auto& b = batched.residuals[i];
    if (rotation_of<G>(s).norm() > Scalar(kPi - 1e-6)) {
      // At pi both signs are logarithms: compare the elements.
      CHECK(double(G::log(G::compose(G::inverse(G::exp(s)), G::exp(b))).norm()) <=
            1e4 * eps_of<G>());
      CHECK(std::abs(double(rotation_of<G>(b).norm() - rotation_of<G>(s).norm())) <=
            std::sqrt(eps_of<G>()));
    } else {
      CHECK(double((b - s).template lpNorm<Eigen::Infinity>()) <= residual_bound<G>(s));
    }
  }
  const auto [bound0, bound1] = force_bounds(data, x_s, scalar.residuals);
  CHECK(double((batched.force.v0 - scalar.force.v0).norm()) <= bound0);
  CHECK(double((batched.force.v1 - scalar.force.v1).norm()) <= bound1);
}

// A non-finite observation inside a full block (gathered): its residual
// and the force are not finite on both paths, and the other residuals are
// as the scalar path's.
template <class G>
void check_non_finite() {
  using Scalar = typename G::Scalar;
  INFO(G::name << " in " << precision_of(eps_of<G>()));
  const typename G::Tangent x = tangent<G>(Vector3(0.9, -0.6, 0.7), Vector3(0.5, 0, 1));
  Data<G> data;
  for (int i = 0; i < 40; ++i) {
    const Scalar t = Scalar(i) / Scalar(39);
    data.f.push_back(G::exp(t * x));
    data.problem.t.push_back(t);
    data.problem.w.push_back(1);
  }
  data.f[5](1, 2) = std::numeric_limits<Scalar>::quiet_NaN();
  const typename G::Element g0 = G::identity();
  const Evaluation<G> scalar = evaluate<G>(data.f, data.problem, g0, x, false);
  const Evaluation<G> batched = evaluate<G>(data.f, data.problem, g0, x, true);
  CHECK(!scalar.residuals[5].allFinite());
  CHECK(!batched.residuals[5].allFinite());
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    if (i == 5) continue;
    INFO("observation " << i);
    const auto& s = scalar.residuals[i];
    CHECK(double((batched.residuals[i] - s).template lpNorm<Eigen::Infinity>()) <=
          residual_bound<G>(s));
  }
  CHECK(!batched.force.v0.allFinite());
  CHECK(!batched.force.v1.allFinite());
}

template <class G>
void check_fit() {
  INFO(G::name);
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0, 0.1);
  const typename G::Element g0 = G::exp(tangent<G>(Vector3(0.2, 0.1, -0.7), Vector3(1, 0, 2)));
  // 1.8 rad over the interval: the closed form.
  const typename G::Tangent x = tangent<G>(Vector3(1.2, -0.8, 1.1), Vector3(0.4, 2, -1));
  std::vector<typename G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 20000; ++i) {
    const double ti = double((i * 7919) % 20000) / 19999.0;
    const Vector3 omega(normal(rng), normal(rng), normal(rng));
    const Vector3 rho(normal(rng), normal(rng), normal(rng));
    f.push_back(G::compose(G::compose(g0, G::exp(ti * x)), G::exp(tangent<G>(omega, rho))));
    t.push_back(ti);
  }
  for (const auto solver : {bireg::Solver::gauss_newton, bireg::Solver::paper}) {
    bireg::RegressionOptions<double> options;
    options.solver = solver;
    options.batched_kernels = false;
    const auto scalar = bireg::GeodesicRegression<G>(options).fit(f, t);
    options.batched_kernels = true;
    const auto batched = bireg::GeodesicRegression<G>(options).fit(f, t);
    options.threads = 2;
    const auto batched_threads = bireg::GeodesicRegression<G>(options).fit(f, t);
    REQUIRE(scalar.ok());
    REQUIRE(batched.ok());
    CHECK(batched.iterations == scalar.iterations);
    const auto& a = *scalar.geodesic;
    const auto& b = *batched.geodesic;
    CHECK(G::log(G::compose(G::inverse(a.start()), b.start())).norm() <= 1e-13);
    CHECK(G::log(G::compose(G::inverse(a.end()), b.end())).norm() <= 1e-13);
    // Any thread count: bit for bit.
    CHECK(batched_threads.geodesic->start() == b.start());
    CHECK(batched_threads.geodesic->end() == b.end());
  }
}

// Float: the batched fit (16 lanes with AVX-512) is as accurate as the
// scalar float fit. Both stop when the step is below float's default
// tolerance, 64 eps_float = 7.6e-6, so both endpoints lie within 1e-5 of
// the double fit's.
template <class F, class D>
void check_float_fit() {
  INFO(F::name << " in float");
  std::mt19937 rng(13);
  std::normal_distribution<double> normal(0, 0.05);
  const typename D::Element g0 = D::exp(tangent<D>(Vector3(0.2, 0.1, -0.7), Vector3(1, 0, 2)));
  const typename D::Tangent x = tangent<D>(Vector3(1.2, -0.8, 1.1), Vector3(0.4, 2, -1));
  std::vector<typename D::Element> f;
  std::vector<typename F::Element> f_float;
  std::vector<double> t;
  for (int i = 0; i < 5000; ++i) {
    const double ti = i / 4999.0;
    const Vector3 omega(normal(rng), normal(rng), normal(rng));
    const Vector3 rho(normal(rng), normal(rng), normal(rng));
    f.push_back(D::compose(D::compose(g0, D::exp(ti * x)), D::exp(tangent<D>(omega, rho))));
    f_float.push_back(f.back().template cast<float>());
    t.push_back(ti);
  }
  const auto reference = bireg::GeodesicRegression<D>().fit(f, t);
  REQUIRE(reference.ok());
  const auto distance = [](const typename D::Element& a, const typename F::Element& b) {
    return D::log(D::compose(D::inverse(a), b.template cast<double>())).norm();
  };
  for (const bool batched : {false, true}) {
    INFO("batched " << batched);
    typename bireg::GeodesicRegression<F>::Options options;
    options.batched_kernels = batched;
    const auto fit = bireg::GeodesicRegression<F>(options).fit(f_float, t);
    REQUIRE(fit.ok());
    CHECK(distance(reference.geodesic->start(), fit.geodesic->start()) <= 1e-5);
    CHECK(distance(reference.geodesic->end(), fit.geodesic->end()) <= 1e-5);
  }
}

template <class G>
void check_trend_test() {
  INFO(G::name);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0, 0.5);
  const typename G::Element g0 = G::exp(tangent<G>(Vector3(0.5, 0.1, 0.2), Vector3(0, 1, 0)));
  const typename G::Tangent x = tangent<G>(Vector3(0.6, 0.3, -0.5), Vector3(1, 0, 0.5));
  std::vector<typename G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 120; ++i) {
    const double ti = i / 119.0;
    const Vector3 omega(normal(rng), normal(rng), normal(rng));
    const Vector3 rho(normal(rng), normal(rng), normal(rng));
    f.push_back(G::compose(G::compose(g0, G::exp(ti * x)), G::exp(tangent<G>(omega, rho))));
    t.push_back(ti);
  }
  // The unpermuted fit turns 0.84 rad and takes the batched kernel; a
  // permuted fit turns about as far as the noise lets it, below or above
  // the closed form's 0.25 rad.
  bireg::TrendTestOptions test_options;
  test_options.permutations = 99;
  test_options.seed = 11;
  for (const int threads : {1, 2}) {
    test_options.threads = threads;
    bireg::RegressionOptions<double> options;
    options.batched_kernels = false;
    const auto scalar =
        bireg::trend_test(bireg::GeodesicRegression<G>(options), f, t, {}, test_options);
    options.batched_kernels = true;
    const auto batched =
        bireg::trend_test(bireg::GeodesicRegression<G>(options), f, t, {}, test_options);
    REQUIRE(scalar.ok());
    REQUIRE(batched.ok());
    CHECK(std::abs(batched.statistic - scalar.statistic) <= 1e-13 * scalar.statistic);
    CHECK(batched.at_least_as_extreme == scalar.at_least_as_extreme);
    CHECK(batched.failed_permutations == scalar.failed_permutations);
    CHECK(batched.p_value == scalar.p_value);
  }
}

// A fast turn (3 rad per unit) sampled densely: each window's geodesic
// turns beyond the closed form's 0.25 rad, so the local fits take the
// batched kernel.
template <class G>
void check_local_regression() {
  INFO(G::name);
  std::mt19937 rng(9);
  std::normal_distribution<double> normal(0, 0.01);
  std::vector<typename G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 400; ++i) {
    const double ti = i / 100.0;
    const Vector3 omega(3 * ti, std::sin(2 * ti), 0.5 * ti * ti);
    const Vector3 noise(normal(rng), normal(rng), normal(rng));
    f.push_back(G::compose(G::exp(tangent<G>(omega, Vector3(ti, 0, -ti))),
                           G::exp(tangent<G>(noise, noise))));
    t.push_back(ti);
  }
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 0.15;
  options.fit.batched_kernels = false;
  const auto scalar = bireg::LocalGeodesicRegression<G>(options).smooth(f, t);
  options.fit.batched_kernels = true;
  const auto batched = bireg::LocalGeodesicRegression<G>(options).smooth(f, t);
  REQUIRE(scalar.size() == batched.size());
  for (std::size_t q = 0; q < scalar.size(); ++q) {
    INFO("query " << q);
    REQUIRE(scalar[q].ok());
    REQUIRE(batched[q].ok());
    const double speed = scalar[q].velocity.norm();
    CHECK((batched[q].velocity - scalar[q].velocity).norm() <= 1e-13 * speed);
    CHECK((batched[q].velocity_error - scalar[q].velocity_error).norm() <=
          1e-12 * scalar[q].velocity_error.norm());
  }
}

}  // namespace

TEST_CASE("The batched force agrees with the scalar loop on random data") {
  require_target();
  check_random_data<bireg::SO3d>(1e-7);
  check_random_data<bireg::SE3d>(1e-7);
  check_random_data<bireg::SO3f>(0);
  check_random_data<bireg::SE3f>(0);
}

TEST_CASE("Batched lanes at the branches' edges take the scalar path's answer") {
  require_target();
  check_edges<bireg::SO3d>();
  check_edges<bireg::SE3d>();
  check_edges<bireg::SO3f>();
  check_edges<bireg::SE3f>();
  check_non_finite<bireg::SO3d>();
  check_non_finite<bireg::SE3d>();
  check_non_finite<bireg::SO3f>();
}

TEST_CASE("A fit through the batched force equals the scalar fit to 1e-13") {
  require_target();
  check_fit<bireg::SO3d>();
  check_fit<bireg::SE3d>();
}

TEST_CASE("A float fit through the batched force is as accurate as the scalar one") {
  require_target();
  check_float_fit<bireg::SO3f, bireg::SO3d>();
  check_float_fit<bireg::SE3f, bireg::SE3d>();
}

TEST_CASE("The trend test through the batched force equals the scalar one") {
  require_target();
  check_trend_test<bireg::SO3d>();
  check_trend_test<bireg::SE3d>();
}

TEST_CASE("Local regression through the batched force equals the scalar one") {
  require_target();
  check_local_regression<bireg::SO3d>();
  check_local_regression<bireg::SE3d>();
}
