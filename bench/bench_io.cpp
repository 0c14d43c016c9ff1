// Parser throughput of the io/ layer (issue 16: at least 200 MB/s): one
// generated SE(3) trajectory per format, read from memory by
// bireg::io::read_trajectory (line reader, number parsing, group check,
// exact timestamps), reported as bytes per second.
//
//   ./build/bench/bench_io --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
//
// BIREG_BENCH_IO_LINES sets the number of lines (default 1e6).
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/io/writers.hpp"

namespace {

using G = bireg::SE3<double>;
using bireg::io::Format;

std::size_t lines() {
  const char* env = std::getenv("BIREG_BENCH_IO_LINES");
  return env ? static_cast<std::size_t>(std::strtoull(env, nullptr, 10)) : 1000000;
}

// Realistic text: random poses, all digits printed, dataset-like timestamps.
const std::string& text_of(Format format) {
  static std::string texts[4];
  std::string& text = texts[static_cast<int>(format)];
  if (!text.empty()) return text;
  std::mt19937 rng(1);
  std::normal_distribution<double> normal(0, 1);
  std::vector<G::Element> poses;
  std::vector<bireg::io::Timestamp> times;
  const std::size_t n = lines();
  for (std::size_t i = 0; i < n; ++i) {
    G::Tangent x;
    for (int k = 0; k < 6; ++k)
      x[k] = normal(rng);
    poses.push_back(G::exp(x));
    bireg::io::Timestamp t;
    const std::string stamp = format == Format::euroc
                                  ? std::to_string(1403636579758555392ULL + 5000000ULL * i)
                                  : std::to_string(1403636579.0 + 0.005 * static_cast<double>(i));
    bireg::io::parse_timestamp(stamp, bireg::io::time_unit(format), t);
    times.push_back(t);
  }
  text = bireg::io::format_trajectory<G>(format, format, times, poses);
  return text;
}

void read(benchmark::State& state, Format format) {
  const std::string& text = text_of(format);
  bireg::io::ReadOptions options;
  options.format = format;
  for (auto _ : state) {
    bireg::io::MemorySource source(text);
    bireg::io::Trajectory<G> trajectory;
    const auto error = bireg::io::read_trajectory<G>(source, options, trajectory);
    if (error) state.SkipWithError(error->message.c_str());
    benchmark::DoNotOptimize(trajectory.observations.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
  state.counters["lines"] = static_cast<double>(lines());
  state.counters["bytes_per_line"] = static_cast<double>(text.size()) / lines();
}

void write(benchmark::State& state, Format format) {
  const std::string& text = text_of(format);
  bireg::io::ReadOptions options;
  options.format = format;
  bireg::io::MemorySource source(text);
  bireg::io::Trajectory<G> trajectory;
  bireg::io::read_trajectory<G>(source, options, trajectory);
  for (auto _ : state) {
    std::string out = bireg::io::format_trajectory<G>(format, format, trajectory.timestamps,
                                                      trajectory.observations);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}

}  // namespace

BENCHMARK_CAPTURE(read, matrix, Format::matrix)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read, tum, Format::tum)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read, euroc, Format::euroc)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read, kitti, Format::kitti)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(write, tum, Format::tum)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
