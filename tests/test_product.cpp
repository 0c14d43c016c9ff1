// Product<G1, G2>: the group identities component-wise, and
// Product<SO3, Rn<3>> against SE3 on the same poses: they agree when nothing
// rotates and differ exactly where SE(3) couples rotation and translation.
#include <random>
#include <vector>

#include "bireg/concept.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;
using bireg_test::relative_error;

namespace {
using Rotation = bireg::SO3<double>;
using Translation = bireg::Rn<3, double>;
using P = bireg::Product<Rotation, Translation>;
using Pose = bireg::SE3<double>;

P::Element to_product(const Pose::Element& g) {
  return {g.topLeftCorner<3, 3>(), g.topRightCorner<3, 1>()};
}
Pose::Element to_pose(const P::Element& p) {
  Pose::Element g = Pose::Element::Identity();
  g.topLeftCorner<3, 3>() = p.first;
  g.topRightCorner<3, 1>() = p.second;
  return g;
}
double distance(const P::Element& a, const P::Element& b) {
  return std::max(relative_error(a.first, b.first), relative_error(a.second, b.second));
}
}  // namespace

TEST_CASE("Product acts component-wise", "[product]") {
  STATIC_REQUIRE(bireg::check_lie_group<P>());
  STATIC_REQUIRE(P::dof == 6);
  std::mt19937 rng(101);
  for (int i = 0; i < 50; ++i) {
    const P::Tangent x = random_tangent<P::Tangent>(rng, 1.0);
    const P::Element a = P::exp(random_tangent<P::Tangent>(rng, 1.0));
    const P::Element b = P::exp(random_tangent<P::Tangent>(rng, 1.0));
    // Each factor's operations, so each factor's accuracy (64 eps, see
    // test_groups.cpp).
    const double tolerance = 64 * 2.2e-16;
    REQUIRE(relative_error(P::log(P::exp(x)), x) <= tolerance);
    REQUIRE(P::vee(P::hat(x)) == x);
    REQUIRE(distance(P::compose(a, P::inverse(a)), P::identity()) <= tolerance);
    REQUIRE(relative_error(P::Ad(P::compose(a, b)), P::Ad(a) * P::Ad(b)) <= 8 * tolerance);
    // The translation factor is commutative: its blocks of ad vanish.
    REQUIRE(P::ad(x).bottomRightCorner<3, 3>().isZero(0));
    REQUIRE(P::ad(x).topRightCorner<3, 3>().isZero(0));
    REQUIRE(P::ad(x).topLeftCorner<3, 3>() == Rotation::ad(x.head<3>()));
    // SO3 x R3 composes translations without rotating them; SE3 rotates them.
    const Pose::Element pa = to_pose(a), pb = to_pose(b);
    REQUIRE(relative_error(P::compose(a, b).second, Eigen::Vector3d(a.second + b.second)) <=
            tolerance);
    REQUIRE(relative_error(Pose::compose(pa, pb).topRightCorner<3, 1>(),
                           Eigen::Vector3d(a.first * b.second + a.second)) <= tolerance);
  }
}

// Poses whose translation moves on a straight line while the orientation
// turns lie on a geodesic of SO3 x R3, not of SE3 (whose geodesics are
// screws); poses on a screw are the other way round. Each group recovers its
// own geodesics to 1e-12 from noise-free data and leaves residuals of the
// order of the coupling (here > 1e-2) on the other's. Without rotation both
// are straight lines and the two fits coincide.
TEST_CASE("Product<SO3, Rn<3>> differs from SE3 exactly as the mathematics says", "[product]") {
  const Rotation::Tangent omega(0.4, -0.8, 0.6);  // about 1.08 rad over the range
  const Eigen::Vector3d start(1.0, -0.5, 2.0), velocity(1.5, 0.3, -0.8);
  std::vector<P::Element> straight_p, screw_p, still_p;
  std::vector<Pose::Element> straight_se3, screw_se3, still_se3;
  std::vector<double> t;
  Pose::Tangent twist;
  twist << velocity, omega;
  const Pose::Element screw_start = Pose::exp((Pose::Tangent() << start, 0.1, 0.2, 0.3).finished());
  for (int i = 0; i < 30; ++i) {
    const double s = i / 29.0;
    const P::Element straight{Rotation::exp(s * omega), start + s * velocity};
    const P::Element still{Rotation::identity(), start + s * velocity};
    const Pose::Element screw = Pose::compose(screw_start, Pose::exp(s * twist));
    straight_p.push_back(straight);
    straight_se3.push_back(to_pose(straight));
    still_p.push_back(still);
    still_se3.push_back(to_pose(still));
    screw_se3.push_back(screw);
    screw_p.push_back(to_product(screw));
    t.push_back(s);
  }
  bireg::GeodesicRegression<P>::Options product_options;
  bireg::GeodesicRegression<Pose>::Options pose_options;
  product_options.tolerance = pose_options.tolerance = 1e-14;
  const bireg::GeodesicRegression<P> product(product_options);
  const bireg::GeodesicRegression<Pose> pose(pose_options);

  const auto p_straight = product.fit(straight_p, t);
  const auto s_straight = pose.fit(straight_se3, t);
  REQUIRE(p_straight.ok());
  REQUIRE(s_straight.ok());
  REQUIRE(distance(p_straight.geodesic->end(), straight_p.back()) <= 1e-12);
  REQUIRE(p_straight.diagnostics.residual_rms <= 1e-12);
  REQUIRE(s_straight.diagnostics.residual_rms > 1e-2);

  const auto p_screw = product.fit(screw_p, t);
  const auto s_screw = pose.fit(screw_se3, t);
  REQUIRE(p_screw.ok());
  REQUIRE(s_screw.ok());
  REQUIRE(relative_error(s_screw.geodesic->end(), screw_se3.back()) <= 1e-12);
  REQUIRE(s_screw.diagnostics.residual_rms <= 1e-12);
  REQUIRE(p_screw.diagnostics.residual_rms > 1e-2);

  const auto p_still = product.fit(still_p, t);
  const auto s_still = pose.fit(still_se3, t);
  REQUIRE(p_still.ok());
  REQUIRE(s_still.ok());
  REQUIRE(relative_error(to_pose(p_still.geodesic->start()), s_still.geodesic->start()) <= 1e-12);
  REQUIRE(relative_error(to_pose(p_still.geodesic->end()), s_still.geodesic->end()) <= 1e-12);
}
