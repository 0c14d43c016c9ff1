// ad(Tangent) but no Ad(Element).
// expect-error: bireg group concept: G needs static ad(Tangent) and Ad(Element) returning AdMatrix
#define BIREG_TOY_NO_AD_OF_ELEMENT
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
