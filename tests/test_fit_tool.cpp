// bireg_fit, run as a user would: both formats, every error path with its
// exit code and one-line message, the JSON read back and compared with the
// library's own fit, order independence, and --output-trajectory.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
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
#include "bireg/io/writers.hpp"
#include "bireg/regression.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
#include "bireg/statistics/smoothing/spline_roughness.hpp"
#include "bireg/version.hpp"
#include "catch.hpp"
#include "test_support.hpp"
#include "tool_runner.hpp"

namespace {

namespace fs = std::filesystem;
using bireg_test::data;
using bireg_test::json_numbers;
using bireg_test::json_string;
using bireg_test::Run;
using bireg_test::slurp;
using bireg_test::work_dir;

bool json_has_non_finite(const std::string& json);

Run run_tool(const std::string& arguments) {
  return bireg_test::run_executable(BIREG_FIT_EXECUTABLE, arguments);
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
  REQUIRE_FALSE(json_has_non_finite(run.out));

  const auto trajectory = read_file<G>(data(file), format);
  const auto result =
      bireg::GeodesicRegression<G>().fit(trajectory.observations, trajectory.covariates);
  REQUIRE(result.ok());
  REQUIRE(bireg_test::relative_error(element_of<G>(json_numbers(run.out, "g0")),
                                     result.geodesic->start()) <= 1e-12);
  REQUIRE(bireg_test::relative_error(element_of<G>(json_numbers(run.out, "g1")),
                                     result.geodesic->end()) <= 1e-12);
  // t_min and t_max are the earliest and latest timestamps, written exactly;
  // the fit's covariates count from the earliest.
  REQUIRE(json_numbers(run.out, "t_min").at(0) == trajectory.origin.seconds);
  REQUIRE(json_numbers(run.out, "t_max").at(0) == trajectory.last.seconds);
  REQUIRE(result.geodesic->t_min() == 0);
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
      {"--group SO3", "extra_columns.csv", "extra_columns.csv:3: expected 10 numbers, found 11"},
      {"--group SE3 --format tum", "extra_columns.tum",
       "extra_columns.tum:2: expected 8 numbers (timestamp tx ty tz qx qy qz qw), found 9"},
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
      {"--group Sim3", "so3_small.csv", "so3_small.csv:3: no format fits this line (10 numbers"},
      {"--group Sim3 --format tum --output-trajectory never.tum", "se3_small.tum",
       "the tum format holds SE3 or SO3 poses, not Sim3 (the input's format; use --output-format "
       "matrix)"},
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

// Issue 36, defect 6: an option given twice was accepted and the last one
// silently won (--group SO3 --group SE3 fitted SE3). Refused, naming it;
// the library's long spellings are the same option as the short ones.
TEST_CASE("bireg_fit refuses an option given more than once, naming it", "[tool]") {
  struct Case {
    std::string args, named;
  };
  const std::vector<Case> cases = {
      {"--group SO3 --group SE3", "--group"},
      {"--group SO3 --group SO3", "--group"},
      {"--group SO3 --tol 1e-8 --tolerance 1e-9", "--tol"},
      {"--group SO3 --max-iter 5 --max-iter 50", "--max-iter"},
      {"--group SO3 --format matrix --format matrix", "--format"},
      {"--group SO3 --project --project", "--project"},
      {"--group SO3 --method exact --method series --order 4", "--method"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Run run = run_tool(c.args + " " + "\"" + data("so3_small.csv") + "\"");
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    REQUIRE(run.err.rfind("bireg_fit: ", 0) == 0);
    const std::string first_line = run.err.substr(0, run.err.find('\n'));
    REQUIRE(first_line.find(c.named) != std::string::npos);
    REQUIRE(first_line.find("more than once") != std::string::npos);
  }
  // Once each is fine.
  const Run once = run_tool(std::string("--group SO3 --tol 1e-8 --max-iter 50 --format matrix ") +
                            "\"" + data("so3_small.csv") + "\"");
  REQUIRE(once.exit_code == 0);
}

// Issue 36: --help and --version, as users of command-line tools expect.
TEST_CASE("bireg_fit --help lists every option with its default, and the exit codes", "[tool]") {
  for (const std::string args : {"--help", "-h", "--group SO3 --help"}) {
    CAPTURE(args);
    const Run run = run_tool(args);
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(run.err.empty());
    REQUIRE(run.out.rfind("usage: bireg_fit", 0) == 0);
    // Every option the tool takes, on one line of its own that says what it
    // does and its default (or that it is required).
    const std::vector<std::string> options = {"--group",         "--format",
                                              "--times",         "--project",
                                              "--method",        "--order",
                                              "--solver",        "--step",
                                              "--tol",           "--max-iter",
                                              "--loss",          "--loss-scale",
                                              "--confidence",    "--permutations",
                                              "--seed",          "--output-band",
                                              "--model",         "--degree",
                                              "--knot-spacing",  "--roughness-penalty",
                                              "--cv-table",      "--output-trajectory",
                                              "--output-format", "--threads",
                                              "--help",          "--version"};
    std::map<std::string, std::string> line_of;
    std::istringstream lines(run.out);
    for (std::string line; std::getline(lines, line);) {
      const std::size_t start = line.find_first_not_of(' ');
      if (start == 0 || start == std::string::npos || line.compare(start, 2, "--") != 0) continue;
      const std::string option = line.substr(start, line.find_first_of(" ,", start) - start);
      REQUIRE(line_of.count(option) == 0);
      line_of[option] = line;
    }
    for (const std::string& option : options) {
      CAPTURE(option);
      REQUIRE(line_of.count(option) == 1);
      const std::string& line = line_of[option];
      if (option != "--help" && option != "--version") {
        REQUIRE((line.find("(default") != std::string::npos ||
                 line.find("(required") != std::string::npos));
      }
      // A meaning, not just the option's name and value.
      REQUIRE(line.size() > option.size() + 30);
    }
    REQUIRE(line_of.size() == options.size());
    // The defaults stated are those the fit uses: the library's.
    const bireg::RegressionOptions<double> library;
    const auto default_in = [&](const std::string& option) {
      const std::string& line = line_of[option];
      const std::size_t at = line.find("(default ");
      REQUIRE(at != std::string::npos);
      const std::size_t start = at + 9;
      return line.substr(start, line.find(')', start) - start);
    };
    REQUIRE(std::strtod(default_in("--tol").c_str(), nullptr) == library.tolerance);
    REQUIRE(std::strtod(default_in("--max-iter").c_str(), nullptr) == library.max_iterations);
    REQUIRE(default_in("--method") == bireg::to_string(library.method));
    REQUIRE(default_in("--solver") == bireg::to_string(library.solver));
    // The exit codes, each on its own line.
    REQUIRE(run.out.find("Exit codes") != std::string::npos);
    for (const char* code : {"\n  0 ", "\n  2 ", "\n  3 ", "\n  4 ", "\n  5 "}) {
      CAPTURE(code);
      REQUIRE(run.out.find(code) != std::string::npos);
    }
  }
}

TEST_CASE("bireg_fit --version prints the library's version", "[tool]") {
  for (const std::string args : {"--version", "--group SO3 --version"}) {
    CAPTURE(args);
    const Run run = run_tool(args);
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(run.err.empty());
    REQUIRE(run.out == std::string("bireg_fit ") + bireg::version + "\n");
  }
}

TEST_CASE("bireg_fit exits with 3 and still prints the JSON when the fit does not converge",
          "[tool]") {
  const Run run =
      run_tool("--group SO3 --solver paper --max-iter 2 \"" + data("so3_small.csv") + "\"");
  REQUIRE(run.exit_code == 3);
  REQUIRE(json_string(run.out, "status") == "max_iterations");
  REQUIRE(json_numbers(run.out, "iterations").at(0) == 2);
  REQUIRE_FALSE(json_has_non_finite(run.out));
  // Exit 3 is explained on stderr: one line naming the file and the status.
  CAPTURE(run.err);
  REQUIRE(run.err.rfind("bireg_fit: ", 0) == 0);
  REQUIRE(run.err.find("so3_small.csv") != std::string::npos);
  REQUIRE(run.err.find("max_iterations") != std::string::npos);
  REQUIRE(std::count(run.err.begin(), run.err.end(), '\n') == 1);
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

TEST_CASE("bireg_fit --model spline prints the library's spline: control points and knots",
          "[tool][spline]") {
  using G = bireg::SE3<double>;
  // A curved SE(3) path (not a geodesic) over 4 s at 50 Hz with noise of
  // 0.01 per coordinate, in the matrix format.
  std::mt19937 rng(21);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<G::Element> poses;
  std::vector<bireg::io::Timestamp> times;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.02 * i;
    G::Tangent x;
    x << std::sin(t), 0.5 * t, 0.2 * t * t, 0.3 * t, 0.4 * std::sin(1.5 * t), 0.1 * t * t;
    G::Tangent e;
    for (int k = 0; k < 6; ++k)
      e[k] = noise(rng);
    poses.push_back(G::compose(G::exp(x), G::exp(e)));
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", 1700000000.0 + t);
    times.emplace_back();
    REQUIRE_FALSE(bireg::io::parse_timestamp(text, bireg::io::TimeUnit::seconds, times.back()));
  }
  const fs::path input = work_dir() / ("spline_" + std::to_string(getpid()) + ".csv");
  {
    std::ofstream(input) << bireg::io::format_trajectory<G>(
        bireg::io::Format::matrix, bireg::io::Format::matrix, times, poses);
  }
  const auto trajectory = read_file<G>(input.string(), bireg::io::Format::matrix);
  const fs::path fitted = work_dir() / ("spline_fitted_" + std::to_string(getpid()) + ".csv");

  const Run run = run_tool("--group SE3 --model spline --knot-spacing 0.5 --output-trajectory \"" +
                           fitted.string() + "\" \"" + input.string() + "\"");
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.err.empty());
  REQUIRE_FALSE(json_has_non_finite(run.out));
  REQUIRE(json_string(run.out, "model") == "spline");
  REQUIRE(json_string(run.out, "status") == "converged");
  REQUIRE(json_string(run.out, "knot_spacing_source") == "given");

  bireg::SplineOptions<double> options;
  options.knot_spacing = 0.5;
  const auto library =
      bireg::SplineRegression<G>(options).fit(trajectory.observations, trajectory.covariates);
  REQUIRE(library.ok());
  const bireg::Spline<G>& spline = *library.spline;
  REQUIRE(json_numbers(run.out, "degree").at(0) == 3);
  REQUIRE(json_numbers(run.out, "knot_spacing").at(0) == spline.knot_spacing());
  REQUIRE(json_numbers(run.out, "iterations").at(0) == library.iterations);
  // Knots in seconds after t_min: the first at 0, one per segment boundary.
  const std::vector<double> knots = json_numbers(run.out, "knots");
  REQUIRE(knots.size() == spline.segments() + 1);
  REQUIRE(knots.front() == spline.t_min());
  REQUIRE(knots.back() == Approx(spline.t_max()).margin(1e-12));
  // The same computation in two binaries (see check_against_library): 1e-12.
  const std::vector<double> points = json_numbers(run.out, "control_points");
  REQUIRE(points.size() == 16 * spline.control_points().size());
  for (std::size_t j = 0; j < spline.control_points().size(); ++j) {
    const std::vector<double> entries(points.begin() + 16 * j, points.begin() + 16 * (j + 1));
    REQUIRE(bireg_test::relative_error(element_of<G>(entries), spline.control_points()[j]) <=
            1e-12);
  }
  // --output-trajectory: the spline at every input time.
  const auto written = read_file<G>(fitted.string(), bireg::io::Format::matrix);
  REQUIRE(written.covariates == trajectory.covariates);
  for (std::size_t i = 0; i < written.observations.size(); ++i) {
    REQUIRE(bireg_test::relative_error(written.observations[i], spline(trajectory.covariates[i])) <=
            1e-12);
  }

  // auto: the cross-validation's choice, said on stderr and kept in the JSON.
  const Run automatic = run_tool("--group SE3 --model spline \"" + input.string() + "\"");
  CAPTURE(automatic.err);
  REQUIRE(automatic.exit_code == 0);
  REQUIRE(automatic.err.find("bireg_fit: knot spacing auto: ") == 0);
  REQUIRE(json_string(automatic.out, "knot_spacing_source") == "auto");
  const auto grid = bireg::auto_knot_spacing_grid(trajectory.covariates);
  const auto selection =
      bireg::select_knot_spacing<G>(trajectory.observations, trajectory.covariates, {}, grid);
  REQUIRE(selection.ok());
  REQUIRE(json_numbers(automatic.out, "chosen").at(0) == selection.knot_spacing);
  REQUIRE(automatic.out.find("\"candidates\": [") != std::string::npos);
  REQUIRE_FALSE(json_has_non_finite(automatic.out));
  REQUIRE(json_numbers(automatic.out, "roughness_penalty").at(0) == 0);
  REQUIRE(json_string(automatic.out, "roughness_penalty_source") == "given");

  // --roughness-penalty auto: fine knots, lambda by the library's
  // cross-validation, the fit the library's with both.
  const Run penalised =
      run_tool("--group SE3 --model spline --roughness-penalty auto \"" + input.string() + "\"");
  CAPTURE(penalised.err);
  REQUIRE(penalised.exit_code == 0);
  REQUIRE(json_string(penalised.out, "knot_spacing_source") == "fine");
  REQUIRE(json_string(penalised.out, "roughness_penalty_source") == "auto");
  REQUIRE(penalised.out.find("\"roughness_selection\": {\"chosen\": ") != std::string::npos);
  REQUIRE(penalised.out.find("\"knot_selection\"") == std::string::npos);
  REQUIRE_FALSE(json_has_non_finite(penalised.out));
  bireg::SplineOptions<double> fine;
  fine.knot_spacing = bireg::fine_knot_spacing(trajectory.covariates);
  const auto roughness = bireg::select_roughness_penalty<G>(
      trajectory.observations, trajectory.covariates, fine,
      bireg::auto_roughness_penalty_grid(trajectory.covariates, double(fine.knot_spacing)));
  REQUIRE(roughness.ok());
  REQUIRE(json_numbers(penalised.out, "roughness_penalty").at(0) == roughness.roughness_penalty);
  fine.roughness_penalty = roughness.roughness_penalty;
  const auto smooth =
      bireg::SplineRegression<G>(fine).fit(trajectory.observations, trajectory.covariates);
  REQUIRE(smooth.ok());
  const std::vector<double> smooth_points = json_numbers(penalised.out, "control_points");
  REQUIRE(smooth_points.size() == 16 * smooth.spline->control_points().size());
  for (std::size_t j = 0; j < smooth.spline->control_points().size(); ++j) {
    const std::vector<double> entries(smooth_points.begin() + 16 * j,
                                      smooth_points.begin() + 16 * (j + 1));
    REQUIRE(bireg_test::relative_error(element_of<G>(entries),
                                       smooth.spline->control_points()[j]) <= 1e-12);
  }

  // Each model's options are refused with the other, and the groups without
  // a spline are named.
  const std::string file = " \"" + input.string() + "\"";
  const std::vector<std::pair<std::string, std::string>> refusals = {
      {"--group SE3 --model spline --loss huber", "--loss applies to --model geodesic only"},
      {"--group SE3 --model spline --confidence 0.9",
       "--confidence applies to --model geodesic only"},
      {"--group SE3 --degree 2", "--degree applies to --model spline only"},
      {"--group SE3 --knot-spacing 1", "--knot-spacing applies to --model spline only"},
      {"--group SE3 --roughness-penalty 1", "--roughness-penalty applies to --model spline only"},
      {"--group SE3 --model spline --roughness-penalty -2",
       "--roughness-penalty needs a number >= 0 or auto, got '-2'"},
      {"--group SE3 --model spline --degree 1 --roughness-penalty auto",
       "--roughness-penalty needs --degree 2 or 3"},
      {"--group SE3 --model spline --degree 1 --roughness-penalty 0.5",
       "--roughness-penalty needs --degree 2 or 3"},
      {"--group SE3 --model spline --knot-spacing 0", "--knot-spacing needs a positive number"},
      {"--group SE3 --model spline --degree 4", "--degree needs 1, 2 or 3"},
      {"--group SE3 --model cubic", "unknown model 'cubic' (geodesic or spline)"},
      {"--group SE3 --model spline --method series", "--method applies to --model geodesic only"},
      {"--group SE3 --model spline --seed 1", "--seed applies to --model geodesic only"},
      {"--group SE3 --model spline --knot-spacing 1 --cv-table t.csv",
       "--cv-table goes with --knot-spacing auto or --roughness-penalty auto"},
      {"--group Sim3 --model spline", "--model spline fits SO2, SO3, SE2 and SE3, not Sim3"},
      {"--group Foo --model spline", "unknown group 'Foo' (--model spline fits SO2, SO3, SE2 or"},
      {"--group auto --model spline", "--group auto chooses among geodesic motion models"}};
  for (const auto& [args, message] : refusals) {
    const Run refused = run_tool(args + file);
    CAPTURE(args, refused.err);
    REQUIRE(refused.exit_code == 2);
    REQUIRE(refused.out.empty());
    REQUIRE(refused.err.find("bireg_fit: " + message) == 0);
  }

  // --max-iter reaches the spline: one step is not enough, the JSON is
  // still printed with that status, and exit code 3 says why.
  const Run stopped = run_tool("--group SE3 --model spline --knot-spacing 0.5 --max-iter 1" + file);
  CAPTURE(stopped.err);
  REQUIRE(stopped.exit_code == 3);
  REQUIRE(json_string(stopped.out, "status") == "max_iterations");
  REQUIRE(json_numbers(stopped.out, "iterations").at(0) == 1);
  REQUIRE(stopped.err.find("the iteration limit (--max-iter) was reached first; exit code 3") !=
          std::string::npos);
  REQUIRE_FALSE(json_has_non_finite(stopped.out));

  // Too few observations to cross-validate: refused, naming the remedy, and
  // the --cv-table file says for every spacing why it was not tried.
  std::string few;
  for (int i = 0; i < 5; ++i) {
    few += std::to_string(i) + " 0." + std::to_string(i) + " 0 0 0 0 0 1\n";
  }
  const fs::path table = work_dir() / ("spline_cv_" + std::to_string(getpid()) + ".csv");
  const fs::path few_file = work_dir() / ("spline_few_" + std::to_string(getpid()) + ".tum");
  std::ofstream(few_file) << few;
  const Run too_few = run_tool("--group SE3 --model spline --cv-table \"" + table.string() +
                               "\" \"" + few_file.string() + "\"");
  CAPTURE(too_few.err);
  REQUIRE(too_few.exit_code == 2);
  REQUIRE(too_few.err.find("knot spacing auto: knot spacing selection needs") != std::string::npos);
  REQUIRE(too_few.err.find("give --knot-spacing S") != std::string::npos);
  const std::string table_text = slurp(table);
  REQUIRE(table_text.rfind("knot_spacing,criterion,failures,refused\n", 0) == 0);
  std::istringstream rows(table_text);
  std::string row;
  std::getline(rows, row);  // the header
  int refused_rows = 0;
  for (; std::getline(rows, row); ++refused_rows) {
    CAPTURE(row);
    REQUIRE(row.find(",,0,\"not tried: knot spacing selection needs") != std::string::npos);
  }
  REQUIRE(refused_rows > 0);
}

// ---- the io/ layer through the tool: formats, timestamps, hostile input ----

namespace {

// True when the JSON holds a non-finite number however it is spelled: null,
// nan, inf, infinity (any case, any sign, outside strings) or a number too
// large for a double (1e999).
bool json_has_non_finite(const std::string& json) {
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') ++i;
      if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(c))) {
      std::size_t end = i;
      std::string word;
      while (end < json.size() && std::isalpha(static_cast<unsigned char>(json[end])))
        word += static_cast<char>(std::tolower(static_cast<unsigned char>(json[end++])));
      if (word == "null" || word == "nan" || word == "inf" || word == "infinity") return true;
      i = end - 1;
    } else if (c == '-' || c == '+' || c == '.' || (c >= '0' && c <= '9')) {
      char* end = nullptr;
      const double x = std::strtod(json.c_str() + i, &end);
      if (end == json.c_str() + i) continue;
      if (!std::isfinite(x)) return true;
      i = static_cast<std::size_t>(end - json.c_str()) - 1;
    }
  }
  return false;
}

