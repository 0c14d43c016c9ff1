// Element-wise two-sample maps (statistics/cohorts/elementwise.hpp,
// docs/cohorts.md "Element-wise maps"): Benjamini-Hochberg by hand, the
// exact mode against two_sample_test, the linearised mode's invariance and
// calibration, and FDR and family-wise error control by simulation.
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/statistics/cohorts/elementwise.hpp"
#include "bireg/testing/random.hpp"
#include "catch.hpp"

namespace {

using SO3 = bireg::SO3d;
using SE3 = bireg::SE3d;

// Element k's centre: spread over the group, a different one per element.
template <class G>
typename G::Tangent centre_of(int k) {
  typename G::Tangent x;
  if constexpr (G::dof == 3) {
    x << 0.01 * k, -0.3, 0.2;
  } else {
    x << 0.5, 0.1 * k, -0.2, 0.01 * k, -0.3, 0.2;
  }
  return x;
}

// `subjects` x `elements` elements of G, subject-major; element k is
// centre_k exp(e) with e of standard deviation sd per coordinate, moved by
// `shift` on the left for k < shifted.
template <class G = SO3>
std::vector<typename G::Element> cohort(std::mt19937& rng, int subjects, int elements, double sd,
                                        int shifted, const typename G::Tangent& shift) {
  std::normal_distribution<double> normal(0.0, sd);
  std::vector<typename G::Element> out;
  for (int i = 0; i < subjects; ++i) {
    for (int k = 0; k < elements; ++k) {
      const typename G::Element centre = G::exp(centre_of<G>(k));
      typename G::Element e =
          G::compose(centre, G::exp(bireg::testing::draw_vector<typename G::Tangent>(rng, normal)));
      if (k < shifted) e = G::compose(G::exp(shift), e);
      out.push_back(e);
    }
  }
  return out;
}

bireg::ElementwiseOptions<double> options_for(bireg::ElementwiseMode mode, int permutations) {
  bireg::ElementwiseOptions<double> options;
  options.mode = mode;
  options.test.permutations = permutations;
  options.test.seed = 9;
  return options;
}

}  // namespace

TEST_CASE("Benjamini-Hochberg q-values, by hand", "[cohorts][maps]") {
  // Sorted: 0.01 (1), 0.03 (2), 0.04 (3), 0.2 (4); p K / rank = 0.04, 0.06,
  // 0.0533, 0.2; the running minimum from the top: 0.04, 0.0533, 0.0533, 0.2.
  const std::vector<double> q =
      bireg::elementwise_detail::benjamini_hochberg(std::vector<double>{0.01, 0.04, 0.03, 0.2});
  CHECK(q[0] == Approx(0.04).epsilon(1e-15));
  CHECK(q[1] == Approx(0.04 * 4 / 3).epsilon(1e-15));
  CHECK(q[2] == Approx(0.04 * 4 / 3).epsilon(1e-15));
  CHECK(q[3] == Approx(0.2).epsilon(1e-15));
}

// With K = 1 the exact mode is two_sample_test: same relabellings, same
// arithmetic, so the same value and p-value bit for bit.
TEST_CASE("The exact mode of one element is the two-sample test", "[cohorts][maps]") {
  std::mt19937 rng(1);
  const auto a = cohort(rng, 12, 1, 0.3, 0, SO3::Tangent::Zero());
  const auto b = cohort(rng, 14, 1, 0.3, 1, SO3::Tangent(0.2, 0, 0));
  for (const auto statistic :
       {bireg::TwoSampleStatistic::hotelling, bireg::TwoSampleStatistic::hellinger}) {
    auto options = options_for(bireg::ElementwiseMode::exact, 199);
    options.test.statistic = statistic;
    const auto map = bireg::elementwise_two_sample_test<SO3>(a, 12, b, 14, 1, options);
    const auto single = bireg::two_sample_test<SO3>(a, b, options.test);
    REQUIRE(map.ok());
    REQUIRE(single.ok());
    CHECK(map.value[0] == single.value);
    CHECK(map.p_value[0] == single.p_value);
    CHECK(map.p_fwer[0] == single.p_value);
    CHECK(map.q_value[0] == single.p_value);
  }
}

