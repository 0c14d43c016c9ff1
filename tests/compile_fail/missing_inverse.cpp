// No inverse(Element).
// expect-error: bireg group concept: G needs static identity(), compose(Element, Element) and inverse(Element), each returning Element
#define BIREG_TOY_NO_INVERSE
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