std::string scratch(const std::string& name) {
  return (work_dir() / (std::to_string(static_cast<long>(getpid())) + "_" + name)).string();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  REQUIRE(out.good());
}

std::string quoted(const std::string& path) {
  return "\"" + path + "\"";
}

std::string g17(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// One trajectory: poses near a geodesic, timestamps 1.7e9 s + 0.01 i with
// microsecond digits, written by hand (not by the io writers) in the four
// formats.
struct Sample {
  std::vector<bireg::SE3<double>::Element> poses;
  std::vector<std::string> seconds, nanoseconds;
};

Sample make_sample(int n) {
  using G = bireg::SE3<double>;
  std::mt19937 rng(11);
  Sample s;
  Eigen::Matrix<double, 6, 1> a, b;
  a << 0.1, -0.2, 0.3, 1.0, 0.5, -0.25;
  b << 0.6, 0.3, -0.2, 2.0, -1.0, 0.75;
  for (int i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / (n - 1);
    const Eigen::Matrix<double, 6, 1> noise =
        bireg_test::random_tangent<Eigen::Matrix<double, 6, 1>>(rng, 0.02);
    s.poses.push_back(G::exp((1 - u) * a + u * b) * G::exp(noise));
    const long micro = 10000L * i + (137L * i) % 1000;  // 0.01 i s plus microseconds
    char seconds[40];
    std::snprintf(seconds, sizeof seconds, "1700000000.%06ld", micro);
    s.seconds.push_back(seconds);
    s.nanoseconds.push_back("1700000000" + std::string(seconds + 11) + "000");
  }
  return s;
}

Eigen::Vector4d quaternion_wxyz(const Eigen::Matrix3d& r) {
  const Eigen::Quaterniond q = bireg::SO3<double>::to_quaternion(r);
  return {q.w(), q.x(), q.y(), q.z()};
}

std::string write_sample(const Sample& s, bireg::io::Format format) {
  std::string text;
  if (format == bireg::io::Format::euroc) text = "#timestamp [ns],x,y,z,qw,qx,qy,qz\n";
  for (std::size_t i = 0; i < s.poses.size(); ++i) {
    const auto& g = s.poses[i];
    const Eigen::Vector4d q = quaternion_wxyz(g.topLeftCorner<3, 3>());
    switch (format) {
      case bireg::io::Format::matrix:
        text += s.seconds[i];
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c)
            text += ", " + g17(g(r, c));
        break;
      case bireg::io::Format::tum:
        text += s.seconds[i] + " " + g17(g(0, 3)) + " " + g17(g(1, 3)) + " " + g17(g(2, 3)) + " " +
                g17(q[1]) + " " + g17(q[2]) + " " + g17(q[3]) + " " + g17(q[0]);
        break;
      case bireg::io::Format::euroc:
        text += s.nanoseconds[i] + "," + g17(g(0, 3)) + "," + g17(g(1, 3)) + "," + g17(g(2, 3)) +
                "," + g17(q[0]) + "," + g17(q[1]) + "," + g17(q[2]) + "," + g17(q[3]) +
                ",0.1,0.2,0.3";
        break;
      case bireg::io::Format::kitti:
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 4; ++c)
            text += (r + c ? " " : "") + g17(g(r, c));
        break;
    }
    text += "\n";
  }
  return text;
}