// The linearised mode's coordinates all move by one matrix (I, Ad(h^-1),
// -Ad(p_k)): every value is unchanged to rounding and every p-value
// exactly, with the same seed.
TEST_CASE("The linearised map is invariant under translation and inversion", "[cohorts][maps]") {
  std::mt19937 rng(2);
  const int k = 5;
  const auto a = cohort(rng, 10, k, 0.3, 0, SO3::Tangent::Zero());
  const auto b = cohort(rng, 11, k, 0.3, 2, SO3::Tangent(0.8, 0, 0));
  const SO3::Element g = SO3::exp(SO3::Tangent(0.4, -1.0, 0.3));
  const SO3::Element h = SO3::exp(SO3::Tangent(-0.7, 0.2, 0.9));
  const auto map = [](std::vector<SO3::Element> x, const auto& f) {
    for (auto& e : x)
      e = f(e);
    return x;
  };
  const auto options = options_for(bireg::ElementwiseMode::linearised, 99);
  const auto base = bireg::elementwise_two_sample_test<SO3>(a, 10, b, 11, k, options);
  REQUIRE(base.ok());
  const auto left = [&](const SO3::Element& e) { return SO3::Element(SO3::compose(g, e)); };
  const auto right = [&](const SO3::Element& e) { return SO3::Element(SO3::compose(e, h)); };
  const auto invert = [](const SO3::Element& e) { return SO3::Element(SO3::inverse(e)); };
  const auto moved_left =
      bireg::elementwise_two_sample_test<SO3>(map(a, left), 10, map(b, left), 11, k, options);
  const auto moved_right =
      bireg::elementwise_two_sample_test<SO3>(map(a, right), 10, map(b, right), 11, k, options);
  const auto inverted =
      bireg::elementwise_two_sample_test<SO3>(map(a, invert), 10, map(b, invert), 11, k, options);
  for (const auto* other : {&moved_left, &moved_right, &inverted}) {
    REQUIRE(other->ok());
    for (int j = 0; j < k; ++j) {
      const auto u = static_cast<std::size_t>(j);
      CHECK(std::abs(other->value[u] - base.value[u]) <= 1e-9 * base.value[u]);
      CHECK(other->p_value[u] == base.p_value[u]);
      CHECK(other->p_fwer[u] == base.p_fwer[u]);
    }
  }
  // The shifted elements (by 2.7 noise standard deviations) stand out.
  CHECK(base.p_value[0] < 0.05);
  CHECK(base.p_value[1] < 0.05);
}

// The linearised mode is a permutation test of fixed coordinates, exact
// under exchangeability: over 1,000 null data sets (20 + 20, B = 199) the
// share of p <= 0.05 lies in 0.028-0.072 (Binomial(1000, 0.05) mean +- 3.2
// standard deviations), for each statistic on SO(3) and SE(3).
template <class G>
int linearised_rejections(bireg::TwoSampleStatistic statistic, unsigned seed) {
  std::mt19937 rng(seed);
  int rejected = 0;
  for (int s = 0; s < 1000; ++s) {
    const auto a = cohort<G>(rng, 20, 1, 0.3, 0, G::Tangent::Zero());
    const auto b = cohort<G>(rng, 20, 1, 0.3, 0, G::Tangent::Zero());
    auto options = options_for(bireg::ElementwiseMode::linearised, 199);
    options.test.statistic = statistic;
    options.test.seed = static_cast<unsigned>(s);
    const auto map = bireg::elementwise_two_sample_test<G>(a, 20, b, 20, 1, options);
    REQUIRE(map.ok());
    rejected += map.p_value[0] <= 0.05 ? 1 : 0;
  }
  return rejected;
}

TEST_CASE("The linearised mode rejects at its level under H0", "[cohorts][maps][calibration]") {
  for (const auto statistic :
       {bireg::TwoSampleStatistic::hotelling, bireg::TwoSampleStatistic::bhattacharyya}) {
    const int so3 = linearised_rejections<SO3>(statistic, 3);
    const int se3 = linearised_rejections<SE3>(statistic, 30);
    CAPTURE(static_cast<int>(statistic), so3, se3);
    CHECK(so3 >= 28);
    CHECK(so3 <= 72);
    CHECK(se3 >= 28);
    CHECK(se3 <= 72);
  }
}

