// GeodesicRegression on SL(3) and GL+(3), whose exp and log are Eigen's
// general matrix functions: the checks of scene_groups.hpp (the other scene
// groups: test_scene_groups.cpp).
#include "bireg/groups/matrix_group.hpp"
#include "catch.hpp"
#include "scene_groups.hpp"

TEMPLATE_TEST_CASE("scene groups: noise-free geodesics are recovered", "[scene][regression]",
                   bireg::SL3<double>, (bireg::GLp<3, double>)) {
  scene_groups::check_noise_free_recovery<TestType>();
}

TEMPLATE_TEST_CASE("scene groups: the fit is left, right and inverse equivariant",
                   "[scene][regression][equivariance]", bireg::SL3<double>,
                   (bireg::GLp<3, double>)) {
  scene_groups::check_equivariance<TestType>();
}

TEMPLATE_TEST_CASE("scene groups: the estimating equations hold at the solution",
                   "[scene][regression]", bireg::SL3<double>, (bireg::GLp<3, double>)) {
  scene_groups::check_estimating_equations<TestType>();
}
