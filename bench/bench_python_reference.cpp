// The C++ side of bench/python_bench.py: the same work as the Python
// package on the same bytes, timed in C++, so that the script reports the
// Python overhead as a ratio measured in one run.
//
//   bench_python_reference fit FILE REPEATS     SE(3) fit of a matrix file
//   bench_python_reference explog FILE REPEATS  SE(3) exp then log of every
//                                               6-vector in FILE (raw float64),
//                                               into vectors allocated once, then
//                                               into new ones
//
// Prints the median wall time of REPEATS runs in seconds (after one warm run).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"

namespace {

using G = bireg::SE3d;

template <class Work>
double median_seconds(int repeats, Work&& work) {
  work();
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    times.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

int fit(const char* path, int repeats) {
  std::ifstream in(path);
  bireg::io::Trajectory<G> data;
  if (!in) {
    std::fprintf(stderr, "bench_python_reference: cannot open %s\n", path);
    return 2;
  }
  if (const auto error = bireg::io::read_trajectory<G>(in, bireg::io::Format::matrix, data)) {
    std::fprintf(stderr, "bench_python_reference: %s:%llu: %s\n", path,
                 static_cast<unsigned long long>(error->line), error->message.c_str());
    return 2;
  }
  const bireg::GeodesicRegression<G> regression;
  int iterations = 0;
  const double seconds = median_seconds(repeats, [&] {
    const auto result = regression.fit(data.observations, data.covariates);
    iterations = result.iterations;
  });
  std::printf("%.9g %d\n", seconds, iterations);
  return 0;
}

int explog(const char* path, int repeats) {
  std::FILE* file = std::fopen(path, "rb");
  if (!file) {
    std::fprintf(stderr, "bench_python_reference: cannot open %s\n", path);
    return 2;
  }
  std::vector<double> raw;
  double buffer[6];
  while (std::fread(buffer, sizeof(double), 6, file) == 6)
    raw.insert(raw.end(), buffer, buffer + 6);
  std::fclose(file);
  const std::size_t n = raw.size() / 6;
  if (n == 0) {
    std::fprintf(stderr, "bench_python_reference: %s holds no 6-vector\n", path);
    return 2;
  }
  std::vector<G::Element> elements(n);
  std::vector<G::Tangent> logs(n);
  const double exp_seconds = median_seconds(repeats, [&] {
    for (std::size_t i = 0; i < n; ++i)
      elements[i] = G::exp(Eigen::Map<const G::Tangent>(&raw[6 * i]));
  });
  const double log_seconds = median_seconds(repeats, [&] {
    for (std::size_t i = 0; i < n; ++i)
      logs[i] = G::log(elements[i]);
  });
  // The same into a vector allocated by each call, as numpy's result is
  // when out= is not given (Eigen leaves its entries uninitialised, as
  // numpy.empty does: the pages are first touched by the loop). The last
  // entry is kept so that the loop is not optimised away.
  double kept = 0;
  const double exp_new_seconds = median_seconds(repeats, [&] {
    std::vector<G::Element> fresh(n);
    for (std::size_t i = 0; i < n; ++i)
      fresh[i] = G::exp(Eigen::Map<const G::Tangent>(&raw[6 * i]));
    kept += fresh[n - 1](0, 3);
  });
  const double log_new_seconds = median_seconds(repeats, [&] {
    std::vector<G::Tangent> fresh(n);
    for (std::size_t i = 0; i < n; ++i)
      fresh[i] = G::log(elements[i]);
    kept += fresh[n - 1][0];
  });
  std::printf("%.9g %.9g %.9g %.9g\n", exp_seconds, log_seconds, exp_new_seconds, log_new_seconds);
  std::fprintf(stderr, "%g\n", kept);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: bench_python_reference fit|explog FILE REPEATS\n");
    return 2;
  }
  const std::string command = argv[1];
  const int repeats = std::max(1, std::atoi(argv[3]));
  if (command == "fit") return fit(argv[2], repeats);
  if (command == "explog") return explog(argv[2], repeats);
  std::fprintf(stderr, "bench_python_reference: unknown command %s\n", command.c_str());
  return 2;
}
