// The roughness penalty's choice by cross-validation
// (statistics/smoothing/spline_roughness.hpp): the choice is the smallest
// criterion among the values not refused, the same choice and criteria for
// data translated on either side, a curve close to the best the grid offers
// against the truth (which the criterion cannot see), a larger penalty for
// noisier data, and every refusal stated.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/so3.hpp"
#include "bireg/spline.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/smoothing/spline_roughness.hpp"
#include "catch.hpp"
#include "spline_samples.hpp"

namespace {

using SO3 = bireg::SO3d;

using bireg_test::distance;
using bireg_test::random_points;
using bireg_test::sample;
using bireg_test::Samples;

// RMS distance between a fit with this lambda and the truth over the
// data's range, on 201 points; infinite where the fit fails.
double error_against_truth(const bireg::Spline<SO3>& truth, const Samples<SO3>& data,
                           bireg::SplineOptions<double> options, double lambda) {
  options.roughness_penalty = lambda;
  const auto fit = bireg::SplineRegression<SO3>(options).fit(data.f, data.t);
  if (!fit.ok()) return std::numeric_limits<double>::infinity();
  double sum = 0;
  for (int q = 0; q <= 200; ++q) {
    const double t = data.t.front() + (data.t.back() - data.t.front()) * q / 200;
    sum += std::pow(distance<SO3>((*fit.spline)(t), truth(t)), 2);
  }
  return std::sqrt(sum / 201);
}

}  // namespace

TEST_CASE(
    "Roughness penalty by cross-validation: invariant, near the best, larger for noisier data",
    "[spline]") {
  std::mt19937 rng(41);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 8, 0.5));
  constexpr std::size_t n = 200;
  bireg::SplineOptions<double> options;
  // Fine knots, 2.5 observations per span: 80 spans, 83 control points.
  options.knot_spacing = 2.5 * (truth.t_max() - truth.t_min()) / double(n);
  double lambda_quiet = 0;
  for (const double noise : {0.02, 0.2}) {
    const Samples<SO3> data = sample(truth, n, noise, rng);
    const std::vector<double> grid =
        bireg::auto_roughness_penalty_grid(data.t, options.knot_spacing);
    // In units of the observations per knot span, from 1e-4 to the
    // fourth power of the number of spans (a window of the whole range),
    // four a decade.
    const double range = data.t.back() - data.t.front();
    const double spans = std::ceil(range / options.knot_spacing);
    const double per_span = double(n) / spans;
    REQUIRE(spans <= 100);
    CHECK(std::abs(grid.front() / (1e-4 * per_span) - 1) < 1e-12);
    CHECK(std::abs(grid.back() / (std::pow(spans, 4) * per_span) - 1) < 1e-12);
    CHECK(grid.size() == std::size_t(1 + std::ceil(4 * (4 * std::log10(spans) + 4))));
    const auto selection = bireg::select_roughness_penalty<SO3>(data.f, data.t, options, grid);
    INFO("noise " << noise << ": " << selection.message);
    REQUIRE(selection.ok());
    // Refused values only where the fine knots, barely penalised, follow
    // the noise until the fit cannot descend, below the choice, and beyond
    // two decades above it, not tried.
    std::size_t best = grid.size();
    for (std::size_t v = 0; v < grid.size(); ++v) {
      INFO("lambda " << grid[v] << ": " << selection.refusals[v]);
      CHECK(std::isfinite(selection.criterion[v]) == selection.refusals[v].empty());
      if (grid[v] > 100 * selection.roughness_penalty) {
        CHECK(selection.refusals[v].find("not tried: the criterion stayed above") == 0);
        continue;
      }
      if (!selection.refusals[v].empty()) {
        CHECK(grid[v] < selection.roughness_penalty);
        CHECK(selection.refusals[v].find("no step along the Gauss-Newton direction") !=
              std::string::npos);
        continue;
      }
      if (best == grid.size() || selection.criterion[v] < selection.criterion[best]) best = v;
    }
    REQUIRE(best < grid.size());
    CHECK(selection.roughness_penalty == grid[best]);
    CHECK_FALSE(selection.at_edge);

    const SO3::Element g = SO3::exp(SO3::Tangent(0.3, -1.1, 0.7));
    const auto [left, right] = bireg_test::translated<SO3>(data.f, g);
    for (const auto& moved : {left, right}) {
      const auto other = bireg::select_roughness_penalty<SO3>(moved, data.t, options, grid);
      REQUIRE(other.ok());
      CHECK(other.roughness_penalty == selection.roughness_penalty);
      for (std::size_t v = 0; v < grid.size(); ++v) {
        if (!selection.refusals[v].empty()) continue;
        CHECK(std::abs(other.criterion[v] / selection.criterion[v] - 1) < 1e-8);
      }
    }

    // Against the truth: within 1.5x of the best grid value's error, and
    // better than the least penalty whose fit converges (fine knots barely
    // penalised follow the noise).
    std::vector<double> errors;
    for (const double lambda : grid)
      errors.push_back(error_against_truth(truth, data, options, lambda));
    const double oracle = *std::min_element(errors.begin(), errors.end());
    INFO("chosen " << selection.roughness_penalty << " error " << errors[best] << ", best "
                   << oracle << ", smallest lambda's " << errors.front());
    CHECK(errors[best] <= 1.5 * oracle);
    std::size_t least = 0;
    while (!std::isfinite(errors[least]))
      ++least;
    CHECK(errors[best] < errors[least]);
    if (noise == 0.02) {
      lambda_quiet = selection.roughness_penalty;
    } else {
      CHECK(selection.roughness_penalty > lambda_quiet);
    }
  }
}

