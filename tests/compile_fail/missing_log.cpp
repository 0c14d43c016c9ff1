// No log(Element).
// The expected message must stay on one line:
// clang-format off
// expect-error: bireg group concept: G needs static exp(Tangent) -> Element and log(Element) -> Tangent
// clang-format on
#define BIREG_TOY_NO_LOG
#include "toy_group.hpp"

static_assert(bireg::check_lie_group<Toy>());
