// The chunked fit (regression/chunked_fit.hpp): observations split into 7
// chunks of unequal size (one of a single observation), each chunk's sums
// sent through to_numbers/from_numbers as a transport would, give fit()'s
// result to 1e-12 relative (only the summation order differs) on every
// group, for each step rule, with weights and with an interval; joined in
// reverse order too. Invalid input is refused with fit()'s message and
// the observation's global index, whichever chunk holds it and in
// whichever order the chunks are joined.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/chunked_fit.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

// Chunk sizes of a 3,000-observation set: unequal, one of a single
// observation, none a multiple of the thread pool's chunk.
const std::vector<std::size_t> kChunkSizes = {1, 700, 13, 999, 2, 1000, 285};

template <class G>
struct Data {
  std::vector<typename G::Element> f;
  std::vector<double> t, w;
};

// f_i = A exp(t_i x + noise_i) B, t_i shuffled over [0, 5].
template <class G>
Data<G> make_data(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> uniform(0.5, 2);
  const auto tangent = [&](double sd) {
    typename G::Tangent x;
    for (int k = 0; k < G::dof; ++k)
      x[k] = sd * normal(rng);
    return x;
  };
  const typename G::Element a = G::exp(tangent(0.5)), b = G::exp(tangent(0.5));
  const typename G::Tangent x = tangent(0.1);
  Data<G> data;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 5.0 * double((i * 7919) % n) / double(n - 1);
    data.f.push_back(G::compose(a, G::compose(G::exp(t * x + tangent(0.05)), b)));
    data.t.push_back(t);
    data.w.push_back(uniform(rng));
  }
  return data;
}

// The chunks of a data set, and `reduce` over them: each chunk's sums
// computed from a request that went through the numbers, and sent back
// through them, joined in chunk order (or reversed).
template <class G>
struct Chunks {
  std::vector<std::vector<typename G::Element>> f;
  std::vector<std::vector<double>> t, w;
  std::vector<std::size_t> offsets;
  bool reversed = false;

  Chunks(const Data<G>& data, bool weighted, const std::vector<std::size_t>& sizes = kChunkSizes) {
    std::size_t offset = 0;
    for (const std::size_t size : sizes) {
      const auto from = [&](const auto& v) {
        return std::vector<typename std::decay_t<decltype(v)>::value_type>(
            v.begin() + std::ptrdiff_t(offset), v.begin() + std::ptrdiff_t(offset + size));
      };
      f.push_back(from(data.f));
      t.push_back(from(data.t));
      w.push_back(weighted ? from(data.w) : std::vector<double>());
      offsets.push_back(offset);
      offset += size;
    }
    REQUIRE(offset == data.f.size());
  }

  bireg::ChunkSums<G> operator()(const bireg::ChunkRequest<G>& request) {
    const std::vector<double> sent = bireg::to_numbers(request);
    const auto received = bireg::from_numbers<bireg::ChunkRequest<G>>(sent.data(), sent.size());
    REQUIRE(received);
    bireg::ChunkSums<G> total;
    for (std::size_t j = 0; j < f.size(); ++j) {
      const std::size_t k = reversed ? f.size() - 1 - j : j;
      const std::vector<double> part =
          bireg::to_numbers(bireg::chunk_sums<G>(*received, f[k], t[k], w[k], offsets[k]));
      const auto back = bireg::from_numbers<bireg::ChunkSums<G>>(part.data(), part.size());
      REQUIRE(back);
      total.add(*back);
    }
    return total;
  }
};

