// What a user meets: the regression over a group without log(Element)
// stops at the concept's message, not deep inside the solver.
// The expected message must stay on one line:
// clang-format off
// expect-error: bireg group concept: G needs static exp(Tangent) -> Element and log(Element) -> Tangent
// clang-format on
#define BIREG_TOY_NO_LOG
#include "toy_group.hpp"

int main() {
  bireg::GeodesicRegression<Toy> regression;
  (void)regression;
}