std::string times_file(const Sample& s) {
  std::string text;
  for (const auto& t : s.seconds)
    text += t + "\n";
  return text;
}

// Splits like Python's str.split(delimiter) (as evo's csv reader does).
std::vector<std::string> split_exact(const std::string& line, char delimiter) {
  std::vector<std::string> fields(1);
  for (char c : line) {
    if (c == delimiter) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// A trajectory file read with evo's documented column conventions: '#' lines
// skipped, TUM 8 space-separated fields (quaternion x y z w), KITTI 12
// space-separated fields (3x4 row-major), EuRoC 17 comma-separated fields
// (nanoseconds, position, quaternion w x y z). No trailing delimiters.
struct EvoTrajectory {
  std::vector<std::string> stamps;
  std::vector<bireg::SE3<double>::Element> poses;
};

EvoTrajectory read_like_evo(const std::string& path, bireg::io::Format format) {
  std::ifstream in(path);
  std::string line;
  EvoTrajectory out;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) continue;
    const char delimiter = format == bireg::io::Format::euroc ? ',' : ' ';
    const auto f = split_exact(line, delimiter);
    const std::size_t expected = format == bireg::io::Format::tum     ? 8
                                 : format == bireg::io::Format::kitti ? 12
                                                                      : 17;
    REQUIRE(f.size() == expected);
    std::vector<double> x;
    for (const auto& field : f) {
      std::size_t used = 0;
      x.push_back(std::stod(field, &used));
      REQUIRE(used == field.size());
    }
    bireg::SE3<double>::Element g = bireg::SE3<double>::Element::Identity();
    if (format == bireg::io::Format::kitti) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
          g(r, c) = x[static_cast<std::size_t>(4 * r + c)];
    } else {
      const bool tum = format == bireg::io::Format::tum;
      const double w = tum ? x[7] : x[4], qx = tum ? x[4] : x[5], qy = tum ? x[5] : x[6],
                   qz = tum ? x[6] : x[7];
      g.topLeftCorner<3, 3>() = bireg::io::rotation_of_quaternion(w, qx, qy, qz);
      g.topRightCorner<3, 1>() = Eigen::Vector3d(x[1], x[2], x[3]);
      out.stamps.push_back(f[0]);
    }
    out.poses.push_back(g);
  }
  return out;
}

}  // namespace

