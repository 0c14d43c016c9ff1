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
