// bireg_fit, run as a user would: both formats, every error path with its
// exit code and one-line message, the JSON read back and compared with the
// library's own fit, order independence, and --output-trajectory.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;

struct Run {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

fs::path work_dir() {
  const fs::path dir = fs::path(BIREG_TEST_WORK_DIR);
  fs::create_directories(dir);
  return dir;
}

std::string data(const std::string& name) {
  return std::string(BIREG_TEST_DATA_DIR) + "/" + name;
}

Run run_tool(const std::string& arguments) {
  // ctest runs test cases in parallel processes: one pair of files each.
  const std::string tag = std::to_string(static_cast<long>(getpid()));
  const fs::path out = work_dir() / ("stdout_" + tag + ".txt");
  const fs::path err = work_dir() / ("stderr_" + tag + ".txt");
  const std::string command = std::string("\"") + BIREG_FIT_EXECUTABLE + "\" " + arguments +
                              " > \"" + out.string() + "\" 2> \"" + err.string() + "\"";
  const int status = std::system(command.c_str());
  Run run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = slurp(out);
  run.err = slurp(err);
  return run;
}

// The numbers of the JSON value after "key": (a number or nested arrays),
// in order. Enough for the flat object bireg_fit prints.
std::vector<double> json_numbers(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  REQUIRE(at != std::string::npos);
  std::size_t i = at + key.size() + 3;
  std::vector<double> numbers;
  int depth = 0;
  do {
    while (json[i] == ' ' || json[i] == ',' || json[i] == '\n')
      ++i;
    if (json[i] == '[') {
      ++depth;
      ++i;
    } else if (json[i] == ']') {
      --depth;
      ++i;
    } else {
      char* end = nullptr;
      numbers.push_back(std::strtod(json.c_str() + i, &end));
      REQUIRE(end != json.c_str() + i);
      i = static_cast<std::size_t>(end - json.c_str());
    }
  } while (depth > 0);
  return numbers;
}

std::string json_string(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\": \"");
  REQUIRE(at != std::string::npos);
  const std::size_t start = at + key.size() + 5;
  return json.substr(start, json.find('"', start) - start);
}

template <class G>
typename G::Element element_of(const std::vector<double>& numbers) {
  typename G::Element g;
  const int n = static_cast<int>(g.rows());
  REQUIRE(numbers.size() == static_cast<std::size_t>(n * n));
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c)
      g(r, c) = numbers[r * n + c];
  }
  return g;
}

template <class G>
bireg::io::Trajectory<G> read_file(const std::string& path, bireg::io::Format format) {
  std::ifstream in(path);
  bireg::io::Trajectory<G> trajectory;
  REQUIRE_FALSE(bireg::io::read_trajectory<G>(in, format, trajectory).has_value());
  return trajectory;
}

// The tool's JSON against the library's fit of the same file. Both run the
// same computation; only code generation (FMA contraction) may differ
// between the two binaries, which stays at rounding level amplified by the
// iteration's condition: 1e-12 relative.
template <class G>
void check_against_library(const std::string& file, bireg::io::Format format,
                           const std::string& args) {
  const Run run = run_tool(args + " \"" + data(file) + "\"");
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.err.empty());
  REQUIRE(json_string(run.out, "status") == "converged");
  REQUIRE(json_string(run.out, "group") == G::name);
  REQUIRE(run.out.find("nan") == std::string::npos);

  const auto trajectory = read_file<G>(data(file), format);
  const auto result =
      bireg::GeodesicRegression<G>().fit(trajectory.observations, trajectory.covariates);
  REQUIRE(result.ok());
  REQUIRE(bireg_test::relative_error(element_of<G>(json_numbers(run.out, "g0")),
                                     result.geodesic.start()) <= 1e-12);
  REQUIRE(bireg_test::relative_error(element_of<G>(json_numbers(run.out, "g1")),
                                     result.geodesic.end()) <= 1e-12);
  REQUIRE(json_numbers(run.out, "t_min").at(0) == result.geodesic.t_min());
  REQUIRE(json_numbers(run.out, "t_max").at(0) == result.geodesic.t_max());
  REQUIRE(json_numbers(run.out, "iterations").at(0) == result.iterations);
  REQUIRE(std::abs(json_numbers(run.out, "residual_rms").at(0) - result.diagnostics.residual_rms) <=
          1e-12 * result.diagnostics.residual_rms);
}

}  // namespace