TEST_CASE("the non-finite check catches every spelling", "[tool]") {
  REQUIRE_FALSE(
      json_has_non_finite("{\"a\": [1, -2.5e-3, 0], \"status\": \"null nan inf\", \"b\": 1e308}"));
  for (const char* bad : {"{\"a\": null}", "{\"a\": nan}", "{\"a\": NaN}", "{\"a\": -inf}",
                          "{\"a\": Infinity}", "{\"a\": [1, -INF]}", "{\"a\": 1e999}"}) {
    CAPTURE(bad);
    REQUIRE(json_has_non_finite(bad));
  }
}

TEST_CASE("bireg_fit: the same trajectory in all four formats gives the same fit", "[tool]") {
  using bireg::io::Format;
  const Sample sample = make_sample(40);
  const std::string times = scratch("times.txt");
  write_text(times, times_file(sample));
  std::vector<std::vector<double>> g0s, g1s;
  for (Format format : {Format::matrix, Format::tum, Format::euroc, Format::kitti}) {
    CAPTURE(bireg::io::to_string(format));
    const std::string file = scratch(std::string("four.") + bireg::io::to_string(format));
    write_text(file, write_sample(sample, format));
    const std::string times_arg = format == Format::kitti ? " --times " + quoted(times) : "";
    for (const std::string& format_arg :
         {std::string(), std::string(" --format ") + bireg::io::to_string(format)}) {
      const Run run =
          run_tool("--group SE3 --tol 1e-14" + format_arg + times_arg + " " + quoted(file));
      CAPTURE(format_arg, run.err);
      REQUIRE(run.exit_code == 0);
      REQUIRE(json_string(run.out, "format") == bireg::io::to_string(format));
      REQUIRE_FALSE(json_has_non_finite(run.out));
      REQUIRE(json_numbers(run.out, "n").at(0) == 40);
      // Exactly the first and the last timestamp, in seconds.
      REQUIRE(run.out.find("\"t_min\": 1700000000,") != std::string::npos);
      REQUIRE(run.out.find("\"t_max\": 1700000000.390343,") != std::string::npos);
      g0s.push_back(json_numbers(run.out, "g0"));
      g1s.push_back(json_numbers(run.out, "g1"));
    }
  }
  for (std::size_t k = 1; k < g0s.size(); ++k) {
    for (std::size_t i = 0; i < 16; ++i) {
      REQUIRE(std::abs(g0s[k][i] - g0s[0][i]) <= 1e-12);
      REQUIRE(std::abs(g1s[k][i] - g1s[0][i]) <= 1e-12);
    }
  }
}

TEST_CASE("bireg_fit: nanosecond timestamps at 1.7e18 keep every digit", "[tool]") {
  using G = bireg::SE3<double>;
  std::string text = "#timestamp [ns],x,y,z,qw,qx,qy,qz\n";
  for (int i = 0; i < 5; ++i) {
    text += std::to_string(1700000000000000000LL + i) + "," + std::to_string(0.5 * i) +
            ",0,0,1,0,0,0\n";
  }
  const std::string file = scratch("ns.csv"), out = scratch("ns_fitted.csv");
  write_text(file, text);
  const Run run = run_tool("--group SE3 --output-trajectory " + quoted(out) + " " + quoted(file));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.out.find("\"t_max\": 1700000000.000000004,") != std::string::npos);
  // Five distinct covariates 1e-9 s apart: translation 0.5 per ns exactly.
  const G::Element g1 = element_of<G>(json_numbers(run.out, "g1"));
  REQUIRE(std::abs(g1(0, 3) - 2.0) <= 1e-9);
  REQUIRE(std::abs(json_numbers(run.out, "residual_rms").at(0)) <= 1e-9);
  const EvoTrajectory fitted = read_like_evo(out, bireg::io::Format::euroc);
  REQUIRE(fitted.stamps.size() == 5);
  for (int i = 0; i < 5; ++i) {
    REQUIRE(fitted.stamps[static_cast<std::size_t>(i)] ==
            std::to_string(1700000000000000000LL + i));
    REQUIRE(std::abs(fitted.poses[static_cast<std::size_t>(i)](0, 3) - 0.5 * i) <= 1e-9);
  }
}

TEST_CASE("bireg_fit: output in every format follows evo's conventions, timestamps exact",
          "[tool]") {
  using bireg::io::Format;
  using G = bireg::SE3<double>;
  const Sample sample = make_sample(12);
  const std::string input = scratch("evo_in.tum");
  write_text(input, write_sample(sample, Format::tum));
  for (Format format : {Format::tum, Format::euroc, Format::kitti, Format::matrix}) {
    CAPTURE(bireg::io::to_string(format));
    const std::string out = scratch(std::string("evo_out.") + bireg::io::to_string(format));
    const Run run =
        run_tool("--group SE3 --output-trajectory " + quoted(out) + " --output-format " +
                 bireg::io::to_string(format) + " " + quoted(input));
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 0);
    const G::Element g0 = element_of<G>(json_numbers(run.out, "g0"));
    const G::Element g1 = element_of<G>(json_numbers(run.out, "g1"));
    const double span = 0.110507;  // 1700000000.110507 - 1700000000
    const bireg::Geodesic<G> geodesic(g0, g1, 0.0, span);
    if (format == Format::matrix) {
      // Read back with the library's reader instead (evo has no matrix format).
      const auto back = read_file<G>(out, Format::matrix);
      REQUIRE(back.timestamps.size() == 12);
      for (std::size_t i = 0; i < 12; ++i)
        REQUIRE(back.timestamps[i].text == sample.seconds[i]);
      continue;
    }
    const EvoTrajectory fitted = read_like_evo(out, format);
    REQUIRE(fitted.poses.size() == 12);
    const auto input_trajectory = read_file<G>(input, Format::tum);
    for (std::size_t i = 0; i < 12; ++i) {
      REQUIRE(bireg_test::relative_error(fitted.poses[i],
                                         geodesic(input_trajectory.covariates[i])) <= 1e-12);
      if (format == Format::tum) REQUIRE(fitted.stamps[i] == sample.seconds[i]);
      if (format == Format::euroc) REQUIRE(fitted.stamps[i] == sample.nanoseconds[i]);
    }
  }
}

