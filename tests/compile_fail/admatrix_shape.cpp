// A 2 x 3 AdMatrix for a group of dof 2.
// expect-error: bireg group concept: G::AdMatrix must be Eigen::Matrix<Scalar, dof, dof>
#define BIREG_TOY_WIDE_ADMATRIX
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