TEST_CASE("bireg_fit reads both formats and agrees with the library", "[tool]") {
  using bireg::io::Format;
  check_against_library<bireg::SO3<double>>("so3_small.csv", Format::matrix, "--group SO3");
  check_against_library<bireg::SE3<double>>("se3_small.tum", Format::tum,
                                            "--group SE3 --format tum");
  check_against_library<bireg::SO3<double>>("se3_small.tum", Format::tum,
                                            "--group SO3 --format tum");
  check_against_library<bireg::SE2<double>>("se2_small.csv", Format::matrix, "--group SE2");
  check_against_library<bireg::SO2<double>>("so2_small.csv", Format::matrix, "--group SO2");
  check_against_library<bireg::Sim3<double>>("sim3_small.csv", Format::matrix, "--group Sim3");
  check_against_library<bireg::SL3<double>>("sl3_small.csv", Format::matrix, "--group SL3");
  check_against_library<bireg::GLp<3, double>>("glp3_small.csv", Format::matrix, "--group GLp3");
}

TEST_CASE("bireg_fit reads standard input", "[tool]") {
  const Run run = run_tool("--group SO3 - < \"" + data("so3_small.csv") + "\"");
  REQUIRE(run.exit_code == 0);
  REQUIRE(json_string(run.out, "status") == "converged");
}

// A permutation of the observations changes only the order of the sums,
// i.e. rounding: run to tolerance 1e-14 (so that the returned endpoints are
// that close to the fixed point), the endpoints agree to 1e-12.
TEST_CASE("bireg_fit does not depend on the order of the lines", "[tool]") {
  const Run sorted = run_tool("--group SO3 --tol 1e-14 \"" + data("so3_small.csv") + "\"");
  const Run shuffled =
      run_tool("--group SO3 --tol 1e-14 \"" + data("so3_small_shuffled.csv") + "\"");
  REQUIRE(sorted.exit_code == 0);
  REQUIRE(shuffled.exit_code == 0);
  const auto g0 = json_numbers(sorted.out, "g0"), g0s = json_numbers(shuffled.out, "g0");
  const auto g1 = json_numbers(sorted.out, "g1"), g1s = json_numbers(shuffled.out, "g1");
  for (std::size_t i = 0; i < g0.size(); ++i) {
    REQUIRE(std::abs(g0[i] - g0s[i]) <= 1e-12);
    REQUIRE(std::abs(g1[i] - g1s[i]) <= 1e-12);
  }
}