TEST_CASE("bireg_fit: hostile input in every new format, one line naming file and line", "[tool]") {
  struct Case {
    std::string name, args, text, expected;
  };
  const std::string tum_ok = "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n";
  const std::string euroc_head = "#timestamp [ns],x,y,z,qw,qx,qy,qz\n";
  const std::string euroc_ok = "0,0,0,0,1,0,0,0\n1000000000,1,0,0,1,0,0,0\n";
  const std::string kitti_ok = "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
  const std::string hostile = "\x1b[31m" + std::string(5000, 'x');
  const std::vector<Case> cases = {
      // tum
      {"t_truncated.tum", "--format tum", tum_ok + "2 1 0 0 0 0 0\n", ":3: expected 8 numbers"},
      {"t_text.tum", "--format tum", tum_ok + "2 1 0 abc 0 0 0 1\n", ":3: not a number: 'abc'"},
      {"t_nan.tum", "--format tum", tum_ok + "2 nan 0 0 0 0 0 1\n", ":3: not a finite number"},
      {"t_huge.tum", "--format tum", "1e400 0 0 0 0 0 0 1\n" + tum_ok,
       ":1: number out of range: '1e400'"},
      {"t_extra.tum", "--format tum", tum_ok + "2 1 0 0 0 0 0 1 7\n",
       ":3: expected 8 numbers (timestamp tx ty tz qx qy qz qw), found 9"},
      {"t_empty.tum", "--format tum", "# nothing\n", "t_empty.tum: no observations"},
      {"t_one.tum", "--format tum", "0 0 0 0 0 0 0 1\n", "need at least 2 observations, got 1"},
      {"t_equal.tum", "--format tum", "5 0 0 0 0 0 0 1\n5.0 1 0 0 0 0 0 1\n",
       "t_equal.tum: all covariates are equal"},
      {"t_escape.tum", "--format tum", "0 0 0 " + hostile + " 0 0 0 1\n",
       ":1: not a number: '\\x1b[31mxxx"},
      // euroc
      {"e_truncated.csv", "--format euroc", euroc_head + euroc_ok + "2000000000,1,0,0,1,0,0\n",
       ":4: expected at least 8 numbers"},
      {"e_text.csv", "--format euroc", euroc_head + euroc_ok + "2000000000,1,0,0,1,0,zero,0\n",
       ":4: not a number: 'zero'"},
      {"e_nan.csv", "--format euroc", euroc_head + "0,0,0,0,NaN,0,0,0\n" + euroc_ok,
       ":2: not a finite number: 'NaN'"},
      {"e_huge.csv", "--format euroc", euroc_head + euroc_ok + "2000000000,1e400,0,0,1,0,0,0\n",
       ":4: number out of range: '1e400'"},
      {"e_empty.csv", "--format euroc", euroc_head, "e_empty.csv: no observations"},
      {"e_one.csv", "--format euroc", euroc_head + "0,0,0,0,1,0,0,0\n",
       "need at least 2 observations, got 1"},
      {"e_equal.csv", "--format euroc", euroc_head + "7,0,0,0,1,0,0,0\n7,1,0,0,1,0,0,0\n",
       "e_equal.csv: all covariates are equal"},
      {"e_quaternion.csv", "--format euroc", euroc_head + euroc_ok + "3,0,0,0,0.5,0,0,0\n",
       ":4: quaternion norm 0.5 is far from 1"},
      // kitti
      {"k_truncated.txt", "--format kitti", kitti_ok + "1 0 0 1 0 1 0 0 0 0 1\n",
       ":3: expected 12 numbers (a 3x4 pose, row-major), found 11"},
      {"k_extra.txt", "--format kitti", kitti_ok + "1 0 0 1 0 1 0 0 0 0 1 0 1\n",
       ":3: expected 12 numbers (a 3x4 pose, row-major), found 13"},
      {"k_text.txt", "--format kitti", kitti_ok + "1 0 0 1 0 1 0 0 0 0 1 O\n",
       ":3: not a number: 'O'"},
      {"k_nan.txt", "--format kitti", kitti_ok + "1 0 0 1 0 1 0 0 0 0 1 -nan\n",
       ":3: not a finite number: '-nan'"},
      {"k_huge.txt", "--format kitti", kitti_ok + "1 0 0 1e400 0 1 0 0 0 0 1 0\n",
       ":3: number out of range: '1e400'"},
      {"k_empty.txt", "--format kitti", "\n\n", "k_empty.txt: no observations"},
      {"k_one.txt", "--format kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n",
       "need at least 2 observations, got 1"},
      {"k_rotation.txt", "--format kitti", kitti_ok + "1 0 0 1 0 2 0 0 0 0 1 0\n",
       ":3: matrix is not an element of SE3"},
      // matrix and tum column counts: extra columns are errors
      {"m_extra.csv", "--format matrix",
       "0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0\n",
       ":2: expected 10 numbers, found 11"},
      {"m_extra_detected.csv", "",
       "0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0\n",
       ":2: expected 10 numbers, found 11"},
      // detection
      {"d_ambiguous.csv", "", "#timestamp\n0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n",
       ":2: ambiguous format: the line reads as matrix or euroc"},
      {"d_none.txt", "", "0 1 2 3 4\n", ":1: no format fits this line"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const std::string file = scratch(c.name);
    write_text(file, c.text);
    const std::string group = c.name[0] == 'm' || c.name[0] == 'd' ? "SO3" : "SE3";
    const Run run = run_tool("--group " + group + " " + c.args + " " + quoted(file));
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    REQUIRE(run.err.rfind("bireg_fit: " + file, 0) == 0);
    REQUIRE(run.err.find(c.expected) != std::string::npos);
    // One line, bounded, printable.
    REQUIRE(run.err.find('\n') == run.err.size() - 1);
    REQUIRE(run.err.size() < 400);
    for (std::size_t i = 0; i + 1 < run.err.size(); ++i)
      REQUIRE((run.err[i] >= 0x20 && run.err[i] < 0x7f));
  }

  // KITTI times: equal times, and a count that does not match the poses.
  const std::string poses = scratch("k_poses.txt"), times = scratch("k_times.txt");
  write_text(poses, kitti_ok);
  write_text(times, "0.5\n0.5\n");
  Run run = run_tool("--group SE3 --format kitti --times " + quoted(times) + " " + quoted(poses));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find("all covariates are equal") != std::string::npos);
  write_text(times, "0\n1\n2\n");
  run = run_tool("--group SE3 --times " + quoted(times) + " " + quoted(poses));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find("3 times for 2 poses") != std::string::npos);
  write_text(times, "0\nx\n");
  run = run_tool("--group SE3 --times " + quoted(times) + " " + quoted(poses));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find(times + ":2: not a number: 'x'") != std::string::npos);
}

TEST_CASE("bireg_fit: --project re-orthonormalises and reports the correction", "[tool]") {
  const std::string file = scratch("project.tum"), zero = scratch("project_zero.tum");
  write_text(file, "0 0 0 0 0 0 0 1.02\n1 1 0 0 0 0 0.1 0.995\n2 2 0 0 0 0 0.2 0.98\n");
  Run run = run_tool("--group SE3 " + quoted(file));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find(":1: quaternion norm 1.02 is far from 1") != std::string::npos);
  run = run_tool("--group SE3 --project " + quoted(file));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(std::abs(json_numbers(run.out, "projection_correction").at(0) - 0.02) < 1e-12);
  REQUIRE_FALSE(json_has_non_finite(run.out));
  // --group auto reads rotations through SE(3) and reports the same (12
  // poses: enough for every candidate).
  const std::string longer = scratch("project_auto.tum");
  std::string text = "0 0 0 0 0 0 0 1.02\n";
  for (int i = 1; i < 12; ++i)
    text += std::to_string(i) + " " + std::to_string(i) + " 0 0 0 0 0 1\n";
  write_text(longer, text);
  run = run_tool("--group auto --project " + quoted(longer));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.out.find("\"pose_group\": \"SE3\"") != std::string::npos);
  REQUIRE(std::abs(json_numbers(run.out, "projection_correction").at(0) - 0.02) < 1e-12);
  write_text(zero, "0 0 0 0 0 0 0 0\n1 1 0 0 0 0 0 1\n");
  run = run_tool("--group SE3 --project " + quoted(zero));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find(":1: quaternion norm 0") != std::string::npos);
}

TEST_CASE("bireg_fit: directories, binary input, long lines and write errors", "[tool]") {
  Run run = run_tool("--group SO3 " + quoted(work_dir().string()));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find("is a directory") != std::string::npos);

  // /dev/zero on standard input: refused at once, memory bounded by the
  // first block.
  run = run_tool("--group SO3 - < /dev/zero");
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find("<stdin>:1: binary input") != std::string::npos);

  const std::string long_line = scratch("long.csv");
  write_text(long_line, "0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n" + std::string(2 << 20, '1') + "\n");
  run = run_tool("--group SO3 " + quoted(long_line));
  REQUIRE(run.exit_code == 2);
  REQUIRE(run.err.find(":2: line longer than 1048576 bytes") != std::string::npos);
  REQUIRE(run.err.size() < 400);

  if (fs::exists("/dev/full")) {
    run = run_tool("--group SE3 --output-trajectory /dev/full \"" + data("se3_small.tum") + "\"");
    REQUIRE(run.exit_code == 4);
    REQUIRE(run.err.find("/dev/full: write error") != std::string::npos);
    const std::string command = std::string("\"") + BIREG_FIT_EXECUTABLE + "\" --group SE3 \"" +
                                data("se3_small.tum") + "\" > /dev/full 2> " +
                                quoted(scratch("full_err.txt"));
    const int status = std::system(command.c_str());
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 4);
    REQUIRE(slurp(scratch("full_err.txt")).find("<stdout>: write error") != std::string::npos);
  }
}

namespace {

// The JSON from the first occurrence of `key` on, so that json_numbers
// finds a key that several sections share ("homoscedastic") in the right one.
std::string section(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  REQUIRE(at != std::string::npos);
  return json.substr(at);
}

// Largest entry of |a - b| over the largest |b|.
template <class Matrix>
double relative_difference(const std::vector<double>& a, const Matrix& b) {
  REQUIRE(a.size() == static_cast<std::size_t>(b.size()));
  double largest = 0, difference = 0;
  for (int k = 0; k < b.size(); ++k) {
    // Row-major in the JSON, column-major in Eigen: symmetric matrices and
    // vectors only.
    largest = std::max(largest, std::abs(b(k)));
    difference = std::max(difference, std::abs(a[static_cast<std::size_t>(k)] - b(k)));
  }
  return difference / largest;
}

// The library's fit of the SE3 sample, with the tool's --tol 1e-14.
bireg::RegressionResult<bireg::SE3<double>> library_fit(
    const bireg::io::Trajectory<bireg::SE3<double>>& trajectory) {
  bireg::GeodesicRegression<bireg::SE3<double>>::Options options;
  options.tolerance = 1e-14;
  const auto fit = bireg::GeodesicRegression<bireg::SE3<double>>(options).fit(
      trajectory.observations, trajectory.covariates);
  REQUIRE(fit.ok());
  return fit;
}

}  // namespace

