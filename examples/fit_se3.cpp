// Fit a geodesic to a noisy SE(3) trajectory: the regression line of a rigid
// body moving with constant body velocity, observed with noise.
#include <cstdio>
#include <random>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"

int main() {
  using G = bireg::SE3<double>;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.05);

  // Ground truth: start pose g0, body velocity (translation first) per second.
  G::Tangent start_twist, velocity;
  start_twist << 0.5, -1.0, 2.0, 0.3, -0.2, 0.1;
  velocity << 0.4, 0.1, 0.0, 0.0, 0.2, 0.5;
  const G::Element g0 = G::exp(start_twist);

  std::vector<G::Element> poses;
  std::vector<double> seconds;
  for (int i = 0; i < 100; ++i) {
    const double t = 0.03 * i;  // 100 samples over 3 s
    G::Tangent jitter;
    for (int k = 0; k < 6; ++k)
      jitter[k] = noise(rng);
    poses.push_back(G::compose(G::compose(g0, G::exp(t * velocity)), G::exp(jitter)));
    seconds.push_back(t);
  }

  const bireg::GeodesicRegression<G> regression;
  const auto result = regression.fit(poses, seconds);
  if (!result.ok()) {
    std::printf("fit failed: %s %s\n", bireg::to_string(result.status), result.message.c_str());
    return 1;
  }
  const auto print = [](const char* name, const G::Element& g) {
    std::printf("%s =\n", name);
    for (int r = 0; r < 4; ++r)
      std::printf("  % .6f % .6f % .6f % .6f\n", g(r, 0), g(r, 1), g(r, 2), g(r, 3));
  };
  print("fitted pose at t = 0 s", result.geodesic->start());
  print("fitted pose at t = 2.97 s", result.geodesic->end());
  const G::Tangent v = result.geodesic->body_velocity();
  std::printf("body velocity  (% .4f % .4f % .4f | % .4f % .4f % .4f) per s\n", v[0], v[1], v[2],
              v[3], v[4], v[5]);
  std::printf("true velocity  (% .4f % .4f % .4f | % .4f % .4f % .4f) per s\n", velocity[0],
              velocity[1], velocity[2], velocity[3], velocity[4], velocity[5]);
  std::printf("status %s after %d iterations, residual RMS %.4f (about the mean %.4f), R^2 %.4f\n",
              bireg::to_string(result.status), result.iterations, result.diagnostics.residual_rms,
              result.diagnostics.residual_rms_about_mean, result.diagnostics.explained_variance);
  return 0;
}
