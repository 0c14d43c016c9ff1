// libFuzzer target: the trajectory parser and fit() on whatever it accepts.
//
// The first byte of the input selects the group (bits 0, 1, 4: SO2, SO3,
// SE2, SE3, Sim3, SL3, GLp3, Heisenberg), the format (bit 2) and the solver
// (bit 3); the rest is the file's text. Properties checked (abort = finding):
//   * the parser never crashes and either reports an error with a line
//     number inside the text or returns observations in the group;
//   * fit() on parsed input never crashes, never returns NaN or infinity
//     in its endpoints or diagnostics, and reports invalid input only with
//     a message.
//
// Build and run (clang):
//   cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DBIREG_BUILD_FUZZERS=ON
//   cmake --build build-fuzz --target fuzz_fit
//   ./build-fuzz/tests/fuzz_fit -max_total_time=60 tests/fuzz/corpus
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"

namespace {

void require(bool condition) {
  if (!condition) std::abort();
}

template <class G>
void exercise(const std::string& text, bireg::io::Format format, bireg::Solver solver) {
  std::istringstream in(text);
  bireg::io::Trajectory<G> trajectory;
  const auto error = bireg::io::read_trajectory<G>(in, format, trajectory);
  if (error) {
    require(!error->message.empty());
    require(error->line >= 0);
    return;
  }
  for (const auto& g : trajectory.observations)
    require(G::is_element(g, 1e-6));
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.max_iterations = 50;
  const auto result =
      bireg::GeodesicRegression<G>(options).fit(trajectory.observations, trajectory.covariates);
  if (result.status == bireg::Status::invalid_input) {
    require(!result.message.empty());
    return;
  }
  require(result.geodesic.start().allFinite() && result.geodesic.end().allFinite());
  const auto& d = result.diagnostics;
  for (double x : {d.mu_min, d.mu_max, d.step_size, d.contraction_factor, d.force_norm,
                   d.residual_rms, d.residual_rms_about_mean, d.explained_variance}) {
    require(std::isfinite(x));
  }
  for (const auto& r : result.residuals)
    require(r.allFinite());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t selector = data[0];
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  const auto format = (selector & 4) ? bireg::io::Format::tum : bireg::io::Format::matrix;
  const auto solver = (selector & 8) ? bireg::Solver::paper : bireg::Solver::gauss_newton;
  switch ((selector & 3) | ((selector >> 2) & 4)) {  // bits 0, 1 and 4
    case 0:
      exercise<bireg::SO2<double>>(text, format, solver);
      break;
    case 1:
      exercise<bireg::SO3<double>>(text, format, solver);
      break;
    case 2:
      exercise<bireg::SE2<double>>(text, format, solver);
      break;
    case 3:
      exercise<bireg::SE3<double>>(text, format, solver);
      break;
    case 4:
      exercise<bireg::Sim3<double>>(text, format, solver);
      break;
    case 5:
      exercise<bireg::SL3<double>>(text, format, solver);
      break;
    case 6:
      exercise<bireg::GLp<3, double>>(text, format, solver);
      break;
    default:
      exercise<bireg::Heisenberg<double>>(text, format, solver);
      break;
  }
  return 0;
}
