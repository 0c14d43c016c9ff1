// GeodesicRegression on Sim(3), the Heisenberg group and SO(3) x R^3
// (Product): the checks of scene_groups.hpp, and Sim(3) at the extremes of
// scale. SL(3) and GL+(3): test_scene_groups_matrix.cpp.
#include <random>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "scene_groups.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;
using scene_groups::distance;
using scene_groups::kTolerance;
using scene_groups::make_scene;
using scene_groups::regression;
using scene_groups::Scene;

TEMPLATE_TEST_CASE("scene groups: noise-free geodesics are recovered", "[scene][regression]",
                   bireg::Sim3<double>, bireg::Heisenberg<double>,
                   (bireg::Product<bireg::SO3<double>, bireg::Rn<3, double>>)) {
  scene_groups::check_noise_free_recovery<TestType>();
}

TEMPLATE_TEST_CASE("scene groups: the fit is left, right and inverse equivariant",
                   "[scene][regression][equivariance]", bireg::Sim3<double>,
                   bireg::Heisenberg<double>,
                   (bireg::Product<bireg::SO3<double>, bireg::Rn<3, double>>)) {
  scene_groups::check_equivariance<TestType>();
}

TEMPLATE_TEST_CASE("scene groups: the estimating equations hold at the solution",
                   "[scene][regression]", bireg::Sim3<double>, bireg::Heisenberg<double>,
                   (bireg::Product<bireg::SO3<double>, bireg::Rn<3, double>>)) {
  scene_groups::check_estimating_equations<TestType>();
}

// Sim(3) at the extremes of scale: data moved to log-scale +-20 from either
// side give the moved fit, and a geodesic whose scale grows by e^3 is
// recovered. The moving element has no translation: an O(1) translation
// next to a scale of e^-20 would leave the data's detail (size e^-20 on top
// of 1) to ~1e-7 relative rounding in any 4x4 representation; the fit then
// stops with `rounding_floor` (a success: ok() is true) once its steps reach that floor (checked
// below).
TEST_CASE("Sim3 regression at log-scales +-20 and large scale changes", "[scene][sim3]") {
  using G = bireg::Sim3<double>;
  std::mt19937 rng(504);
  const Scene<G> scene = make_scene<G>(rng);
  const auto fit = regression<G>();
  const auto base = fit.fit(scene.noisy, scene.t);
  REQUIRE(base.ok());
  for (double log_scale : {-20.0, 20.0}) {
    G::Tangent y = random_tangent<G::Tangent>(rng, 1.0);
    y.head<3>().setZero();
    y[6] = log_scale;
    const G::Element h = G::exp(y);
    std::vector<G::Element> left, right;
    for (const G::Element& f : scene.noisy) {
      left.push_back(G::compose(h, f));
      right.push_back(G::compose(f, h));
    }
    // Right multiplication maps tangent coordinates by Ad_{h^-1}, which
    // stretches translations by e^-log_scale: the (absolute) step tolerance
    // and the comparison scale by the same factor.
    const double stretch = G::Ad(G::inverse(h)).norm();
    typename bireg::GeodesicRegression<G>::Options stretched;
    stretched.tolerance = 1e-13 * stretch;
    const auto l = fit.fit(left, scene.t);
    const auto r = bireg::GeodesicRegression<G>(stretched).fit(right, scene.t);
    CAPTURE(log_scale, stretch);
    REQUIRE((l.ok() && r.ok()));
    for (double s : {0.0, 1.0}) {
      REQUIRE(distance<G>((*l.geodesic)(s), G::compose(h, (*base.geodesic)(s))) <= kTolerance);
      REQUIRE(distance<G>((*r.geodesic)(s), G::compose((*base.geodesic)(s), h)) <=
              kTolerance * stretch);
    }
  }

  // The rounding floor: h with translation 1 and scale e^-20.
  G::Tangent y = G::Tangent::Zero();
  y[0] = 1.0;
  y[6] = -20.0;
  std::vector<G::Element> buried;
  for (const G::Element& f : scene.noisy)
    buried.push_back(G::compose(G::exp(y), f));
  const auto floor = fit.fit(buried, scene.t);
  REQUIRE(floor.status == bireg::Status::rounding_floor);
  REQUIRE(floor.ok());
  REQUIRE(floor.iterations < 50);

  G::Tangent growth;
  growth << 2.0, -1.0, 0.5, 0.3, 0.8, -0.4, 3.0;
  std::vector<G::Element> growing;
  for (double s : scene.t)
    growing.push_back(G::compose(scene.g0, G::exp(s * growth)));
  const auto grown = fit.fit(growing, scene.t);
  REQUIRE(grown.ok());
  REQUIRE(distance<G>(grown.geodesic->end(), G::compose(scene.g0, G::exp(growth))) <= kTolerance);
}