TEST_CASE("bireg_fit reports every input error on one line with exit code 2", "[tool]") {
  struct Case {
    std::string args, file, expected;
  };
  const std::vector<Case> cases = {
      {"--group SO3", "truncated.csv", "truncated.csv:3: expected 10 numbers, found 9"},
      {"--group SO3", "text_in_number.csv", "text_in_number.csv:2: not a number: 'abc'"},
      {"--group SO3", "not_in_group.csv", "not_in_group.csv:2: matrix is not an element of SO3"},
      {"--group SO3", "empty.csv", "empty.csv: no observations"},
      {"--group SO3", "one_observation.csv",
       "one_observation.csv: need at least 2 observations, got 1"},
      {"--group SO3", "equal_covariates.csv", "equal_covariates.csv: all covariates are equal"},
      {"--group SO3", "nan.csv", "nan.csv:2: not a finite number: 'nan'"},
      {"--group SO3", "huge.csv", "huge.csv:3: number out of range: '1e400'"},
      {"--group SE3 --format tum", "bad_quaternion.tum",
       "bad_quaternion.tum:2: quaternion norm 0.5 is far from 1"},
      {"--group SE3 --format tum", "wrong_columns.tum", "wrong_columns.tum:2: expected 8 numbers"},
      {"--group SE2 --format tum", "se3_small.tum",
       "the tum format holds SE3 or SO3 poses, not SE2"},
      {"--group SO3", "no_such_file.csv", "no_such_file.csv: cannot open file"},
      {"--group SO4", "so3_small.csv", "unknown group 'SO4'"},
      {"--group SO3 --tol -1", "so3_small.csv", "--tol needs a non-negative number"},
      {"--group SO3 --solver paper --step 100", "so3_small.csv", "no longer contracts"},
      {"--group SO3 --step 0.01", "so3_small.csv", "step_size applies to the paper solver only"},
      {"--group SO3 --method series", "so3_small.csv", "--method series needs --order M"},
      {"--group SO3 --method series --order 0", "so3_small.csv", "--order needs an integer"},
      {"--group SO3 --order 8", "so3_small.csv", "--order applies to --method series only"},
      {"--group SO3 --method taylor", "so3_small.csv", "unknown method 'taylor'"},
      {"--group SO3 --solver newton", "so3_small.csv", "unknown solver 'newton'"},
      {"--group Sim3", "sim3_not_in_group.csv",
       "sim3_not_in_group.csv:3: matrix is not an element of Sim3"},
      {"--group SL3", "sl3_not_in_group.csv",
       "sl3_not_in_group.csv:4: matrix is not an element of SL3"},
      {"--group GLp3", "glp3_not_in_group.csv",
       "glp3_not_in_group.csv:2: matrix is not an element of GLp"},
      {"--group Sim3", "so3_small.csv", "so3_small.csv:3: expected 17 numbers, found 10"},
      {"--group SL3 --format tum", "se3_small.tum",
       "the tum format holds SE3 or SO3 poses, not SL3"},
      {"--group SL3", "sl3_no_logarithm.csv",
       "sl3_no_logarithm.csv:5: observation 4 is out of reach of the middle observation"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args, c.file);
    const Run run = run_tool(c.args + " \"" + data(c.file) + "\"");
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    REQUIRE(run.err.find(c.expected) != std::string::npos);
    REQUIRE(run.err.rfind("bireg_fit: ", 0) == 0);
  }
}

TEST_CASE("bireg_fit exits with 3 and still prints the JSON when the fit does not converge",
          "[tool]") {
  const Run run =
      run_tool("--group SO3 --solver paper --max-iter 2 \"" + data("so3_small.csv") + "\"");
  REQUIRE(run.exit_code == 3);
  REQUIRE(json_string(run.out, "status") == "max_iterations");
  REQUIRE(json_numbers(run.out, "iterations").at(0) == 2);
  REQUIRE(run.out.find("nan") == std::string::npos);
}

TEST_CASE("bireg_fit --output-trajectory writes the fitted geodesic in the input's format",
          "[tool]") {
  using G = bireg::SE3<double>;
  const std::string out =
      (work_dir() / ("fitted_" + std::to_string(static_cast<long>(getpid())) + ".tum")).string();
  const Run run = run_tool("--group SE3 --format tum --output-trajectory \"" + out + "\" \"" +
                           data("se3_small.tum") + "\"");
  REQUIRE(run.exit_code == 0);
  const auto input = read_file<G>(data("se3_small.tum"), bireg::io::Format::tum);
  const auto fitted = read_file<G>(out, bireg::io::Format::tum);
  REQUIRE(fitted.covariates == input.covariates);
  const G::Element g0 = element_of<G>(json_numbers(run.out, "g0"));
  const G::Element g1 = element_of<G>(json_numbers(run.out, "g1"));
  const bireg::Geodesic<G> geodesic(g0, g1, input.covariates.front(), input.covariates.back());
  // 17 significant digits round-trip a double, and a quaternion converts to a
  // rotation and back within a few ulps: 1e-14.
  for (std::size_t i = 0; i < fitted.observations.size(); ++i) {
    REQUIRE(bireg_test::relative_error(fitted.observations[i], geodesic(input.covariates[i])) <=
            1e-14);
  }
}