template <class Matrix>
double relative_difference(const Matrix& a, const Matrix& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

// The chunked fit against fit() on the same data and options.
template <class G>
void check_equal_fits(const bireg::RegressionOptions<double>& options, bool weighted,
                      bool reversed) {
  const Data<G> data = make_data<G>(3000, 11);
  Chunks<G> chunks(data, weighted);
  chunks.reversed = reversed;
  const auto local = bireg::GeodesicRegression<G>(options).fit(
      data.f, data.t, weighted ? data.w : std::vector<double>());
  const auto chunked = bireg::fit_by_chunks<G>(options, chunks);
  INFO(G::name << " solver " << bireg::to_string(options.solver) << " weighted " << weighted
               << " reversed " << reversed << ": " << chunked.message);
  REQUIRE(local.status == bireg::Status::converged);
  REQUIRE(chunked.status == local.status);
  CHECK(chunked.iterations == local.iterations);
  CHECK(chunked.residuals.empty());
  const double tolerance = 1e-12;
  CHECK(relative_difference(chunked.geodesic->start(), local.geodesic->start()) < tolerance);
  CHECK(relative_difference(chunked.geodesic->end(), local.geodesic->end()) < tolerance);
  CHECK(chunked.geodesic->t_min() == local.geodesic->t_min());
  CHECK(chunked.geodesic->t_max() == local.geodesic->t_max());
  CHECK(relative_difference(chunked.jacobian, local.jacobian) < tolerance);
  const auto& a = chunked.diagnostics;
  const auto& b = local.diagnostics;
  CHECK(std::abs(a.residual_rms - b.residual_rms) < tolerance * b.residual_rms);
  CHECK(std::abs(a.residual_rms_about_mean - b.residual_rms_about_mean) <
        tolerance * b.residual_rms_about_mean);
  CHECK(std::abs(a.explained_variance - b.explained_variance) < tolerance);
  CHECK(std::abs(a.mu_min - b.mu_min) < tolerance * b.mu_min);
  CHECK(a.largest_residual_observation == b.largest_residual_observation);
  CHECK(a.series_order == b.series_order);
}

template <class G>
void check_group() {
  bireg::RegressionOptions<double> options;
  for (const bool weighted : {false, true}) {
    for (const bool reversed : {false, true})
      check_equal_fits<G>(options, weighted, reversed);
  }
}

}  // namespace

TEST_CASE("A fit over 7 unequal chunks equals fit() to 1e-12 on every group") {
  check_group<bireg::SO3d>();
  check_group<bireg::SE3d>();
  check_group<bireg::SE2d>();
  check_group<bireg::Sim3d>();
  check_group<bireg::SL3<double>>();
  check_group<bireg::GLp<3, double>>();
}

TEST_CASE("A chunked fit equals fit() with every step rule and with an interval") {
  using G = bireg::SE3d;
  bireg::RegressionOptions<double> options;
  for (const bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::optimal_linear,
                                     bireg::Solver::preconditioned, bireg::Solver::gauss_newton}) {
    options.solver = solver;
    check_equal_fits<G>(options, false, false);
  }
  options.solver = bireg::Solver::gauss_newton;
  options.interval = std::make_pair(-1.0, 7.0);
  check_equal_fits<G>(options, true, false);
  options.interval.reset();
  options.method = bireg::Method::series_adaptive;
  check_equal_fits<G>(options, false, true);
}

namespace {

// fit()'s refusal and the chunked fit's, in both joining orders.
template <class G>
void check_same_refusal(const Data<G>& data, bool weighted,
                        const bireg::RegressionOptions<double>& options = {},
                        const std::vector<std::size_t>& sizes = kChunkSizes) {
  const auto local = bireg::GeodesicRegression<G>(options).fit(
      data.f, data.t, weighted ? data.w : std::vector<double>());
  REQUIRE(local.status == bireg::Status::invalid_input);
  for (const bool reversed : {false, true}) {
    Chunks<G> chunks(data, weighted, sizes);
    chunks.reversed = reversed;
    const auto chunked = bireg::fit_by_chunks<G>(options, chunks);
    CHECK(chunked.status == bireg::Status::invalid_input);
    CHECK(chunked.message == local.message);
    CHECK(chunked.bad_index == local.bad_index);
  }
}

}  // namespace

TEST_CASE("A chunked fit refuses what fit() refuses, naming the global index") {
  using G = bireg::SE3d;
  const Data<G> clean = make_data<G>(3000, 12);
  // Two bad observations in different chunks: the first is named, whichever
  // chunk is joined first.
  Data<G> nan_pose = clean;
  nan_pose.f[2500](1, 3) = std::numeric_limits<double>::quiet_NaN();
  nan_pose.f[1800](0, 0) = std::numeric_limits<double>::infinity();
  check_same_refusal(nan_pose, false);
  Data<G> not_element = clean;
  not_element.f[900](3, 0) = 1;
  not_element.f[2000](0, 0) = 2;
  check_same_refusal(not_element, false);
  Data<G> bad_covariate = clean;
  bad_covariate.t[1500] = std::numeric_limits<double>::quiet_NaN();
  bad_covariate.f[10](0, 0) = std::numeric_limits<double>::quiet_NaN();
  check_same_refusal(bad_covariate, false);
  Data<G> bad_weight = clean;
  bad_weight.w[2999] = -1;
  check_same_refusal(bad_weight, true);
  Data<G> zero_weights = clean;
  std::fill(zero_weights.w.begin(), zero_weights.w.end(), 0.0);
  check_same_refusal(zero_weights, true);
  Data<G> one_covariate = clean;
  std::fill(one_covariate.t.begin(), one_covariate.t.end(), 2.0);
  check_same_refusal(one_covariate, false);
  bireg::RegressionOptions<double> narrow;
  narrow.interval = std::make_pair(0.0, 4.0);
  check_same_refusal(clean, false, narrow);
  bireg::RegressionOptions<double> no_iterations;
  no_iterations.max_iterations = 0;
  check_same_refusal(clean, false, no_iterations);
}