TEST_CASE("Roughness penalty by cross-validation: refusals name the problem", "[spline]") {
  std::mt19937 rng(43);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 6, 0.5));
  const Samples<SO3> data = sample(truth, 60, 0.05, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.2;
  const std::vector<double> grid = {0.01, 0.1, 1.0};
  const auto refused_because = [&](const bireg::SplineOptions<double>& o,
                                   const std::vector<double>& g, const std::string& reason) {
    const auto selection = bireg::select_roughness_penalty<SO3>(data.f, data.t, o, g);
    INFO(selection.message);
    CHECK_FALSE(selection.ok());
    CHECK(selection.message.find(reason) != std::string::npos);
    CHECK(selection.refusals.size() == g.size());
    CHECK(selection.criterion.size() == g.size());
    for (const std::string& refusal : selection.refusals)
      CHECK(refusal.find(reason) != std::string::npos);
  };
  auto linear = options;
  linear.degree = 1;
  refused_because(linear, grid, "degree 2 or 3");
  auto unbounded = options;
  unbounded.knot_spacing = std::numeric_limits<double>::infinity();
  refused_because(unbounded, grid, "finite positive knot spacing");
  refused_because(options, {0.1, 0.01}, "ascending (value 1)");
  refused_because(options, {0.0, 0.1}, "positive");
  refused_because(options, {}, "needs a grid");
  // Knots too dense for a fold's data: every value refused with the fold's
  // reason, the failures counted. 800 spans, 803 control points: at most
  // 16 per observation for 60 observations (960), not for a fold's 48
  // (768).
  auto dense = options;
  dense.knot_spacing = (data.t.back() - data.t.front()) / 800;
  const auto selection = bireg::select_roughness_penalty<SO3>(data.f, data.t, dense, grid);
  CHECK_FALSE(selection.ok());
  for (std::size_t v = 0; v < grid.size(); ++v) {
    INFO(selection.refusals[v]);
    CHECK(selection.refusals[v].find("fold ") == 0);
    CHECK(selection.refusals[v].find("16 per observation") != std::string::npos);
    CHECK(selection.failures[v] > 0);
  }
  CHECK(selection.message.find("every roughness penalty was refused") == 0);
}

