// Cost of the group primitives: one exp, one log and two compositions, the
// floor every inverse-differential method pays per observation and iteration
// (SO(2), SO(3), SE(2), SE(3), Sim(3)); and SO(3) exp and SE(3) log alone
// against reference formulas (issue 16): the previous Rodrigues form (W^2 by
// a 3 x 3 product) and the route Sophus takes (a quaternion from the half
// angle, then its matrix; for the log, the quaternion of the matrix, an atan
// and V^{-1} from sin and cos of the half angle). The references are written
// here from the formulas; Sophus is not a dependency.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "bireg/groups/element_check.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"

namespace {

template <class G>
std::vector<typename G::Tangent> sample_tangents(int count) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<typename G::Tangent> xs(count);
  for (auto& x : xs) {
    for (int i = 0; i < G::dof; ++i)
      x[i] = uniform(rng);
  }
  return xs;
}

// exp + log + 2 compositions on varying inputs (no constant folding).
template <class G>
void BM_ExpLogTwoCompositions(benchmark::State& state) {
  const auto xs = sample_tangents<G>(256);
  const typename G::Element a = G::exp(xs[0]);
  std::size_t i = 0;
  for (auto _ : state) {
    const typename G::Element b = G::compose(a, G::exp(xs[i % xs.size()]));
    const typename G::Tangent y = G::log(G::compose(b, a));
    benchmark::DoNotOptimize(y);
    ++i;
  }
}

BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SO2<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SO3<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SE2<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SE3<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::Sim3<double>);

using SO3 = bireg::SO3<double>;
using SE3 = bireg::SE3<double>;

// The previous SO3::exp: the same coefficients, W^2 by a 3 x 3 product.
SO3::Element exp_full_product(const SO3::Tangent& omega) {
  const double half = omega.norm() / 2;
  const double sinc_half = half > 0 ? std::sin(half) / half : 1.0;
  const SO3::Algebra w = SO3::hat(omega);
  return SO3::Element::Identity() + (sinc_half * std::cos(half)) * w +
         (sinc_half * sinc_half / 2) * (w * w);
}

// Sophus's route: the unit quaternion (cos h, sin(h)/t omega), then its matrix.
SO3::Element exp_via_quaternion(const SO3::Tangent& omega) {
  const double theta = omega.norm();
  const double half = theta / 2;
  double real, imaginary;
  if (theta < 1e-10) {
    real = 1 - theta * theta / 8;
    imaginary = 0.5 - theta * theta / 48;
  } else {
    real = std::cos(half);
    imaginary = std::sin(half) / theta;
  }
  const Eigen::Quaterniond q(real, imaginary * omega[0], imaginary * omega[1],
                             imaginary * omega[2]);
  return q.toRotationMatrix();
}

// Sophus's route for the SE(3) log of a 4 x 4 matrix: the quaternion of the
// rotation block, omega = 2 atan(|v|/w) v/|v|, and V^{-1} t with
// V^{-1} = I - W/2 + (1 - t cos(t/2) / (2 sin(t/2)))/t^2 W^2.
SE3::Tangent log_via_quaternion(const SE3::Element& g) {
  Eigen::Quaterniond q(Eigen::Matrix3d(g.topLeftCorner<3, 3>()));
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  const double two_atan_n_by_w = n < 1e-10 ? 2 / q.w() - 2 * n * n / (3 * q.w() * q.w() * q.w())
                                           : 2 * std::atan2(n, q.w()) / n;
  const Eigen::Vector3d omega = two_atan_n_by_w * q.vec();
  const double theta = omega.norm();
  const Eigen::Matrix3d w = SO3::hat(omega);
  Eigen::Matrix3d v_inverse = Eigen::Matrix3d::Identity() - w / 2;
  if (theta < 1e-10) {
    v_inverse += (w * w) / 12;
  } else {
    const double half = theta / 2;
    v_inverse += (1 - theta * std::cos(half) / (2 * std::sin(half))) / (theta * theta) * (w * w);
  }
  SE3::Tangent xi;
  xi.head<3>() = v_inverse * g.topRightCorner<3, 1>();
  xi.tail<3>() = omega;
  return xi;
}