// The tool and the test compute the same quantities from endpoints that
// agree to 1e-12 (see check_against_library); the covariance is a smooth
// function of endpoints and residuals (size 0.02 here), so it moves by at
// most ~1e-12 / 0.02 = 5e-11 relative: 1e-9 leaves margin.
TEST_CASE("bireg_fit --confidence: covariance, standard errors and R^2 are the library's",
          "[tool][confidence]") {
  using G = bireg::SE3<double>;
  const Sample sample = make_sample(40);
  const std::string file = scratch("confidence.csv");
  write_text(file, write_sample(sample, bireg::io::Format::matrix));
  const Run run = run_tool("--group SE3 --tol 1e-14 --confidence 0.9 " + quoted(file));
  CAPTURE(run.err, run.out);
  REQUIRE(run.exit_code == 0);
  REQUIRE_FALSE(json_has_non_finite(run.out));
  const std::string confidence = section(run.out, "confidence");
  REQUIRE(json_numbers(confidence, "level").at(0) == 0.9);

  const auto trajectory = read_file<G>(file, bireg::io::Format::matrix);
  const auto fit = library_fit(trajectory);
  const auto plain = bireg::covariance(fit, trajectory.covariates);
  const auto robust =
      bireg::covariance(fit, trajectory.covariates, {}, bireg::CovarianceFlavour::robust);
  REQUIRE(plain.status == bireg::CovarianceStatus::defined);
  REQUIRE(robust.status == bireg::CovarianceStatus::defined);

  const std::string endpoints = section(confidence, "endpoint_covariance");
  REQUIRE(relative_difference(json_numbers(endpoints, "homoscedastic"), plain.endpoints) <= 1e-9);
  REQUIRE(relative_difference(json_numbers(endpoints, "heteroscedasticity_robust"),
                              robust.endpoints) <= 1e-9);
  // The two flavours differ (else the test could not tell them apart).
  REQUIRE((plain.endpoints - robust.endpoints).norm() > 1e-3 * plain.endpoints.norm());

  const std::string velocity_se = section(confidence, "velocity_standard_error");
  REQUIRE(relative_difference(json_numbers(velocity_se, "homoscedastic"),
                              bireg::standard_errors(bireg::velocity_covariance(plain))) <= 1e-9);
  REQUIRE(relative_difference(json_numbers(velocity_se, "heteroscedasticity_robust"),
                              bireg::standard_errors(bireg::velocity_covariance(robust))) <= 1e-9);
  // The velocity per second: the displacement over the 0.39 s the sample spans.
  const Eigen::Matrix<double, 6, 1> velocity =
      fit.geodesic->displacement() / (trajectory.covariates.back() - trajectory.covariates.front());
  REQUIRE(relative_difference(json_numbers(confidence, "velocity"), velocity) <= 1e-9);

  // Unit weights: nu = N - 2 (textbook), up to rounding of the weight sums.
  REQUIRE(std::abs(json_numbers(section(confidence, "degrees_of_freedom"), "homoscedastic").at(0) -
                   38) <= 1e-9);

  const auto mean = bireg::mean<G>(trajectory.observations);
  const auto explained = bireg::explained_variance(fit, mean);
  REQUIRE(explained.defined);
  const std::string variance = section(confidence, "explained_variance");
  REQUIRE(std::abs(json_numbers(variance, "r_squared").at(0) - explained.euclidean) <= 1e-9);
  REQUIRE(std::abs(json_numbers(variance, "wilks_lambda").at(0) - explained.wilks_lambda) <=
          1e-9 * explained.wilks_lambda);
}

TEST_CASE("bireg_fit --confidence: an undefined covariance is a message and exit code 5",
          "[tool][confidence]") {
  // N = 2: no degrees of freedom. N = 3 on a geodesic (rotations about x
  // by 0, a and 2a, cos a = 0.8, sin a = 0.6, cos 2a = 0.28, sin 2a = 0.96):
  // residuals at rounding level, which the covariance reports as vanishing.
  const std::string two = "0, 1,0,0, 0,1,0, 0,0,1\n1, 1,0,0, 0,0.8,-0.6, 0,0.6,0.8\n";
  const std::string three = two + "2, 1,0,0, 0,0.28,-0.96, 0,0.96,0.28\n";
  for (const std::string& text : {two, three}) {
    const std::string file = scratch("undefined.csv");
    write_text(file, text);
    const std::string band = scratch("undefined_band.csv");
    fs::remove(band);
    const Run run = run_tool("--group SO3 --confidence 0.95 --output-band " + quoted(band) + " " +
                             quoted(file));
    CAPTURE(text, run.out, run.err);
    REQUIRE(run.exit_code == 5);
    REQUIRE(json_string(run.out, "status") == "converged");
    REQUIRE(run.out.find("\"covariance_defined\": false") != std::string::npos);
    REQUIRE(json_string(run.out, "message").find("undefined") != std::string::npos);
    REQUIRE(run.out.find("\"endpoint_covariance\"") == std::string::npos);
    REQUIRE_FALSE(json_has_non_finite(run.out));
    REQUIRE_FALSE(fs::exists(band));
    REQUIRE(run.err.find("not written") != std::string::npos);
  }
}

TEST_CASE("bireg_fit --output-band: too few degrees of freedom for the quantile is exit code 5",
          "[tool][confidence]") {
  // Five SE(3) poses: the homoscedastic covariance is defined with
  // nu = N - 2 = 3 degrees of freedom, fewer than the 6 dimensions of the
  // pose, so the Hotelling quantile of the band does not exist. That is an
  // undefined statistic (5), not a write error (4): fuzz_bireg_fit found
  // the tool reporting it as one.
  std::istringstream source(slurp(data("se3_small.tum")));
  std::string text, line;
  for (int poses = 0; poses < 5 && std::getline(source, line);) {
    text += line + '\n';
    poses += line.rfind('#', 0) != 0;
  }
  const std::string file = scratch("five_poses.tum");
  write_text(file, text);
  const std::string band = scratch("five_poses_band.csv");
  fs::remove(band);
  const Run run =
      run_tool("--group SE3 --confidence 0.95 --output-band " + quoted(band) + " " + quoted(file));
  CAPTURE(run.out, run.err);
  REQUIRE(run.exit_code == 5);
  REQUIRE(json_string(run.out, "status") == "converged");
  REQUIRE(run.out.find("\"covariance_defined\": true") != std::string::npos);
  REQUIRE_FALSE(json_has_non_finite(run.out));
  REQUIRE_FALSE(fs::exists(band));
  REQUIRE(run.err.find("not written: too few degrees of freedom") != std::string::npos);
}

