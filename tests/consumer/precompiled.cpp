// Links the installed compiled part: the fit, the covariance and the mean
// on SE(3) are declarations here (BIREG_PRECOMPILED, set by linking
// bireg::bireg_precompiled) and their code comes from libbireg_precompiled.
// Exits non-zero unless a noise-free geodesic is recovered.
#include <cstdio>
#include <vector>

#include <bireg/groups/se3.hpp>
#include <bireg/regression.hpp>
#include <bireg/statistics/inference/covariance.hpp>
#include <bireg/statistics/inference/mean.hpp>

#ifndef BIREG_PRECOMPILED
#error "bireg::bireg_precompiled must define BIREG_PRECOMPILED for its consumers"
#endif

int main() {
  using G = bireg::SE3d;
  G::Tangent velocity;
  velocity << 0.3, -0.1, 0.2, 0.05, 0.4, -0.2;
  const G::Element start = G::exp(G::Tangent::Constant(0.1));
  std::vector<G::Element> poses;
  std::vector<double> times;
  for (int i = 0; i < 12; ++i) {
    times.push_back(0.5 * i);
    poses.push_back(start * G::exp(velocity * times.back()));
  }
  const auto fit = bireg::GeodesicRegression<G>().fit(poses, times);
  const double error = fit.ok() ? (fit.geodesic->body_velocity() - velocity).norm() : 1.0;
  const auto mean = bireg::mean<G>(poses);
  // Noise-free data: the covariance is refused with a message, never NaN.
  const auto c = bireg::covariance(fit, times);
  std::printf("consumer_precompiled: velocity error %.3g, mean %s, covariance %s\n", error,
              mean.ok() ? "ok" : "failed", c.defined() ? "defined" : c.message.c_str());
  return error < 1e-9 && mean.ok() ? 0 : 1;
}