template <class Function>
void exp_benchmark(benchmark::State& state, Function exp) {
  const auto xs = sample_tangents<SO3>(256);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(exp(xs[i % xs.size()]));
    ++i;
  }
}
void BM_SO3Exp(benchmark::State& state) {
  exp_benchmark(state, SO3::exp);
}
void BM_SO3ExpFullProduct(benchmark::State& state) {
  exp_benchmark(state, exp_full_product);
}
void BM_SO3ExpViaQuaternion(benchmark::State& state) {
  exp_benchmark(state, exp_via_quaternion);
}
BENCHMARK(BM_SO3Exp);
BENCHMARK(BM_SO3ExpFullProduct);
BENCHMARK(BM_SO3ExpViaQuaternion);

template <class Function>
void se3_log_benchmark(benchmark::State& state, Function log) {
  const auto xs = sample_tangents<SE3>(256);
  std::vector<SE3::Element> gs;
  for (const auto& x : xs)
    gs.push_back(SE3::exp(x));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(log(gs[i % gs.size()]));
    ++i;
  }
}
void BM_SE3Log(benchmark::State& state) {
  se3_log_benchmark(state, SE3::log);
}
void BM_SE3LogViaQuaternion(benchmark::State& state) {
  se3_log_benchmark(state, log_via_quaternion);
}
BENCHMARK(BM_SE3Log);
BENCHMARK(BM_SE3LogViaQuaternion);

void BM_SE3Exp(benchmark::State& state) {
  const auto xs = sample_tangents<SE3>(256);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(SE3::exp(xs[i % xs.size()]));
    ++i;
  }
}
BENCHMARK(BM_SE3Exp);

// G's elements as numpy stores them, row-major.
template <class G>
using RowMajor = Eigen::Matrix<double, G::Element::RowsAtCompileTime, G::Element::ColsAtCompileTime,
                               Eigen::RowMajor>;

// Membership of 256 row-major matrices in cache (numpy's layout, as the
// Python module checks them before a batched log): G::is_element matrix by
// matrix, against first_non_element's block loop (groups/element_check.hpp),
// which the compiler vectorizes across matrices when the target can gather
// (build with -march=haswell or -march=skylake-avx512 to see it). Per matrix.
template <class G>
std::vector<double> row_major_elements(int count) {
  const auto xs = sample_tangents<G>(count);
  std::vector<double> data(xs.size() * RowMajor<G>::SizeAtCompileTime);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    Eigen::Map<RowMajor<G>> target(data.data() + i * RowMajor<G>::SizeAtCompileTime);
    target = G::exp(xs[i]);
  }
  return data;
}

template <class G>
void BM_IsElementEach(benchmark::State& state) {
  const std::vector<double> data = row_major_elements<G>(256);
  for (auto _ : state) {
    benchmark::DoNotOptimize(data.data());
    std::size_t members = 0;
    while (members < 256 && G::is_element(typename G::Element(Eigen::Map<const RowMajor<G>>(
                                data.data() + members * RowMajor<G>::SizeAtCompileTime))))
      ++members;
    benchmark::DoNotOptimize(members);
  }
  state.SetItemsProcessed(state.iterations() * 256);
}

template <class G>
void BM_FirstNonElement(benchmark::State& state) {
  const std::vector<double> data = row_major_elements<G>(256);
  for (auto _ : state) {
    benchmark::DoNotOptimize(data.data());
    const std::size_t members = bireg::first_non_element<G>(data.data(), 256);
    benchmark::DoNotOptimize(members);
  }
  state.SetItemsProcessed(state.iterations() * 256);
}

BENCHMARK_TEMPLATE(BM_IsElementEach, bireg::SO3<double>);
BENCHMARK_TEMPLATE(BM_FirstNonElement, bireg::SO3<double>);
BENCHMARK_TEMPLATE(BM_IsElementEach, bireg::SE3<double>);
BENCHMARK_TEMPLATE(BM_FirstNonElement, bireg::SE3<double>);

}  // namespace

BENCHMARK_MAIN();