TEST_CASE("bireg_fit refuses bad --confidence, --permutations and --seed", "[tool][confidence]") {
  const std::string file = quoted(data("so3_small.csv"));
  for (const std::string& args :
       {std::string("--confidence 0"), std::string("--confidence 1"),
        std::string("--confidence -0.5"), std::string("--confidence 95"),
        std::string("--permutations 0"), std::string("--permutations -10"),
        std::string("--permutations 9.5"), std::string("--seed 3"),
        std::string("--permutations 9 --seed -1"), std::string("--threads 0"),
        std::string("--threads 2.5"), std::string("--threads 2000")}) {
    const Run run = run_tool("--group SO3 " + args + " " + file);
    CAPTURE(args, run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    const std::string option = args.substr(0, args.find(' '));
    REQUIRE(run.err.rfind("bireg_fit: ", 0) == 0);
    REQUIRE(run.err.find(args.find("--seed") != std::string::npos ? "--seed" : option) !=
            std::string::npos);
  }
}

// The p-value is (1 + k) / (B + 1) with k an integer count: the tool and the
// library, with the same seed, draw the same permutations, so k agrees
// exactly (a Lambda_b tied with Lambda to rounding would be needed to flip
// a comparison, which continuous data make improbable). The whole output
// is the same on 1 and 2 threads.
TEST_CASE("bireg_fit --permutations: the library's p-value, reproducible by seed",
          "[tool][trend]") {
  using G = bireg::SE3<double>;
  const Sample sample = make_sample(40);
  const std::string file = scratch("trend.csv");
  write_text(file, write_sample(sample, bireg::io::Format::matrix));
  const int b = 49;
  const Run first =
      run_tool("--group SE3 --tol 1e-14 --permutations 49 --seed 7 --threads 1 " + quoted(file));
  const Run second =
      run_tool("--group SE3 --tol 1e-14 --permutations 49 --seed 7 --threads 2 " + quoted(file));
  REQUIRE(second.out == first.out);
  CAPTURE(first.err, first.out);
  REQUIRE(first.exit_code == 0);
  REQUIRE(second.exit_code == 0);
  REQUIRE_FALSE(json_has_non_finite(first.out));
  const std::string test = section(first.out, "trend_test");
  const double p = json_numbers(test, "p_value").at(0);
  REQUIRE(p == json_numbers(section(second.out, "trend_test"), "p_value").at(0));
  REQUIRE(json_numbers(test, "permutations").at(0) == b);
  REQUIRE(json_numbers(test, "seed").at(0) == 7);

  const auto trajectory = read_file<G>(file, bireg::io::Format::matrix);
  bireg::GeodesicRegression<G>::Options options;
  options.tolerance = 1e-14;
  bireg::TrendTestOptions test_options;
  test_options.permutations = b;
  test_options.seed = 7;
  const auto expected =
      bireg::trend_test(bireg::GeodesicRegression<G>(options), trajectory.observations,
                        trajectory.covariates, {}, test_options);
  REQUIRE(expected.ok());
  REQUIRE(p == expected.p_value);
  REQUIRE(std::abs(json_numbers(test, "wilks_lambda").at(0) - expected.statistic) <=
          1e-9 * expected.statistic);
  // The sample moves ~2 (tangent units) against noise 0.02: no permutation
  // comes near, so p is the smallest possible value.
  REQUIRE(p == 1.0 / (b + 1));
}

TEST_CASE("bireg_fit --output-band: exact timestamps, the fitted poses, a band narrowest inside",
          "[tool][confidence]") {
  using G = bireg::SE3<double>;
  const Sample sample = make_sample(40);
  const std::string file = scratch("band_input.csv");
  write_text(file, write_sample(sample, bireg::io::Format::matrix));
  const std::string band = scratch("band.csv");
  const Run run =
      run_tool("--group SE3 --tol 1e-14 --output-band " + quoted(band) + " " + quoted(file));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  std::ifstream in(band);
  std::string header;
  REQUIRE(std::getline(in, header));
  REQUIRE(header.rfind("timestamp,m00,m01,", 0) == 0);
  REQUIRE(header.find(",half_width_trans_x,") != std::string::npos);
  REQUIRE(header.find(",half_width_rot_z_deg") != std::string::npos);

  const auto trajectory = read_file<G>(file, bireg::io::Format::matrix);
  const auto fit = library_fit(trajectory);
  const auto c = bireg::covariance(fit, trajectory.covariates);
  const double q = *bireg::pose_quantile(c, 0.95);
  std::vector<double> sizes;  // |half-widths| per row
  std::string line;
  for (std::size_t i = 0; std::getline(in, line); ++i) {
    REQUIRE(i < sample.poses.size());
    const auto fields = split_exact(line, ',');
    REQUIRE(fields.size() == 1 + 16 + 6);
    REQUIRE(fields[0] == sample.seconds[i]);
    const G::Element pose = (*fit.geodesic)(trajectory.covariates[i]);
    for (int k = 0; k < 16; ++k)
      REQUIRE(std::abs(std::stod(fields[1 + static_cast<std::size_t>(k)]) - pose(k / 4, k % 4)) <=
              1e-9);
    const Eigen::Matrix<double, 6, 1> widths =
        bireg::half_widths(bireg::pose_covariance(c, trajectory.covariates[i]), q);
    Eigen::Matrix<double, 6, 1> written;
    for (int k = 0; k < 6; ++k)
      written[k] = std::stod(fields[17 + static_cast<std::size_t>(k)]);
    // Rotation half-widths are written in degrees.
    written.tail<3>() *= 3.14159265358979323846 / 180;
    REQUIRE((written - widths).norm() <= 1e-9 * widths.norm());
    sizes.push_back(written.norm());
  }
  REQUIRE(sizes.size() == sample.poses.size());
  // The band of a line fitted to evenly spread covariates is narrowest near
  // their centre and widest at the ends (the OLS variance of the line's
  // value is quadratic in t with its minimum at the mean covariate).
  const double middle = sizes[sizes.size() / 2];
  REQUIRE(middle < sizes.front());
  REQUIRE(middle < sizes.back());
}

// Issue 15: one pose replaced by a gross error (rotated by pi/2, moved by
// 2 units) among 30 near an SE3 geodesic with noise 0.01. The plain fit is
// pulled by ~1/30 of the error (~0.05); Tukey's fit gives the outlier
// weight 0 and stays at the noise level (~0.01 / sqrt(30) per endpoint).
TEST_CASE("bireg_fit --loss names the planted outlier's line and fits closer to the truth",
          "[tool][robust]") {
  using G = bireg::SE3<double>;
  std::mt19937 rng(5);
  G::Tangent x;
  x << 1.0, -0.5, 0.3, 0.4, 0.2, -0.3;
  const G::Element g0 = G::exp((G::Tangent() << 0.2, 0.1, -0.3, 0.1, 0.5, 0.2).finished());
  const G::Element g1 = g0 * G::exp(x);
  const int n = 30, bad = 12;
  std::string text = "# a comment line, so that line numbers differ from indices\n";
  for (int i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / (n - 1);
    G::Element pose =
        g0 * G::exp(u * x) * G::exp(bireg_test::random_tangent<G::Tangent>(rng, 0.01));
    if (i == bad)
      pose = pose * G::exp((G::Tangent() << 2.0, 0, 0, 0, 1.5707963267948966, 0).finished());
    text += g17(u);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        text += ", " + g17(pose(r, c));
    text += "\n";
  }
  const std::string file = scratch("outlier.csv");
  write_text(file, text);
  const Run plain = run_tool("--group SE3 " + quoted(file));
  const Run robust = run_tool("--group SE3 --loss tukey " + quoted(file));
  CAPTURE(robust.err, robust.out);
  REQUIRE(plain.exit_code == 0);
  REQUIRE(robust.exit_code == 0);
  // Line 1 is the comment: observation i is on line i + 2.
  const std::vector<double> lines = json_numbers(robust.out, "outlier_lines");
  REQUIRE(lines == std::vector<double>{bad + 2});
  const auto distance = [](const std::vector<double>& json, const G::Element& truth) {
    return G::log(G::inverse(truth) * element_of<G>(json)).norm();
  };
  const double plain_error =
      distance(json_numbers(plain.out, "g0"), g0) + distance(json_numbers(plain.out, "g1"), g1);
  const double robust_error =
      distance(json_numbers(robust.out, "g0"), g0) + distance(json_numbers(robust.out, "g1"), g1);
  CAPTURE(plain_error, robust_error);
  REQUIRE(robust_error < plain_error / 2);
}

// Issue 36, defect 2: a robust fit whose plain fit converged but whose
// reweighting did not settle exits 3; the top-level "status" must then be
// the robust one (the one that decided the exit code), not the last
// weighted fit's "converged", and stderr must say why the exit is 3. Two
// robust failures the library documents (statistics/robust/regression.hpp): fewer
// observations than the robust fit in SE(3) needs (dof + 2 = 8), and planar
// motion fitted in SE(3), whose residuals have no z, rot_x or rot_y
// component, so their scatter is singular.
TEST_CASE("bireg_fit --loss: a robust fit that fails decides both the status and exit code 3",
          "[tool][robust]") {
  using G = bireg::SE3<double>;
  struct Case {
    std::string name, loss, expected;
    int n;
    bool planar;
  };
  const std::vector<Case> cases = {
      {"robust_seven.csv", "tukey", "too_few_good", 7, false},
      {"robust_planar.csv", "huber", "singular_scatter", 20, true},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    std::mt19937 rng(17);
    std::normal_distribution<double> normal(0.0, 0.01);
    std::string text;
    for (int i = 0; i < c.n; ++i) {
      const double u = static_cast<double>(i) / (c.n - 1);
      G::Tangent x;
      if (c.planar) {  // translation x, y and rotation about z only
        x << 1.0 * u + normal(rng), 0.5 * u + normal(rng), 0, 0, 0, 0.8 * u + normal(rng);
      } else {
        x << 1.0 * u + normal(rng), 0.5 * u + normal(rng), -0.2 * u + normal(rng),
            0.3 * u + normal(rng), -0.1 * u + normal(rng), 0.8 * u + normal(rng);
      }
      const G::Element pose = G::exp(x);
      text += g17(u);
      for (int r = 0; r < 4; ++r)
        for (int col = 0; col < 4; ++col)
          text += ", " + g17(pose(r, col));
      text += "\n";
    }
    const std::string file = scratch(c.name);
    write_text(file, text);
    // The plain fit of the same data converges: only the robust stage fails.
    const Run plain = run_tool("--group SE3 " + quoted(file));
    REQUIRE(plain.exit_code == 0);
    REQUIRE(json_string(plain.out, "status") == "converged");

    const Run run = run_tool("--group SE3 --loss " + c.loss + " " + quoted(file));
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 3);
    REQUIRE(json_string(section(run.out, "robust"), "status") == c.expected);
    REQUIRE(json_string(run.out, "status") == c.expected);
    REQUIRE_FALSE(json_has_non_finite(run.out));
    REQUIRE(run.err.rfind("bireg_fit: ", 0) == 0);
    REQUIRE(std::count(run.err.begin(), run.err.end(), '\n') == 1);
    REQUIRE(run.err.find(c.name) != std::string::npos);
    REQUIRE(run.err.find(c.expected) != std::string::npos);
  }
}