TEST_CASE(
    "Chunks larger than a slice give fit()'s result and name an observation in a later slice") {
  using G = bireg::SE3d;
  // 9,000 observations in one chunk: chunk_sums works through it in
  // slices of kChunkSize (4,096), each named from the chunk's offset.
  const std::vector<std::size_t> sizes = {1, 9000, 999};
  Data<G> data = make_data<G>(10000, 13);
  const auto local = bireg::GeodesicRegression<G>().fit(data.f, data.t, data.w);
  Chunks<G> chunks(data, true, sizes);
  const auto chunked = bireg::fit_by_chunks<G>(bireg::RegressionOptions<double>{}, chunks);
  REQUIRE(chunked.status == local.status);
  CHECK(relative_difference(chunked.geodesic->end(), local.geodesic->end()) < 1e-12);
  CHECK(chunked.diagnostics.largest_residual_observation ==
        local.diagnostics.largest_residual_observation);
  data.f[8500](2, 1) = std::numeric_limits<double>::quiet_NaN();
  data.w[9500] = std::numeric_limits<double>::infinity();
  check_same_refusal(data, true, {}, sizes);
  data.w[9500] = 1;
  check_same_refusal(data, true, {}, sizes);
}

TEST_CASE("A chunked fit of one observation is refused as fit() refuses it") {
  using G = bireg::SO3d;
  struct One {
    bireg::ChunkSums<G> operator()(const bireg::ChunkRequest<G>& request) const {
      const std::vector<G::Element> f = {G::identity()};
      const std::vector<double> t = {0.0};
      return bireg::chunk_sums<G>(request, f, t, {}, 0);
    }
  } one;
  const auto result = bireg::fit_by_chunks<G>(bireg::RegressionOptions<double>{}, one);
  CHECK(result.status == bireg::Status::invalid_input);
  CHECK(result.message == "need at least 2 observations, got 1");
}

TEST_CASE("Numbers of another layout are refused, not misread") {
  using G = bireg::SO3d;
  bireg::ChunkRequest<G> request;
  request.pass = bireg::ChunkPass::chart;
  request.g0 = G::exp(G::Tangent(0.1, 0.2, 0.3));
  std::vector<double> numbers = bireg::to_numbers(request);
  const auto back = bireg::from_numbers<bireg::ChunkRequest<G>>(numbers.data(), numbers.size());
  REQUIRE(back);
  CHECK(back->pass == bireg::ChunkPass::chart);
  CHECK(back->g0 == request.g0);
  numbers.push_back(0);
  CHECK_FALSE(bireg::from_numbers<bireg::ChunkRequest<G>>(numbers.data(), numbers.size()));
  CHECK_FALSE(bireg::from_numbers<bireg::ChunkRequest<G>>(numbers.data(), numbers.size() - 2));
}

TEST_CASE("Numbers that do not fit their fields are refused, not cast") {
  using G = bireg::SO3d;
  const std::vector<double> good = bireg::to_numbers(bireg::ChunkRequest<G>{});
  // Fields 0 (the pass), 2 (has_interval), 9 (series order), 5 (t_min).
  const auto refused = [&](std::size_t field, double value) {
    std::vector<double> numbers = good;
    numbers[field] = value;
    return !bireg::from_numbers<bireg::ChunkRequest<G>>(numbers.data(), numbers.size());
  };
  CHECK(refused(0, std::numeric_limits<double>::quiet_NaN()));
  CHECK(refused(0, 2.5));
  CHECK(refused(0, 5));  // one past the last pass
  CHECK(refused(0, -1));
  CHECK(refused(2, 0.5));  // a bool
  CHECK(refused(9, 2e9));  // a series of 2e9 terms
  CHECK(refused(9, 1e300));
  CHECK(refused(5, std::numeric_limits<double>::infinity()));
  CHECK_FALSE(refused(0, 4));  // the residuals pass
  // A sums record with an index that is not an integer.
  std::vector<double> sums = bireg::to_numbers(bireg::ChunkSums<G>{});
  sums[5] = 0.5;  // covariates.bad_covariate
  CHECK_FALSE(bireg::from_numbers<bireg::ChunkSums<G>>(sums.data(), sums.size()));
  sums[5] = 3;
  const auto read = bireg::from_numbers<bireg::ChunkSums<G>>(sums.data(), sums.size());
  REQUIRE(read);
  CHECK(read->covariates.bad_covariate == 3);
}
