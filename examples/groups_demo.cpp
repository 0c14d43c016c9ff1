// A first look at bireg's group traits: a rigid motion, its logarithm, and
// the adjoint that moves a twist between frames.
#include <cstdio>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"

int main() {
  using G = bireg::SE3<double>;
  G::Tangent twist;  // translation first, then rotation vector
  twist << 1.0, 0.0, 0.5, 0.0, 0.0, 1.2;
  const G::Element pose = G::exp(twist);
  const G::Tangent recovered = G::log(pose);
  std::printf("pose = exp(twist):\n");
  for (int i = 0; i < 4; ++i) {
    std::printf("  % .6f % .6f % .6f % .6f\n", pose(i, 0), pose(i, 1), pose(i, 2), pose(i, 3));
  }
  std::printf("log(pose) - twist: %.2e\n", (recovered - twist).norm());
  const G::Tangent moved = G::Ad(pose) * twist;
  std::printf("Ad(pose) twist = (% .4f % .4f % .4f | % .4f % .4f % .4f)\n", moved[0], moved[1],
              moved[2], moved[3], moved[4], moved[5]);
  return 0;
}
