// Control for the compile-fail tests (built with the suite, not a ctest):
// the toy group with nothing broken satisfies the concept and instantiates
// the regression, so each compile-fail test fails only for what it breaks.
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
static_assert(sizeof(bireg::GeodesicRegression<Toy>) > 0);
