// Subjects' trends (statistics/cohorts/trends.hpp, docs/cohorts.md
// "Trends"): fit_many on a shared interval, two cohorts' trends compared
// on G x G, and the population trend's confidence region, by simulation.
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/testing/random.hpp"
#include "catch.hpp"

namespace {

using SO3 = bireg::SO3d;

// A population of rotation trends on [0, 1]: subject i's geodesic runs from
// g0 exp(a_i) to g1 exp(b_i), a_i and b_i Gaussian with `spread` rad per
// coordinate, and is observed at `samples` equally spaced times with noise
// `noise` rad per coordinate.
struct Population {
  SO3::Element g0, g1;
  double spread = 0.1, noise = 0.05;
  int samples = 8;
};

std::vector<bireg::SubjectData<SO3>> simulate(const Population& population, int subjects,
                                              std::mt19937& rng) {
  std::normal_distribution<double> deviation(0.0, population.spread);
  std::normal_distribution<double> noise(0.0, population.noise);
  std::vector<bireg::SubjectData<SO3>> out(static_cast<std::size_t>(subjects));
  for (auto& subject : out) {
    const SO3::Element start = SO3::compose(
        population.g0, SO3::exp(bireg::testing::draw_vector<SO3::Tangent>(rng, deviation)));
    const SO3::Element end = SO3::compose(
        population.g1, SO3::exp(bireg::testing::draw_vector<SO3::Tangent>(rng, deviation)));
    const bireg::Geodesic<SO3> truth(start, end);
    for (int k = 0; k < population.samples; ++k) {
      const double t = static_cast<double>(k) / (population.samples - 1);
      subject.observations.push_back(
          SO3::compose(truth(t), SO3::exp(bireg::testing::draw_vector<SO3::Tangent>(rng, noise))));
      subject.covariates.push_back(t);
    }
  }
  return out;
}

std::vector<bireg::Trend<SO3>> trends_of(const std::vector<bireg::SubjectData<SO3>>& subjects) {
  const auto fits = bireg::fit_many(bireg::GeodesicRegression<SO3>(), subjects);
  REQUIRE(fits.ok());
  return fits.trends;
}

}  // namespace

// Noise-free subjects on different ranges: each trend is its own geodesic
// evaluated at the ends of the union of the ranges, extrapolated where the
// subject was not observed; the thread count changes nothing.
TEST_CASE("fit_many evaluates every subject's geodesic on the shared interval",
          "[cohorts][trends]") {
  using G = bireg::SE3d;
  std::mt19937 rng(1);
  std::normal_distribution<double> normal(0.0, 0.5);
  const double ranges[3][2] = {{0.0, 1.0}, {0.5, 2.0}, {1.0, 3.0}};
  std::vector<bireg::SubjectData<G>> subjects(3);
  std::vector<bireg::Geodesic<G>> truths;
  for (int i = 0; i < 3; ++i) {
    const G::Element start = G::exp(bireg::testing::draw_vector<G::Tangent>(rng, normal));
    const G::Element end = G::exp(bireg::testing::draw_vector<G::Tangent>(rng, normal));
    truths.emplace_back(start, end, ranges[i][0], ranges[i][1]);
    for (int k = 0; k < 6; ++k) {
      const double t = ranges[i][0] + (ranges[i][1] - ranges[i][0]) * k / 5.0;
      subjects[static_cast<std::size_t>(i)].observations.push_back(truths.back()(t));
      subjects[static_cast<std::size_t>(i)].covariates.push_back(t);
    }
  }
  const auto serial = bireg::fit_many(bireg::GeodesicRegression<G>(), subjects);
  REQUIRE(serial.ok());
  CHECK(serial.t0 == 0.0);
  CHECK(serial.t1 == 3.0);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK((serial.trends[i].first - truths[i](0.0)).norm() < 1e-8);
    CHECK((serial.trends[i].second - truths[i](3.0)).norm() < 1e-8);
  }
  bireg::FitManyOptions<double> options;
  options.threads = 3;
  const auto parallel = bireg::fit_many(bireg::GeodesicRegression<G>(), subjects, options);
  REQUIRE(parallel.ok());
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(parallel.trends[i].first == serial.trends[i].first);
    CHECK(parallel.trends[i].second == serial.trends[i].second);
  }
}

