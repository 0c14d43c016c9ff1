// No inverse(Element).
// The expected message must stay on one line:
// clang-format off
// expect-error: bireg group concept: G needs static identity(), compose(Element, Element) and inverse(Element), each returning Element
// clang-format on
#define BIREG_TOY_NO_INVERSE
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