// Real recordings drop samples: with a penalty the fine knots need not
// have data in every span (splines.md §12, "Knots finer than the data"),
// so a gap of 16 samples (about 11 spans of 1.5 sample spacings) in 200
// leaves every lambda that converges scored, and the choice's curve
// crosses the gap within 1.5x of the best grid value's error against the
// truth there.
TEST_CASE("Roughness penalty by cross-validation: fine knots across a gap in the data",
          "[spline]") {
  std::mt19937 rng(53);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 8, 0.5));
  const Samples<SO3> all = sample(truth, 200, 0.05, rng);
  Samples<SO3> data;
  for (std::size_t i = 0; i < all.t.size(); ++i) {
    if (i >= 80 && i < 96) continue;
    data.f.push_back(all.f[i]);
    data.t.push_back(all.t[i]);
  }
  bireg::SplineOptions<double> options;
  options.knot_spacing = bireg::fine_knot_spacing(data.t);
  const std::vector<double> grid = bireg::auto_roughness_penalty_grid(data.t, options.knot_spacing);
  const auto selection = bireg::select_roughness_penalty<SO3>(data.f, data.t, options, grid);
  INFO(selection.message);
  REQUIRE(selection.ok());
  for (std::size_t v = 0; v < grid.size(); ++v) {
    INFO("lambda " << grid[v] << ": " << selection.refusals[v]);
    CHECK(selection.refusals[v].find("Schoenberg-Whitney") == std::string::npos);
    CHECK(selection.refusals[v].find("control points for") == std::string::npos);
  }
  // Against the truth inside the gap.
  const double from = all.t[80], to = all.t[95];
  const auto gap_error = [&](double lambda) {
    bireg::SplineOptions<double> o = options;
    o.roughness_penalty = lambda;
    const auto fit = bireg::SplineRegression<SO3>(o).fit(data.f, data.t);
    if (!fit.ok()) return std::numeric_limits<double>::infinity();
    double sum = 0;
    for (int q = 0; q <= 50; ++q) {
      const double t = from + (to - from) * q / 50;
      sum += std::pow(distance<SO3>((*fit.spline)(t), truth(t)), 2);
    }
    return std::sqrt(sum / 51);
  };
  double oracle = std::numeric_limits<double>::infinity();
  for (const double lambda : grid)
    oracle = std::min(oracle, gap_error(lambda));
  CHECK(gap_error(selection.roughness_penalty) <= 1.5 * oracle);
}

// Progress counts fits: 1 + folds per grid value, values not tried counted
// done, never backwards, ending at the whole.
TEST_CASE("Roughness penalty by cross-validation: progress in fits, to the end", "[spline]") {
  std::mt19937 rng(47);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 6, 0.5));
  const Samples<SO3> data = sample(truth, 60, 0.05, rng);
  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.2;
  const std::vector<double> grid = {1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3, 1e4};
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  const auto selection = bireg::select_roughness_penalty<SO3>(
      data.f, data.t, options, grid, 4,
      [&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); });
  REQUIRE(selection.ok());
  REQUIRE_FALSE(calls.empty());
  for (std::size_t k = 0; k < calls.size(); ++k) {
    CHECK(calls[k].second == grid.size() * 5);
    CHECK(calls[k].first <= calls[k].second);
    if (k > 0) CHECK(calls[k].first >= calls[k - 1].first);
  }
  CHECK(calls.back().first == grid.size() * 5);
  std::size_t tried = 0;
  for (const std::string& refusal : selection.refusals)
    tried += refusal.rfind("not tried", 0) == 0 ? 0 : 1;
  // Some values past two decades above the choice were skipped (the grid
  // spans seven), and their fits counted done: one call per fit tried and
  // the last, which jumps over the skipped ones.
  REQUIRE(tried < grid.size());
  CHECK(calls.size() == tried * 5 + 1);
  CHECK(calls[calls.size() - 2].first == tried * 5);
}