TEST_CASE("fit_many reports each failed subject and refuses a bad interval",
          "[cohorts][trends][hostile]") {
  std::mt19937 rng(2);
  Population population{SO3::identity(), SO3::exp(SO3::Tangent(0.5, 0, 0))};
  auto subjects = simulate(population, 4, rng);
  subjects[2].observations.resize(1);
  subjects[2].covariates.resize(1);
  const auto fits = bireg::fit_many(bireg::GeodesicRegression<SO3>(), subjects);
  INFO(fits.message);
  CHECK_FALSE(fits.ok());
  CHECK(fits.failed == 1);
  CHECK(fits.message.find("subject 2") != std::string::npos);
  CHECK(fits.fits[0].ok());
  CHECK(fits.fits[3].ok());
  CHECK_FALSE(fits.fits[2].ok());
  // A block of a larger cohort names the subject by its cohort index.
  bireg::FitManyOptions<double> block;
  block.first_subject = 40;
  const auto in_block = bireg::fit_many(bireg::GeodesicRegression<SO3>(), subjects, block);
  CHECK(in_block.message.find("subject 42:") != std::string::npos);
  bireg::FitManyOptions<double> reversed;
  reversed.t0 = 1.0;
  reversed.t1 = 0.0;
  const auto refused = bireg::fit_many(bireg::GeodesicRegression<SO3>(), subjects, reversed);
  CHECK(refused.status == bireg::Status::invalid_input);
  CHECK(refused.message.find("t0 < t1") != std::string::npos);
  CHECK(bireg::fit_many(bireg::GeodesicRegression<SO3>(), {}).status ==
        bireg::Status::invalid_input);
}

namespace {

// Rejections at 0.05 of compare_trends over `sets` pairs of cohorts of 20
// subjects; cohort B's population end is moved by `shift` (the velocity
// changes, the start does not).
int trend_rejections(int sets, const SO3::Tangent& shift, int permutations, unsigned seed) {
  std::mt19937 rng(seed);
  const Population a{SO3::exp(SO3::Tangent(0.2, -0.1, 0.3)), SO3::exp(SO3::Tangent(0.6, 0.2, 0.1))};
  Population b = a;
  b.g1 = SO3::compose(a.g1, SO3::exp(shift));
  int count = 0;
  for (int s = 0; s < sets; ++s) {
    const auto trends_a = trends_of(simulate(a, 20, rng));
    const auto trends_b = trends_of(simulate(b, 20, rng));
    bireg::TwoSampleOptions<double> options;
    options.permutations = permutations;
    options.seed = seed + static_cast<unsigned>(s);
    const auto test = bireg::compare_trends<SO3>(trends_a, trends_b, options);
    REQUIRE(test.ok());
    count += test.p_value <= 0.05 ? 1 : 0;
  }
  return count;
}

}  // namespace

// Identical generating trends: rejections ~ Binomial(1000, 0.05), mean 50,
// standard deviation 6.9; 28-72 is the band 0.028-0.072. A change
// of the population's end by 0.2 rad (2 between-subject standard
// deviations of the end, 0.1 rad per coordinate) with the same start, at
// 20 + 20 subjects: found in more than 90 % of 50 data sets. (At 0.15 rad
// it was found in 42 of 50.)
TEST_CASE("Cohorts' trends: calibrated under H0, a change of velocity found",
          "[cohorts][trends][calibration]") {
  const int null = trend_rejections(1000, SO3::Tangent::Zero(), 199, 10);
  CAPTURE(null);
  CHECK(null >= 28);
  CHECK(null <= 72);
  const int shifted = trend_rejections(50, SO3::Tangent(0.2, 0, 0), 99, 20);
  CAPTURE(shifted);
  CHECK(shifted >= 46);
}

