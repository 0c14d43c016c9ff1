// libFuzzer target: local regression on hostile data sets (fuzz_data.hpp)
// and options -- LocalGeodesicRegression's smooth, smooth_at at any query
// and leave_one_out, bandwidth_grid and auto_bandwidth_grid, and
// select_bandwidth on a grid of the data's or of any values; any kernel,
// bandwidth, velocity degree, turn limit, robust loss and thread count
// (values outside their domains and enumerations included).
//
// The group is SO(3) (bit 0 of the first byte clear) or SE(3): the two the
// tools smooth in 3-D. Properties checked (abort = finding), whatever the
// input (docs/hostile_input.md):
//   * one estimate per query, in the queries' order, each carrying its
//     query; a failed or refused estimate carries a message; an ok one has
//     a finite pose, velocity and (when defined) velocity standard errors;
//   * leave_one_out gives one finite error per observation or a reason;
//   * every bandwidth a grid function returns is positive and finite;
//   * a bandwidth selection that is ok chose positive, finite bandwidths
//     from its grid and its criteria hold no NaN; one that is not says why.
//
// Build and run (clang): see fuzz_fit.cpp, target fuzz_local_regression,
// corpus tests/fuzz/corpus_fuzz_local_regression.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/smoothing/bandwidth.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "fuzz_data.hpp"

namespace {

using bireg_fuzz::number;
using bireg_fuzz::require;
using bireg_fuzz::require_message;

template <class G>
void check_estimates(const std::vector<bireg::LocalEstimate<G>>& estimates,
                     const std::vector<double>& queries) {
  require(estimates.size() == queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const auto& e = estimates[q];
    require(e.covariate == queries[q] || (std::isnan(e.covariate) && std::isnan(queries[q])));
    if (!e.ok()) {
      require_message(e.message);
      continue;
    }
    require(e.pose.allFinite() && e.velocity.allFinite());
    if (e.velocity_error_defined) require(e.velocity_error.allFinite());
  }
}

void check_grid(const std::vector<double>& grid) {
  for (const double h : grid)
    require(std::isfinite(h) && h > 0);
}

template <class G>
void exercise(FuzzedDataProvider& in) {
  const auto data = bireg_fuzz::data_set<G>(in, 32);
  const auto& f = data.observations;
  const auto& t = data.covariates;

  bireg::LocalRegressionOptions<double> options;
  options.kernel = static_cast<bireg::Kernel>(in.ConsumeIntegralInRange(0, 3));
  options.bandwidth = in.ConsumeBool() ? 0.5 : number(in, 5.0);
  options.velocity_degree = in.ConsumeIntegralInRange(0, 4);
  if (in.ConsumeBool()) options.max_turn = number(in, 3.0);
  options.wide_windows = in.ConsumeBool();
  options.standard_errors = in.ConsumeBool();
  options.threads = in.ConsumeIntegralInRange(0, 2);
  options.fit.max_iterations = 20;
  if (in.ConsumeIntegralInRange(0, 3) == 0) {
    bireg::RobustOptions<double> robust;
    robust.loss = static_cast<bireg::Loss>(in.ConsumeIntegralInRange(0, 3));
    robust.max_rounds = in.ConsumeIntegralInRange(0, 10);
    options.robust = robust;
  }
  const bireg::LocalGeodesicRegression<G> local(options);

  // At the data's covariates, and at up to four queries of any value.
  check_estimates(local.smooth(f, t), t);
  std::vector<double> queries;
  for (int q = in.ConsumeIntegralInRange(0, 4); q > 0; --q)
    queries.push_back(in.ConsumeBool() && !t.empty() ? t[t.size() / 2] : number(in, 100.0));
  check_estimates(local.smooth_at(f, t, queries), queries);

  std::string problem;
  const auto errors = local.leave_one_out(f, t, problem);
  if (problem.empty()) {
    require(errors.size() == f.size());
    for (const auto& e : errors)
      require(e.allFinite());
  } else {
    require(errors.empty());
  }

  const auto automatic = bireg::auto_bandwidth_grid(t);
  check_grid(automatic);
  std::vector<double> grid =
      bireg::bandwidth_grid(t, in.ConsumeIntegralInRange(0, 6), number(in, 4.0));
  check_grid(grid);
  if (in.ConsumeBool()) {
    grid.clear();
    for (int k = in.ConsumeIntegralInRange(0, 4); k > 0; --k)
      grid.push_back(number(in, 5.0));
  }
  grid.resize(std::min<std::size_t>(grid.size(), 4));  // the selection's cost
  const auto selection = bireg::select_bandwidth<G>(f, t, options, grid);
  if (selection.ok()) {
    require(std::isfinite(selection.bandwidth) && selection.bandwidth > 0);
    require(std::isfinite(selection.velocity_bandwidth) && selection.velocity_bandwidth > 0);
    for (const auto* criteria :
         {&selection.criterion, &selection.velocity_criterion, &selection.cubic_velocity_criterion})
      for (const double c : *criteria)
        require(!std::isnan(c));
  } else {
    require_message(selection.message);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  if (in.ConsumeIntegral<std::uint8_t>() & 1) {
    exercise<bireg::SE3<double>>(in);
  } else {
    exercise<bireg::SO3<double>>(in);
  }
  return 0;
}
