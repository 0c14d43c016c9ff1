// Uses one group through the installed headers; exits non-zero on a wrong
// round trip so that the consumer test checks behaviour, not only linkage.
#include <cstdio>

#include <bireg/groups/se3.hpp>
#include <bireg/version.hpp>  // generated: installed, or in bireg's build tree

int main() {
  using G = bireg::SE3<double>;
  G::Tangent xi;
  xi << 0.1, -0.2, 0.3, 0.4, 0.5, -0.6;
  const double error = (G::log(G::exp(xi)) - xi).norm();
  std::printf("consumer: bireg %s, SE3 log(exp(xi)) error %.3g\n", bireg::version, error);
  return error < 1e-12 ? 0 : 1;
}