// Inverting all observations inverts every fit, hence every trend: the
// invariant statistic on G x G is unchanged (to the fits' tolerance,
// 1e-10 on the endpoints, which moves T^2 ~ 10 by ~1e-7 at most).
TEST_CASE("Comparing trends is invariant under inversion of the data", "[cohorts][trends]") {
  std::mt19937 rng(3);
  const Population a{SO3::identity(), SO3::exp(SO3::Tangent(0.6, 0, 0))};
  Population b = a;
  b.g1 = SO3::exp(SO3::Tangent(0.6, 0.2, 0));
  auto subjects_a = simulate(a, 15, rng), subjects_b = simulate(b, 15, rng);
  bireg::TwoSampleOptions<double> options;
  options.permutations = 0;
  const auto base =
      bireg::compare_trends<SO3>(trends_of(subjects_a), trends_of(subjects_b), options);
  REQUIRE(base.ok());
  for (auto* cohort : {&subjects_a, &subjects_b}) {
    for (auto& subject : *cohort) {
      for (auto& r : subject.observations)
        r = SO3::inverse(r);
    }
  }
  const auto inverted =
      bireg::compare_trends<SO3>(trends_of(subjects_a), trends_of(subjects_b), options);
  REQUIRE(inverted.ok());
  CHECK(std::abs(inverted.value - base.value) <= 1e-6 * base.value);
}

// The trends at one covariate and the velocities (docs/cohorts.md, "The
// trends at one covariate", "The velocities"). At t = t0 the test is the
// element test of the starts, bit for bit. Moving every trend by h on the
// left or the right leaves both statistics unchanged and p identical (same
// seed, same relabellings; the tie margin absorbs rounding); inverting every
// trend leaves the test at t unchanged and changes the velocities' (each
// v_k moves by its own -Ad(g0_k)).
TEST_CASE("Trends at one covariate are fully invariant and velocities under translations",
          "[cohorts][trends]") {
  using Trend = bireg::Trend<SO3>;
  std::mt19937 rng(31);
  Population a{SO3::exp(SO3::Tangent(0.3, 0.1, 0)), SO3::exp(SO3::Tangent(0.9, 0.2, -0.4))};
  a.spread = 0.3;  // starts far apart: inversion's Ad(g0_k) differ
  Population b = a;
  b.g1 = SO3::compose(a.g1, SO3::exp(SO3::Tangent(0.1, -0.1, 0.05)));
  const std::vector<Trend> trends_a = trends_of(simulate(a, 14, rng));
  const std::vector<Trend> trends_b = trends_of(simulate(b, 16, rng));
  bireg::TwoSampleOptions<double> options;
  options.permutations = 499;
  options.seed = 8;
  const double t0 = 0.0, t1 = 1.0, t = 0.4;

  std::vector<SO3::Element> starts_a, starts_b;
  for (const Trend& trend : trends_a)
    starts_a.push_back(trend.first);
  for (const Trend& trend : trends_b)
    starts_b.push_back(trend.first);
  const auto starts = bireg::two_sample_test<SO3>(starts_a, starts_b, options);
  const auto at_start = bireg::compare_trends_at<SO3>(trends_a, trends_b, t0, t1, t0, options);
  REQUIRE(at_start.ok());
  CHECK(at_start.value == starts.value);
  CHECK(at_start.p_value == starts.p_value);

  const auto at = bireg::compare_trends_at<SO3>(trends_a, trends_b, t0, t1, t, options);
  const auto velocities = bireg::compare_velocities<SO3>(trends_a, trends_b, t0, t1, options);
  REQUIRE(at.ok());
  REQUIRE(velocities.ok());
  // A p strictly inside (1/(B+1), 1), so that a change of the statistic
  // would show in p.
  CHECK(velocities.at_least_as_extreme > 0);
  CHECK(velocities.at_least_as_extreme < 499);
  const auto moved = [](const std::vector<Trend>& trends, auto move) {
    std::vector<Trend> out;
    for (const Trend& trend : trends)
      out.push_back({move(trend.first), move(trend.second)});
    return out;
  };
  const SO3::Element h = SO3::exp(SO3::Tangent(-0.7, 1.1, 0.4));
  const auto left = [&](const SO3::Element& g) { return SO3::compose(h, g); };
  const auto right = [&](const SO3::Element& g) { return SO3::compose(g, h); };
  const auto inverse = [](const SO3::Element& g) { return SO3::inverse(g); };
  for (const int which : {0, 1, 2}) {
    CAPTURE(which);
    const auto move = [&](const std::vector<Trend>& trends) {
      return which == 0   ? moved(trends, left)
             : which == 1 ? moved(trends, right)
                          : moved(trends, inverse);
    };
    const auto at_moved =
        bireg::compare_trends_at<SO3>(move(trends_a), move(trends_b), t0, t1, t, options);
    const auto velocities_moved =
        bireg::compare_velocities<SO3>(move(trends_a), move(trends_b), t0, t1, options);
    CHECK(std::abs(at_moved.value - at.value) <= 1e-9 * at.value);
    CHECK(at_moved.p_value == at.p_value);
    if (which < 2) {
      CHECK(std::abs(velocities_moved.value - velocities.value) <= 1e-9 * velocities.value);
      CHECK(velocities_moved.p_value == velocities.p_value);
    } else {
      CHECK(std::abs(velocities_moved.value - velocities.value) > 1e-3 * velocities.value);
    }
  }
  // Refusals: a bad interval, a covariate that is not finite.
  CHECK(bireg::compare_velocities<SO3>(trends_a, trends_b, 1.0, 1.0, options)
            .message.find("t0 < t1") != std::string::npos);
  CHECK_FALSE(
      bireg::compare_trends_at<SO3>(trends_a, trends_b, t0, t1, std::nan(""), options).ok());
}

