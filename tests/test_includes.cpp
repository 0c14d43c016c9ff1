// Each header includes only what it needs: the closed-form groups, the
// product, the geodesic, the regression and the tools compile without
// Eigen's matrix-function module (unsupported/MatrixFunctions), which only
// bireg/groups/matrix_group.hpp includes. Checked through that module's
// include guard, before anything else is included.
#include "bireg/geodesic.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"

#ifdef EIGEN_MATRIX_FUNCTIONS
constexpr bool kMatrixFunctionsIncluded = true;
#else
constexpr bool kMatrixFunctionsIncluded = false;
#endif

#include "catch.hpp"

TEST_CASE("closed-form headers do not pull in matrix functions", "[includes]") {
  STATIC_REQUIRE_FALSE(kMatrixFunctionsIncluded);
}

// The umbrella header is everything (issue 36, defect 4): the statistics
// are reachable through bireg/bireg.hpp alone (no statistics header is
// included above; matrix functions are checked above, before this). The
// generic lambdas are never called: naming bireg::trend_test and friends
// in them needs only their declarations, which keeps this file quick to
// compile; mean, covariance and the robust fit run once on SO(3).
#include <cmath>
#include <type_traits>
#include <vector>

#include "bireg/bireg.hpp"

TEST_CASE("bireg/bireg.hpp includes the statistics", "[includes]") {
  using G = bireg::SO3<double>;
  std::vector<G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 12; ++i) {
    const G::Tangent noise(std::sin(1.3 * i), std::cos(2.1 * i), std::sin(0.7 * i + 1));
    f.push_back(G::exp(G::Tangent(0.1 * i, 0.02 * i, 0) + 0.01 * noise));
    t.push_back(i);
  }
  const bireg::MeanResult<G> m = bireg::mean<G>(f);
  REQUIRE(m.ok());
  const auto fit = bireg::GeodesicRegression<G>().fit(f, t);
  REQUIRE(fit.ok());
  const bireg::FitCovariance<G> c = bireg::covariance(fit, t);
  REQUIRE(c.defined());
  const bireg::RobustGeodesicRegression<G> robust;
  REQUIRE(robust.fit(f, t).fit.geodesic.has_value());

  const auto trend = [](const auto& observations, const auto& covariates) {
    return bireg::trend_test(bireg::GeodesicRegression<G>(), observations, covariates);
  };
  const auto motion = [](const auto& poses, const auto& times) {
    return bireg::select_motion_model(poses, times);
  };
  const auto local = [](const auto& options, const auto& observations, const auto& covariates) {
    return bireg::LocalGeodesicRegression<G>(options).smooth(observations, covariates);
  };
  static_cast<void>(trend);
  static_cast<void>(motion);
  static_cast<void>(local);
  STATIC_REQUIRE(std::is_same_v<decltype(bireg::TrendTestOptions().permutations), int>);
}