// K = 1,000 elements, the first 50 (5 %) shifted by 0.45 rad (1.5 noise
// standard deviations), 20 + 20 subjects, B = 999, 100 simulated studies.
// Benjamini-Hochberg at q = 0.05 controls the false discovery rate at
// q pi0 = 0.0475: the mean false discovery proportion over the studies
// must not exceed it by more than 3 standard errors of that mean. Max-T
// controls the family-wise error: the number of studies with any false
// rejection at p_fwer <= 0.05 is Binomial(100, <= 0.05), at most 11
// (P(>= 12) < 0.005).
TEST_CASE("Benjamini-Hochberg controls the FDR and max-T the family-wise error",
          "[cohorts][maps][calibration]") {
  constexpr int kElements = 1000, kShifted = 50, kStudies = 100;
  std::mt19937 rng(4);
  std::vector<double> proportions;
  int with_false_fwer = 0, true_found = 0;
  for (int s = 0; s < kStudies; ++s) {
    const auto a = cohort(rng, 20, kElements, 0.3, 0, SO3::Tangent::Zero());
    const auto b = cohort(rng, 20, kElements, 0.3, kShifted, SO3::Tangent(0.45, 0, 0));
    auto options = options_for(bireg::ElementwiseMode::linearised, 999);
    options.test.seed = 100 + static_cast<unsigned>(s);
    options.test.threads = 2;
    const auto map = bireg::elementwise_two_sample_test<SO3>(a, 20, b, 20, kElements, options);
    REQUIRE(map.ok());
    int discoveries = 0, false_discoveries = 0;
    bool false_fwer = false;
    for (int k = 0; k < kElements; ++k) {
      const auto u = static_cast<std::size_t>(k);
      if (map.q_value[u] <= 0.05) {
        ++discoveries;
        false_discoveries += k >= kShifted ? 1 : 0;
        true_found += k < kShifted ? 1 : 0;
      }
      false_fwer = false_fwer || (k >= kShifted && map.p_fwer[u] <= 0.05);
    }
    proportions.push_back(discoveries == 0 ? 0.0 : double(false_discoveries) / discoveries);
    with_false_fwer += false_fwer ? 1 : 0;
  }
  double mean = 0, square = 0;
  for (const double p : proportions) {
    mean += p / kStudies;
    square += p * p / kStudies;
  }
  const double standard_error = std::sqrt((square - mean * mean) / (kStudies - 1));
  CAPTURE(mean, standard_error, with_false_fwer, true_found);
  CHECK(mean <= 0.0475 + 3 * standard_error);
  CHECK(with_false_fwer <= 11);
  // And it finds true differences: at 1.5 standard deviations, and BH's
  // threshold near 0.05 x 50 / 1000 = 0.0025, 59 % of them (measured); a
  // map that found under half would have lost power.
  CHECK(true_found >= 0.5 * kShifted * kStudies);
}

