// A row vector as Tangent: the concept asks for a column of size dof.
// expect-error: bireg group concept: G::Tangent must be Eigen::Matrix<Scalar, dof, 1>
#define BIREG_TOY_ROW_TANGENT
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