// The confidence region of the population trend at level 0.95 holds the
// generating (g0, g1) in 93-97 % of 1,000 simulated studies of 20 subjects
// (Binomial(1000, 0.95): standard deviation 0.7 %, the band is +- 2.9 of
// them), and the velocity's 95 % ellipsoid (Hotelling's T^2, dimension 3,
// 19 degrees of freedom) holds the generating velocity as often.
TEST_CASE("The population trend's confidence region has its coverage",
          "[cohorts][trends][calibration]") {
  std::mt19937 rng(4);
  const Population population{SO3::exp(SO3::Tangent(0.1, 0.4, -0.2)),
                              SO3::exp(SO3::Tangent(0.7, 0.1, 0.3))};
  const bireg::Trend<SO3> truth{population.g0, population.g1};
  const SO3::Tangent true_velocity =
      SO3::log(SO3::compose(SO3::inverse(population.g0), population.g1));
  const double velocity_radius = *bireg::hotelling_quantile(0.95, 3, 19);
  int covered = 0, velocity_covered = 0, flagged = 0;
  for (int s = 0; s < 1000; ++s) {
    const auto trends = trends_of(simulate(population, 20, rng));
    const auto estimate = bireg::population_trend<SO3>(trends, 0.0, 1.0);
    REQUIRE(estimate.ok());
    covered += estimate.contains(truth) ? 1 : 0;
    const SO3::Tangent error = estimate.velocity - true_velocity;
    velocity_covered +=
        error.dot(estimate.velocity_covariance.ldlt().solve(error)) <= velocity_radius ? 1 : 0;
    for (const bool outlying : estimate.outlying)
      flagged += outlying ? 1 : 0;
  }
  CAPTURE(covered, velocity_covered, flagged);
  CHECK(covered >= 930);
  CHECK(covered <= 970);
  CHECK(velocity_covered >= 930);
  CHECK(velocity_covered <= 970);
  // 20,000 typical subjects at outlier_level 0.999: about 20 flags
  // (Poisson, standard deviation 4.5); at most 40.
  CHECK(flagged <= 40);
}

TEST_CASE("An outlying subject is flagged and too few subjects are refused",
          "[cohorts][trends][hostile]") {
  std::mt19937 rng(5);
  const Population population{SO3::identity(), SO3::exp(SO3::Tangent(0.5, 0, 0))};
  auto subjects = simulate(population, 20, rng);
  for (auto& r : subjects[7].observations)
    r = SO3::compose(SO3::exp(SO3::Tangent(0, 0.8, 0)), r);
  const auto estimate = bireg::population_trend<SO3>(trends_of(subjects), 0.0, 1.0);
  REQUIRE(estimate.ok());
  CHECK(estimate.outlying[7]);
  const std::vector<bireg::Trend<SO3>> all = trends_of(subjects);
  const std::vector<bireg::Trend<SO3>> few(all.begin(), all.begin() + 7);
  const auto refused = bireg::population_trend<SO3>(few, 0.0, 1.0);
  CHECK(refused.status == bireg::Status::invalid_input);
  CHECK(refused.message.find("at least 8 subjects") != std::string::npos);
  bireg::PopulationOptions<double> options;
  options.level = 1.5;
  CHECK(bireg::population_trend<SO3>(all, 0.0, 1.0, options).status ==
        bireg::Status::invalid_input);
}
