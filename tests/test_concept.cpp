// The compile-time concept check accepts the shipped groups and a minimal
// user-written group, and tells a group that misses pieces apart.
#include "bireg/concept.hpp"
#include "bireg/groups/se3.hpp"
#include "catch.hpp"

namespace {

// The smallest group a user could write: the circle as R / 2pi Z, with the
// angle as element. It exists to show that the recipe in the README is
// complete.
struct Circle {
  using Scalar = double;
  static constexpr int dof = 1;
  static constexpr const char* name = "Circle";
  using Element = Eigen::Matrix<double, 1, 1>;
  using Tangent = Eigen::Matrix<double, 1, 1>;
  using AdMatrix = Eigen::Matrix<double, 1, 1>;
  using Algebra = Eigen::Matrix<double, 1, 1>;
  static Element identity() { return Element::Zero(); }
  static Element compose(const Element& a, const Element& b) { return a + b; }
  static Element inverse(const Element& g) { return -g; }
  static Element exp(const Tangent& x) { return x; }
  static Tangent log(const Element& g) { return g; }
  static Algebra hat(const Tangent& x) { return x; }
  static Tangent vee(const Algebra& m) { return m; }
  static AdMatrix ad(const Tangent&) { return AdMatrix::Zero(); }
  static AdMatrix Ad(const Element&) { return AdMatrix::Identity(); }
  static bool is_element(const Element& g, double) { return g.allFinite(); }
};

struct MissingLog {
  using Scalar = double;
  static constexpr int dof = 1;
  static constexpr const char* name = "MissingLog";
  using Element = Eigen::Matrix<double, 1, 1>;
  using Tangent = Eigen::Matrix<double, 1, 1>;
  using AdMatrix = Eigen::Matrix<double, 1, 1>;
  using Algebra = Eigen::Matrix<double, 1, 1>;
  static Element identity() { return Element::Zero(); }
  static Element compose(const Element& a, const Element& b) { return a + b; }
  static Element inverse(const Element& g) { return -g; }
  static Element exp(const Tangent& x) { return x; }
  static Algebra hat(const Tangent& x) { return x; }
  static Tangent vee(const Algebra& m) { return m; }
  static AdMatrix ad(const Tangent&) { return AdMatrix::Zero(); }
  static AdMatrix Ad(const Element&) { return AdMatrix::Identity(); }
  static bool is_element(const Element&, double) { return true; }
};

struct WrongTangentSize : bireg::SE3<double> {
  using Tangent = Eigen::Matrix<double, 5, 1>;
};

struct NotAGroup {};

}  // namespace

TEST_CASE("the concept check tells groups from non-groups", "[concept]") {
  STATIC_REQUIRE(bireg::is_lie_group_v<Circle>);
  STATIC_REQUIRE(bireg::is_lie_group_v<bireg::SE3<double>>);
  STATIC_REQUIRE_FALSE(bireg::is_lie_group_v<MissingLog>);
  STATIC_REQUIRE_FALSE(bireg::is_lie_group_v<WrongTangentSize>);
  STATIC_REQUIRE_FALSE(bireg::is_lie_group_v<NotAGroup>);
}