// Data turning far beyond pi (issue 19): among simulated recordings that
// turn 6 to 12 rad, the first whose fit converges (checked with the library,
// so the test does not rest on one lucky seed) must come out of the tool
// with "beyond_domain": true and a warning naming the farthest line.
TEST_CASE("bireg_fit reports a converged fit of data turning beyond pi", "[tool]") {
  using G = bireg::SO3<double>;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int attempt = 0; attempt < 50; ++attempt) {
    G::Tangent x = bireg::testing::draw_vector<G::Tangent>(rng, normal);
    x *= (6.0 + 6.0 * attempt / 50.0) / x.norm();
    std::vector<G::Element> f;
    std::vector<double> t;
    std::string text;
    for (int i = 0; i < 50; ++i) {
      const double s = i / 49.0;
      f.push_back(G::exp(G::Tangent(s * x)) *
                  G::exp(bireg_test::random_tangent<G::Tangent>(rng, 0.01)));
      t.push_back(s);
      text += g17(s);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          text += ", " + g17(f.back()(r, c));
      text += "\n";
    }
    const auto fit = bireg::GeodesicRegression<G>().fit(f, t);
    if (!fit.ok()) continue;
    REQUIRE(fit.diagnostics.beyond_domain);
    const std::string file = scratch("beyond_pi.csv");
    write_text(file, text);
    const Run run = run_tool("--group SO3 " + quoted(file));
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(run.out.find("\"beyond_domain\": true") != std::string::npos);
    const std::string line =
        std::to_string(fit.diagnostics.largest_residual_observation + 1);  // no comment lines
    REQUIRE(run.err.find("beyond_pi.csv:" + line + ": warning:") != std::string::npos);
    return;
  }
  FAIL("no recording turning beyond pi converged: the test exercised nothing");
}

// --group auto (issue 18): scenes simulated from one model each (N = 60,
// noise 0.01 rad and 0.01 m, motion over 10 noise levels, as in
// test_model_selection.cpp, where the selector recovers them in 198-200 of
// 200 replicates) must come back with that model recommended, the
// five-row table, and the recommended model's prediction written out.
namespace {
std::string tum_scene(bool rotates, bool translates, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i < 60; ++i) {
    const double t = 1.7e9 + 0.1 * i;
    const double u = i / 59.0;
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(rotates ? 1.2 * u : 0.0, axis).toRotationMatrix() *
        bireg::SO3<double>::exp(bireg::testing::draw_vector<Eigen::Vector3d>(rng, noise));
    const Eigen::Vector3d p = Eigen::Vector3d(1.0, 2.0, 0.5) +
                              (translates ? u : 0.0) * Eigen::Vector3d(3.0, -1.0, 0.2) +
                              bireg::testing::draw_vector<Eigen::Vector3d>(rng, noise);
    const Eigen::Quaterniond q(r);
    text += g17(t) + " " + g17(p.x()) + " " + g17(p.y()) + " " + g17(p.z()) + " " + g17(q.x()) +
            " " + g17(q.y()) + " " + g17(q.z()) + " " + g17(q.w()) + "\n";
  }
  return text;
}
}  // namespace

TEST_CASE("bireg_fit --group auto recommends the generating model and writes its fit",
          "[tool][model_selection]") {
  struct Scene {
    bool rotates, translates;
    const char* model;
  };
  for (const Scene scene :
       {Scene{true, false, "rotation_only"}, Scene{false, true, "translation_only"},
        Scene{false, false, "static"}}) {
    CAPTURE(scene.model);
    const std::string file = scratch(std::string("auto_") + scene.model + ".tum");
    write_text(file, tum_scene(scene.rotates, scene.translates, 3));
    const std::string out = scratch(std::string("auto_fit_") + scene.model + ".tum");
    const Run run =
        run_tool("--group auto --output-trajectory " + quoted(out) + " " + quoted(file));
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(json_string(run.out, "recommended") == scene.model);
    std::size_t rows = 0;
    for (std::size_t at = run.out.find("{\"model\": "); at != std::string::npos;
         at = run.out.find("{\"model\": ", at + 1))
      ++rows;
    REQUIRE(rows == 5);
    REQUIRE_FALSE(json_has_non_finite(run.out));
    // The written prediction: 60 poses at the input's timestamps; for a
    // scene that does not translate, every predicted position is the
    // fixed one to within the noise's mean (0.01 / sqrt(60) per axis, 5
    // sigma allowed).
    const auto fitted = read_file<bireg::SE3<double>>(out, bireg::io::Format::tum);
    REQUIRE(fitted.observations.size() == 60);
    if (!scene.translates) {
      for (const auto& pose : fitted.observations)
        REQUIRE((pose.topRightCorner<3, 1>() - Eigen::Vector3d(1.0, 2.0, 0.5)).norm() <=
                5 * 0.01 / std::sqrt(60.0) * std::sqrt(3.0));
    }
  }
  const std::string file = scratch("auto_static.tum");
  const Run refused = run_tool("--group auto --loss tukey " + quoted(file));
  REQUIRE(refused.exit_code == 2);
  REQUIRE(refused.err.find("--group auto takes") != std::string::npos);
}

// Similarities (matrix format, Sim3 elements): --group auto reads them in
// the same pass, compares the six Sim(3) candidates, and recommends the one
// that generated the scene: the screw with a log-scale drift of 0.4 (40
// noise levels), or a pure rotation at the constant scale 1.3. As in
// test_model_selection.cpp, noise 0.01 per Sim(3) tangent coordinate.
namespace {
std::string sim3_scene(bool scale_drifts, unsigned seed) {
  using S = bireg::Sim3<double>;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  S::Tangent xi;
  xi << 0.5, 0.2, -0.3, 0.4, -0.6, 1.0, 0.4;
  if (!scale_drifts) xi << 0, 0, 0, 0.4, -0.6, 1.0, 0;
  S::Tangent start;
  start << 1.0, -2.0, 0.5, 0.3, 0.1, -0.2, std::log(1.3);
  std::string text;
  for (int i = 0; i < 60; ++i) {
    const double u = i / 59.0;
    S::Tangent e;
    for (int j = 0; j < 7; ++j)
      e[j] = noise(rng);
    const Eigen::Matrix4d f = S::compose(S::exp(start), S::compose(S::exp(u * xi), S::exp(e)));
    text += g17(u);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c)
        text += ", " + g17(f(r, c));
    text += "\n";
  }
  return text;
}
}  // namespace

TEST_CASE("bireg_fit --group auto on similarities compares the Sim(3) candidates",
          "[tool][model_selection]") {
  for (const bool drifts : {true, false}) {
    CAPTURE(drifts);
    const std::string file = scratch(drifts ? "auto_sim3_drift.csv" : "auto_sim3_rotation.csv");
    write_text(file, sim3_scene(drifts, 11));
    const std::string out = scratch(drifts ? "auto_sim3_drift_fit.csv" : "auto_sim3_rot_fit.csv");
    const Run run =
        run_tool("--group auto --output-trajectory " + quoted(out) + " " + quoted(file));
    CAPTURE(run.out, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(json_string(run.out, "pose_group") == "Sim3");
    REQUIRE(json_string(run.out, "recommended") == (drifts ? "similarity" : "rotation_only"));
    std::size_t rows = 0;
    for (std::size_t at = run.out.find("{\"model\": "); at != std::string::npos;
         at = run.out.find("{\"model\": ", at + 1))
      ++rows;
    REQUIRE(rows == 6);
    REQUIRE_FALSE(json_has_non_finite(run.out));
    // The written prediction's scale at both ends: 1.3 and 1.3 e^0.4 (or
    // 1.3 throughout). The fitted log-scale at an end of a line through 60
    // points with noise 0.01 has sd 0.01 * sqrt(4/60) = 0.0026; 5 sd allowed.
    const auto fitted = read_file<bireg::Sim3<double>>(out, bireg::io::Format::matrix);
    REQUIRE(fitted.observations.size() == 60);
    const auto log_scale = [](const Eigen::Matrix4d& g) {
      return std::log(g.topLeftCorner<3, 3>().determinant()) / 3;
    };
    REQUIRE(std::abs(log_scale(fitted.observations.front()) - std::log(1.3)) <= 0.013);
    REQUIRE(std::abs(log_scale(fitted.observations.back()) -
                     (std::log(1.3) + (drifts ? 0.4 : 0.0))) <= 0.013);
  }
  // A similarity has no TUM spelling: refused before any fitting.
  const std::string file = scratch("auto_sim3_drift.csv");
  const Run refused = run_tool("--group auto --output-format tum --output-trajectory " +
                               quoted(scratch("never.tum")) + " " + quoted(file));
  REQUIRE(refused.exit_code == 2);
  REQUIRE(refused.err.find("not Sim3") != std::string::npos);
}
