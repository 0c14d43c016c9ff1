// No is_element(Element, Scalar).
// expect-error: bireg group concept: G needs static is_element(Element, Scalar tol) -> bool
#define BIREG_TOY_NO_IS_ELEMENT
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
