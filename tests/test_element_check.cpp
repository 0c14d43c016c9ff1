// bireg::first_non_element (groups/element_check.hpp): the index of the first
// row-major matrix that G::is_element refuses, for SO(3) and SE(3) by the
// straight-line block loop and for other groups by is_element itself.
//
// What must hold: the verdict is is_element's. The block loop evaluates the
// same functions of the entries (groups/membership.hpp), but a compiler may
// contract them into fused multiply-adds differently there and in is_element,
// so a matrix within a rounding error of the tolerance may be judged either
// way; the comparison on random near-elements skips the few whose is_element
// verdict changes when the tolerance moves by 1e-6 of itself (far more than the
// rounding of a sum of three products of entries of size 1, a few 1e-16).
//
// The block loop is written to be vectorized across matrices, so this file
// is also built with -march=haswell and -march=skylake-avx512
// (tests/CMakeLists.txt), as the Python module's clones compile it.
#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "bireg/groups/element_check.hpp"
#include "bireg/groups/se2.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

template <class G>
using RowMajor = Eigen::Matrix<typename G::Scalar, G::Element::RowsAtCompileTime,
                               G::Element::ColsAtCompileTime, Eigen::RowMajor>;

template <class G>
constexpr std::size_t kEntries =
    std::size_t(G::Element::RowsAtCompileTime) * std::size_t(G::Element::ColsAtCompileTime);

// count random elements, row-major, one after another.
template <class G>
std::vector<typename G::Scalar> random_stack(std::size_t count, std::mt19937& rng) {
  std::vector<typename G::Scalar> data(count * kEntries<G>);
  for (std::size_t i = 0; i < count; ++i) {
    Eigen::Map<RowMajor<G>> target(data.data() + i * kEntries<G>);
    target = G::exp(bireg_test::random_tangent<typename G::Tangent>(rng, 1.5));
  }
  return data;
}

template <class G>
bool is_element_at(const std::vector<typename G::Scalar>& data, std::size_t i,
                   typename G::Scalar tol) {
  const typename G::Element element = Eigen::Map<const RowMajor<G>>(data.data() + i * kEntries<G>);
  return G::is_element(element, tol);
}

// Entry (r, c) of matrix i changed to `value`.
template <class G>
void set_entry(std::vector<typename G::Scalar>& data, std::size_t i, int r, int c, double value) {
  const int side = G::Element::ColsAtCompileTime;
  data[i * kEntries<G> + std::size_t(r * side + c)] = typename G::Scalar(value);
}

// SO(3), SE(3): every way of not being an element that is_element tests,
// put at block edges (the loop checks 256 matrices at a time) and inside blocks: the
// index returned is that matrix's.
template <class G>
void check_each_defect(std::mt19937& rng) {
  using Scalar = typename G::Scalar;
  constexpr int n = G::Element::ColsAtCompileTime;
  const Scalar tol = bireg::default_element_tolerance<Scalar>();
  const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN();
  const Scalar inf = std::numeric_limits<Scalar>::infinity();
  const std::size_t count = 1000;
  const std::vector<Scalar> clean = random_stack<G>(count, rng);
  CHECK(bireg::first_non_element<G>(clean.data(), count) == count);
  CHECK(bireg::first_non_element<G>(clean.data(), 0) == 0);
  // Entries of the rotation block moved off R^T R = I by 100 tol, or made
  // not finite.
  struct Defect {
    int r, c;
    bool moved;  // true: add 100 tol; false: set to `value`
    Scalar value;
  };
  const Defect defects[] = {{0, 0, true, 0},    {1, 2, true, 0},    {2, 1, true, 0},
                            {0, 1, false, nan}, {2, 2, false, inf}, {1, 0, false, -inf}};
  for (const std::size_t at : {std::size_t(0), std::size_t(1), std::size_t(255), std::size_t(256),
                               std::size_t(257), std::size_t(511), std::size_t(999)}) {
    CAPTURE(G::name, at);
    for (const Defect& defect : defects) {
      CAPTURE(defect.r, defect.c, defect.moved, defect.value);
      std::vector<Scalar> data = clean;
      Scalar& entry = data[at * kEntries<G> + std::size_t(defect.r * n + defect.c)];
      entry = defect.moved ? entry + 100 * tol : defect.value;
      REQUIRE_FALSE(is_element_at<G>(data, at, tol));
      CHECK(bireg::first_non_element<G>(data.data(), count, tol) == at);
      // The matrices before it alone, in an array of their own: a read
      // beyond `count` would be the sanitizers' to catch.
      const std::vector<Scalar> before(data.begin(),
                                       data.begin() + std::ptrdiff_t(at * kEntries<G>));
      CHECK(bireg::first_non_element<G>(before.data(), at, tol) == at);
    }
    // The rows below the rotation (SE(3): the last row (0, 0, 0, 1)) and
    // the translation column.
    if constexpr (n == 4) {
      for (const auto& [r, c, value] :
           {std::tuple{3, 0, 1e-3}, std::tuple{3, 2, -1e-3}, std::tuple{3, 3, 1 + 1e-3},
            std::tuple{3, 1, double(nan)}, std::tuple{0, 3, double(nan)},
            std::tuple{2, 3, double(inf)}}) {
        CAPTURE(r, c, value);
        std::vector<Scalar> data = clean;
        set_entry<G>(data, at, r, c, value);
        REQUIRE_FALSE(is_element_at<G>(data, at, tol));
        CHECK(bireg::first_non_element<G>(data.data(), count, tol) == at);
      }
    }
    // A reflection: orthogonal, determinant -1.
    std::vector<Scalar> data = clean;
    for (int c = 0; c < 3; ++c)
      data[at * kEntries<G> + std::size_t(c)] = -data[at * kEntries<G> + std::size_t(c)];
    REQUIRE_FALSE(is_element_at<G>(data, at, tol));
    CHECK(bireg::first_non_element<G>(data.data(), count, tol) == at);
  }
}