// A map of 37 elements computed as slices 0-9, 10-29 and 30-36 (each with
// all relabellings) and joined by combine_elementwise equals the map of all
// 37 at once: the per-element p-values are the slices' own, and the
// family-wise p-values and q-values need every element, which the slices'
// per-relabelling maxima and ranked values carry.
TEST_CASE("An element-wise map computed in slices of elements combines exactly",
          "[cohorts][maps][shares]") {
  std::mt19937 rng(21);
  const int m = 9, n = 10, elements = 37;
  const auto a = cohort(rng, m, elements, 0.2, 0, SO3::Tangent::Zero());
  const auto b = cohort(rng, n, elements, 0.2, 6, SO3::Tangent(0.25, 0, 0));
  for (const auto mode : {bireg::ElementwiseMode::linearised, bireg::ElementwiseMode::exact}) {
    auto options = options_for(mode, 199);
    options.test.statistic = bireg::TwoSampleStatistic::hellinger;
    const auto whole = bireg::elementwise_two_sample_test<bireg::SO3d>(
        a, std::size_t(m), b, std::size_t(n), std::size_t(elements), options);
    REQUIRE(whole.ok());
    const auto slice = [&](int first, int count) {
      std::vector<SO3::Element> slice_a, slice_b;
      for (int i = 0; i < m; ++i)
        for (int k = first; k < first + count; ++k)
          slice_a.push_back(a[std::size_t(i * elements + k)]);
      for (int j = 0; j < n; ++j)
        for (int k = first; k < first + count; ++k)
          slice_b.push_back(b[std::size_t(j * elements + k)]);
      return bireg::elementwise_two_sample_test<bireg::SO3d>(
          slice_a, std::size_t(m), slice_b, std::size_t(n), std::size_t(count), options);
    };
    const auto combined =
        bireg::combine_elementwise<bireg::SO3d>({slice(0, 10), slice(10, 20), slice(30, 7)});
    REQUIRE(combined.ok());
    REQUIRE(combined.elements == std::size_t(elements));
    CHECK(combined.value == whole.value);
    CHECK(combined.p_value == whole.p_value);
    CHECK(combined.p_fwer == whole.p_fwer);
    CHECK(combined.q_value == whole.q_value);
    // The shifted elements make the adjustment matter: some family-wise
    // p-value is above its element's p-value (else joining could skip it).
    bool adjusted = false;
    for (int k = 0; k < elements; ++k)
      adjusted = adjusted || whole.p_fwer[std::size_t(k)] > whole.p_value[std::size_t(k)];
    CHECK(adjusted);
    // The family-wise p-values by their definition, counted by hand.
    REQUIRE(whole.relabelling_maximum.size() == 199);
    for (int k = 0; k < elements; ++k) {
      const double threshold = whole.ranked_value[std::size_t(k)] * (1 - 1e-9);
      int beyond = 0;
      for (const double maximum : whole.relabelling_maximum)
        beyond += maximum >= threshold ? 1 : 0;
      CHECK(whole.p_fwer[std::size_t(k)] == (1.0 + beyond) / 200.0);
    }
    // Slices of other relabellings do not join.
    auto fewer = options;
    fewer.test.permutations = 99;
    const auto other = bireg::elementwise_two_sample_test<bireg::SO3d>(
        a, std::size_t(m), b, std::size_t(n), std::size_t(elements), fewer);
    CHECK(!bireg::combine_elementwise<bireg::SO3d>({slice(0, 10), other}).ok());
    // Nor slices of another seed or statistic.
    auto reseeded = slice(10, 20);
    reseeded.seed += 1;
    CHECK(!bireg::combine_elementwise<bireg::SO3d>({slice(0, 10), reseeded}).ok());
    auto restated = slice(10, 20);
    restated.statistic = bireg::TwoSampleStatistic::hotelling;
    CHECK(!bireg::combine_elementwise<bireg::SO3d>({slice(0, 10), restated}).ok());
  }
}

TEST_CASE("Element-wise maps refuse bad input and name the element", "[cohorts][maps][hostile]") {
  std::mt19937 rng(5);
  auto a = cohort(rng, 6, 3, 0.3, 0, SO3::Tangent::Zero());
  const auto b = cohort(rng, 6, 3, 0.3, 0, SO3::Tangent::Zero());
  const auto options = options_for(bireg::ElementwiseMode::linearised, 9);
  const auto mismatched = bireg::elementwise_two_sample_test<SO3>(a, 6, b, 6, 4, options);
  CHECK(mismatched.status == bireg::Status::invalid_input);
  CHECK(mismatched.message.find("K = 4") != std::string::npos);
  CHECK(bireg::elementwise_two_sample_test<SO3>(a, 6, b, 6, 0, options).status ==
        bireg::Status::invalid_input);
  auto bhattacharyya = options;
  bhattacharyya.test.statistic = bireg::TwoSampleStatistic::bhattacharyya;
  const auto small = bireg::elementwise_two_sample_test<SO3>(
      std::vector<SO3::Element>(a.begin(), a.begin() + 9), 3, b, 6, 3, bhattacharyya);
  CHECK(small.message.find("more than 3") != std::string::npos);
  a[4 * 3 + 2](1, 1) = std::nan("");
  const auto with_nan = bireg::elementwise_two_sample_test<SO3>(a, 6, b, 6, 3, options);
  INFO(with_nan.message);
  CHECK_FALSE(with_nan.ok());
  CHECK(with_nan.bad_element == 2);
  CHECK(with_nan.message.find("element 2") != std::string::npos);
  // A slice of a larger map names the element by its index in the map.
  auto slice = options;
  slice.first_element = 30;
  const auto in_slice = bireg::elementwise_two_sample_test<SO3>(a, 6, b, 6, 3, slice);
  CHECK(in_slice.bad_element == 32);
  CHECK(in_slice.message.find("element 32:") != std::string::npos);
}
