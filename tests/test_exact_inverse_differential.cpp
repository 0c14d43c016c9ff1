// Method::exact against a long double reference: the series with 64 terms
// evaluated in long double (omitted terms below (pi / 2 pi)^64 ~ 5e-20 of
// the first), densely in the angle (0 and 1e-10 .. pi, eight angles per
// decade below 0.1, steps of 0.05 above) and in s, for both signs of X.
// Bound: 1e-14 relative (the target); the closed forms measure
// <= 6e-16 from 0.25 rad on, and the series branch below it carries a few
// ulps per term.
#include <cmath>
#include <random>
#include <vector>

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/math/psi_series.hpp"
#include "catch.hpp"

namespace {

std::vector<double> angles() {
  std::vector<double> out = {0.0};
  for (int i = 0; i <= 72; ++i)
    out.push_back(std::pow(10.0, -10.0 + i / 8.0));  // 1e-10 .. 1
  for (double a = 1.0; a < 3.14159; a += 0.05)
    out.push_back(a);
  for (double a : {3.1, 3.14, 3.1415, 3.14159265, 3.141592653589793})
    out.push_back(a);
  return out;
}

template <class G, class GL>
void check_exact(std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (double angle : angles()) {
    for (int trial = 0; trial < 4; ++trial) {
      typename G::Tangent x, r;
      for (int k = 0; k < G::dof; ++k) {
        x[k] = uniform(rng);
        r[k] = uniform(rng);
      }
      if constexpr (G::dof == 6) {
        x.template tail<3>() *= angle / x.template tail<3>().norm();
      } else if constexpr (G::dof == 3 && std::is_same_v<G, bireg::SE2<double>>) {
        x[2] = trial % 2 ? angle : -angle;
      } else {
        x *= angle / x.norm();
      }
      for (double s : {0.0, 1e-8, 0.01, 0.25, 0.5, 0.75, 0.99, 1.0}) {
        for (int sign : {1, -1}) {
          const typename G::Tangent xs = sign * x;
          const typename G::Tangent value = bireg::apply_psi<G>(xs, s, r);
          const typename GL::AdMatrix a = GL::ad(xs.template cast<long double>());
          const auto reference = bireg::apply_psi_series<long double, G::dof>(
              a, static_cast<long double>(s), r.template cast<long double>(),
              bireg::kMaxSeriesOrder);
          const long double scale = std::max<long double>(reference.norm(), s * r.norm());
          CAPTURE(G::name, angle, s, sign);
          if (scale == 0) {
            REQUIRE(value.isZero(0));
          } else {
            REQUIRE((value.template cast<long double>() - reference).norm() / scale <= 1e-14L);
          }
        }
      }
    }
  }
}

}  // namespace

TEST_CASE("exact inverse differentials are within 1e-14 of a long double reference", "[exact]") {
  std::mt19937 rng(81);
  check_exact<bireg::SO3<double>, bireg::SO3<long double>>(rng);
  check_exact<bireg::SE3<double>, bireg::SE3<long double>>(rng);
  check_exact<bireg::SE2<double>, bireg::SE2<long double>>(rng);
  check_exact<bireg::SO2<double>, bireg::SO2<long double>>(rng);
}
