// A group without AdMatrix: the concept names every type it needs.
// The expected message must stay on one line:
// clang-format off
// expect-error: bireg group concept: G must define Scalar, Element, Tangent, AdMatrix, static constexpr int dof and static constexpr const char* name
// clang-format on
#define BIREG_TOY_NO_ADMATRIX
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
