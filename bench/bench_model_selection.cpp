// Cost of bireg::select_motion_model against one SE(3) fit of the same data:
// 60 poses of a screw motion with 0.01 noise. The ratio of the two timings
// is the selection's cost in SE(3) fits (5 candidates x (1 + 5 folds) fits,
// most of them on the cheaper SO(3) and Rn<3>). The same scene as
// similarities (scale 1.3, log-scale drifting by 0.4) times the Sim(3)
// selection: 6 candidates x (1 + 5 folds), the sixth a Sim(3) fit.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/selection/model_selection.hpp"

namespace {

struct Scene {
  std::vector<Eigen::Matrix4d> poses;
  std::vector<double> times;
};

Scene screw_scene() {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 0.01);
  bireg::SE3d::Tangent xi;
  xi << 0.5, 0.2, -0.3, 0.4, -0.6, 1.0;
  Scene scene;
  for (int i = 0; i < 60; ++i) {
    const double t = i / 59.0;
    bireg::SE3d::Tangent noise;
    for (int j = 0; j < 6; ++j)
      noise[j] = normal(rng);
    scene.poses.push_back(bireg::SE3d::compose(bireg::SE3d::exp(t * xi), bireg::SE3d::exp(noise)));
    scene.times.push_back(t);
  }
  return scene;
}

Scene drifting_scene() {
  Scene scene = screw_scene();
  for (std::size_t i = 0; i < scene.poses.size(); ++i)
    scene.poses[i].topLeftCorner<3, 3>() *= 1.3 * std::exp(0.4 * scene.times[i]);
  return scene;
}

void se3_fit(benchmark::State& state) {
  const Scene scene = screw_scene();
  const bireg::GeodesicRegression<bireg::SE3d> regression;
  for (auto _ : state)
    benchmark::DoNotOptimize(regression.fit(scene.poses, scene.times));
}

void model_selection(benchmark::State& state) {
  const Scene scene = screw_scene();
  for (auto _ : state)
    benchmark::DoNotOptimize(bireg::select_motion_model(scene.poses, scene.times));
}

void sim3_fit(benchmark::State& state) {
  const Scene scene = drifting_scene();
  const bireg::GeodesicRegression<bireg::Sim3d> regression;
  for (auto _ : state)
    benchmark::DoNotOptimize(regression.fit(scene.poses, scene.times));
}

void sim3_model_selection(benchmark::State& state) {
  const Scene scene = drifting_scene();
  bireg::ModelSelectionOptions options;
  options.group = bireg::PoseGroup::sim3;
  for (auto _ : state)
    benchmark::DoNotOptimize(bireg::select_motion_model(scene.poses, scene.times, options));
}

}  // namespace

BENCHMARK(se3_fit)->Unit(benchmark::kMicrosecond);
BENCHMARK(model_selection)->Unit(benchmark::kMicrosecond);
BENCHMARK(sim3_fit)->Unit(benchmark::kMicrosecond);
BENCHMARK(sim3_model_selection)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
