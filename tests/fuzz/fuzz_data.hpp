// Structured input for the fuzz targets of the layers above fit()
// (fuzz_statistics, fuzz_local_regression, fuzz_model_selection): the
// fuzzer's bytes, read with LLVM's FuzzedDataProvider, become a data set --
// observations, covariates, weights -- in which any number may be an
// ordinary one or one of docs/hostile_input.md's input classes (NaN,
// infinities, 1e308, denormals, covariates 1e-300 apart, EuRoC
// nanoseconds as doubles, ...).
//
// The data set is a noisy geodesic, so that most inputs reach the
// statistics instead of the first refusal, with a few hostile edits on top:
//   * n observations (0..max_n) exp(x0) exp(s_i x) exp(e_i), s_i = i/(n-1),
//     e_i Gaussian with a standard deviation from the input (the noise is
//     drawn from a generator seeded by the input, so that an input is a few
//     dozen bytes whatever n; the standard library's distributions make
//     an input's data set that library's: libstdc++ here, as in CI);
//   * covariates: evenly spaced from t0 by dt (both from number(): either
//     may be hostile), shuffled, or drawn; then up to three covariates
//     replaced by number(), and possibly one too few or one too many;
//   * weights: none, all 1, all one number(), or drawn in [0.1, 10]; then
//     up to three replaced by number();
//   * up to three matrix entries of the observations replaced by number().
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>
#include <Eigen/Core>

#include "require.hpp"

namespace bireg_fuzz {

// An ordinary number, uniform in [-scale, scale], or -- for 24 of the 256
// values of the selector byte -- one of the hostile ones.
inline double number(FuzzedDataProvider& in, double scale) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr double kHostile[] = {std::numeric_limits<double>::quiet_NaN(),
                                        kInf,
                                        -kInf,
                                        0.0,
                                        -0.0,
                                        std::numeric_limits<double>::denorm_min(),
                                        std::numeric_limits<double>::min(),
                                        1e-300,
                                        1e-8,
                                        1e8,
                                        1.4e18,  // EuRoC's nanoseconds
                                        5e6,     // and its 200 Hz spacing in them
                                        1e154,
                                        1e200,
                                        1e300,
                                        std::numeric_limits<double>::max(),
                                        -std::numeric_limits<double>::max(),
                                        3.141592653589793,
                                        1.0,
                                        -1.0,
                                        0.5,
                                        2.0,
                                        1e-3,
                                        -1e-3};
  const auto kind = in.ConsumeIntegral<std::uint8_t>();
  if (kind < std::size(kHostile)) return kHostile[kind];
  return in.ConsumeFloatingPointInRange(-scale, scale);
}

template <class G>
struct DataSet {
  std::vector<typename G::Element> observations;
  std::vector<double> covariates;
  std::vector<double> weights;  // empty: unweighted
};

template <class G>
DataSet<G> data_set(FuzzedDataProvider& in, std::size_t max_n) {
  using Tangent = typename G::Tangent;
  DataSet<G> data;
  const auto n = in.ConsumeIntegralInRange<std::size_t>(0, max_n);
  std::mt19937_64 rng(in.ConsumeIntegral<std::uint64_t>());
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.1, 10.0);

  Tangent x0;
  Tangent x;
  for (int k = 0; k < G::dof; ++k) {
    x0[k] = number(in, 3.0);
    x[k] = number(in, 3.0);
  }
  const double noise = number(in, 0.3);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = n > 1 ? double(i) / double(n - 1) : 0.0;
    Tangent e;
    for (int k = 0; k < G::dof; ++k)
      e[k] = noise * normal(rng);
    data.observations.push_back(
        G::compose(G::compose(G::exp(x0), G::exp(Tangent(s * x))), G::exp(e)));
  }

  const double t0 = number(in, 100.0);
  const double dt = number(in, 1.0);
  for (std::size_t i = 0; i < n; ++i)
    data.covariates.push_back(t0 + dt * double(i));
  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 1:
      std::shuffle(data.covariates.begin(), data.covariates.end(), rng);
      break;
    case 2:
      for (double& t : data.covariates)
        t = t0 + dt * uniform(rng);
      break;
    default:
      break;
  }

  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 1:
      data.weights.assign(n, 1.0);
      break;
    case 2:
      data.weights.assign(n, number(in, 10.0));
      break;
    case 3:
      for (std::size_t i = 0; i < n; ++i)
        data.weights.push_back(uniform(rng));
      break;
    default:
      break;
  }

  // The hostile edits.
  for (int edit = in.ConsumeIntegralInRange(0, 3); edit > 0 && n > 0; --edit) {
    auto& g = data.observations[in.ConsumeIntegralInRange<std::size_t>(0, n - 1)];
    g(in.ConsumeIntegralInRange<Eigen::Index>(0, g.rows() - 1),
      in.ConsumeIntegralInRange<Eigen::Index>(0, g.cols() - 1)) = number(in, 2.0);
  }
  for (int edit = in.ConsumeIntegralInRange(0, 3); edit > 0 && n > 0; --edit)
    data.covariates[in.ConsumeIntegralInRange<std::size_t>(0, n - 1)] = number(in, 100.0);
  for (int edit = in.ConsumeIntegralInRange(0, 3); edit > 0 && !data.weights.empty(); --edit)
    data.weights[in.ConsumeIntegralInRange<std::size_t>(0, n - 1)] = number(in, 10.0);
  switch (in.ConsumeIntegralInRange(0, 7)) {
    case 0:
      if (n > 0) data.covariates.pop_back();
      break;
    case 1:
      data.covariates.push_back(0.0);
      break;
    default:
      break;
  }
  return data;
}

}  // namespace bireg_fuzz