// Random near-elements, their departures spread over 1e-12 .. 1e-4 around
// a tolerance of 1e-8: the same verdict as is_element, matrix by matrix.
template <class G>
void check_agreement(std::mt19937& rng) {
  using Scalar = typename G::Scalar;
  const Scalar tol = Scalar(1e-8);
  std::uniform_real_distribution<double> exponent(-12, -4), unit(-1, 1);
  std::uniform_int_distribution<std::size_t> entry(0, kEntries<G> - 1);
  const std::size_t count = 4000;
  std::vector<Scalar> data = random_stack<G>(count, rng);
  for (std::size_t i = 0; i < count; ++i)
    data[i * kEntries<G> + entry(rng)] += Scalar(unit(rng) * std::pow(10.0, exponent(rng)));
  int compared = 0, refused = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const bool verdict = is_element_at<G>(data, i, tol);
    if (verdict != is_element_at<G>(data, i, tol * Scalar(1 - 1e-6)) ||
        verdict != is_element_at<G>(data, i, tol * Scalar(1 + 1e-6)))
      continue;
    ++compared;
    refused += verdict ? 0 : 1;
    CAPTURE(G::name, i);
    CHECK((bireg::first_non_element<G>(data.data() + i * kEntries<G>, 1, tol) == 0) == !verdict);
  }
  // Both verdicts occur often: the comparison means something.
  CHECK(compared > 3900);
  CHECK(refused > 500);
  CHECK(refused < compared - 500);
}

}  // namespace

TEST_CASE("first_non_element names the first matrix is_element refuses", "[element_check]") {
  std::mt19937 rng(20261129);
  check_each_defect<bireg::SO3d>(rng);
  check_each_defect<bireg::SE3d>(rng);
  check_each_defect<bireg::SO3<float>>(rng);
  check_each_defect<bireg::SE3<float>>(rng);
  // Another group: is_element itself, matrix by matrix.
  std::vector<double> data = random_stack<bireg::SE2d>(600, rng);
  CHECK(bireg::first_non_element<bireg::SE2d>(data.data(), 600) == 600);
  set_entry<bireg::SE2d>(data, 400, 2, 0, 1e-3);
  set_entry<bireg::SE2d>(data, 256, 0, 2, std::nan(""));
  CHECK(bireg::first_non_element<bireg::SE2d>(data.data(), 600) == 256);
}

TEST_CASE("first_non_element agrees with is_element away from the tolerance", "[element_check]") {
  std::mt19937 rng(7);
  check_agreement<bireg::SO3d>(rng);
  check_agreement<bireg::SE3d>(rng);
  check_agreement<bireg::SE2d>(rng);
}

TEST_CASE("an infinite tolerance is is_element's: entries must still be finite",
          "[element_check]") {
  std::mt19937 rng(3);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> data = random_stack<bireg::SE3d>(300, rng);
  CHECK(bireg::first_non_element<bireg::SE3d>(data.data(), 300, inf) == 300);
  // An infinite entry of the last row: every departure is within an
  // infinite tolerance, so only a test of finiteness refuses it.
  data[270 * 16 + 12] = inf;
  REQUIRE_FALSE(is_element_at<bireg::SE3d>(data, 270, inf));
  CHECK(bireg::first_non_element<bireg::SE3d>(data.data(), 300, inf) == 270);
}
