// bireg_smooth, run as a user would: every hostile input class with exit 2
// and one line naming file:line, noise-free geodesics smoothed to their
// poses and velocity, --at and --rate timestamps, the --velocity CSV, and
// the write-error exit code. Lean on purpose: only the groups' headers, no
// regression templates (the library's behaviour is tested in
// test_local_regression.cpp).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/version.hpp"
#include "catch.hpp"
#include "tool_runner.hpp"

namespace {

namespace fs = std::filesystem;
using bireg_test::data;
using bireg_test::Run;
using bireg_test::slurp;
using bireg_test::work_dir;

// A file in the work directory holding `text`; its path, quoted.
std::string make_file(const std::string& name, const std::string& text) {
  const fs::path path = work_dir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return "\"" + path.string() + "\"";
}

Run run_tool(const std::string& arguments) {
  return bireg_test::run_executable(BIREG_SMOOTH_EXECUTABLE, arguments);
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, separator))
    parts.push_back(part);
  // getline drops a trailing empty field ("1,2," is three fields).
  if (!text.empty() && text.back() == separator && separator != '\n') parts.emplace_back();
  return parts;
}

// The lines of a matrix-format output: the timestamp text and the numbers.
struct Line {
  std::string time;
  std::vector<double> numbers;
  std::string status;  // the velocity CSV's last column: "ok" or "failed: ..."
};

std::vector<Line> parse_csv(const std::string& text) {
  std::vector<Line> lines;
  for (const std::string& row : split(text, '\n')) {
    if (row.empty()) continue;
    std::vector<std::string> fields = split(row, ',');
    Line line;
    line.time = fields[0];
    // The velocity CSV's status: "ok", or "failed: ..." (quoted when its
    // reason holds a comma, which then spans several fields).
    for (std::size_t k = 1; k < fields.size(); ++k) {
      if (fields[k] == "ok" || fields[k].rfind("failed", 0) == 0 ||
          fields[k].rfind("\"failed", 0) == 0) {
        for (std::size_t j = k; j < fields.size(); ++j)
          line.status += (j == k ? "" : ",") + fields[j];
        fields.resize(k);
        break;
      }
    }
    // An empty field (an undefined standard error) reads as NaN.
    for (std::size_t k = 1; k < fields.size(); ++k) {
      line.numbers.push_back(fields[k].empty() ? std::nan("")
                                               : std::strtod(fields[k].c_str(), nullptr));
    }
    lines.push_back(line);
  }
  return lines;
}

template <class G>
typename G::Element element_of(const std::vector<double>& numbers) {
  typename G::Element g;
  const int n = static_cast<int>(g.rows());
  REQUIRE(numbers.size() == static_cast<std::size_t>(n * n));
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c)
      g(r, c) = numbers[static_cast<std::size_t>(r * n + c)];
  }
  return g;
}

std::string number_text(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

// A noise-free geodesic g(t) = g0 exp((t - 100) X) at t = 100 + k / 10,
// k < n, in the matrix format, timestamps written as exact decimals.
template <class G>
struct GeodesicFile {
  typename G::Element g0;
  typename G::Tangent velocity;
  double origin = 100;
  std::string text;

  typename G::Element at(double seconds_after_origin) const {
    return g0 * G::exp(seconds_after_origin * velocity);
  }
};

// With noise > 0, each sample is the geodesic's times exp of N(0, noise^2)
// coordinates drawn from `rng` (at() stays the truth).
template <class G>
GeodesicFile<G> geodesic_file(const typename G::Tangent& start, const typename G::Tangent& velocity,
                              int n, double noise = 0, std::mt19937* rng = nullptr) {
  GeodesicFile<G> file;
  file.g0 = G::exp(start);
  file.velocity = velocity;
  // (A standard deviation of 0 is invalid: libstdc++'s assertions abort.)
  std::normal_distribution<double> normal(0.0, noise > 0 ? noise : 1.0);
  for (int k = 0; k < n; ++k) {
    typename G::Element g = file.at(k / 10.0);
    if (noise > 0) {
      typename G::Tangent e;
      for (int i = 0; i < G::dof; ++i)
        e[i] = normal(*rng);
      g = g * G::exp(e);
    }
    file.text += std::to_string(100 + k / 10) + "." + std::to_string(k % 10);
    for (int r = 0; r < g.rows(); ++r) {
      for (int c = 0; c < g.cols(); ++c)
        file.text += ", " + number_text(g(r, c));
    }
    file.text += '\n';
  }
  return file;
}

}  // namespace

TEST_CASE("bireg_smooth: every hostile input gives exit 2 and one line naming file:line",
          "[tool]") {
  struct Case {
    std::string args, expected;
  };
  const std::string small = "\"" + data("so3_small.csv") + "\"";
  const std::vector<Case> cases = {
      {"--bandwidth 1 \"" + data("truncated.csv") + "\"",
       "truncated.csv:3: expected 10 numbers, found 9"},
      {"--bandwidth 1 \"" + data("text_in_number.csv") + "\"",
       "text_in_number.csv:2: not a number: 'abc'"},
      {"--bandwidth 1 \"" + data("not_in_group.csv") + "\"",
       "not_in_group.csv:2: matrix is not an element of SO3"},
      {"--bandwidth 1 \"" + data("nan.csv") + "\"", "nan.csv:2: not a finite number: 'nan'"},
      {"--bandwidth 1 \"" + data("huge.csv") + "\"", "huge.csv:3: number out of range: '1e400'"},
      {"--bandwidth 1 \"" + data("extra_columns.csv") + "\"",
       "extra_columns.csv:3: expected 10 numbers, found 11"},
      {"--bandwidth 1 \"" + data("empty.csv") + "\"", "empty.csv: no observations"},
      {"--bandwidth 1 \"" + data("one_observation.csv") + "\"",
       "one_observation.csv: need at least 2 observations, got 1"},
      {"--bandwidth 1 \"" + data("equal_covariates.csv") + "\"",
       "equal_covariates.csv: all covariates are equal"},
      {"--bandwidth 1 \"" + data("no_such_file.csv") + "\"", "no_such_file.csv: cannot open file"},
      {"--bandwidth 1 \"" + std::string(BIREG_TEST_DATA_DIR) + "\"",
       "data: is a directory, not a file"},
      {"--bandwidth 1 --format tum \"" + data("bad_quaternion.tum") + "\"",
       "bad_quaternion.tum:2: quaternion norm 0.5 is far from 1"},
      {"--bandwidth 1 --format tum \"" + data("wrong_columns.tum") + "\"",
       "wrong_columns.tum:2: expected 8 numbers"},
      {"--bandwidth 1 - < " + make_file("stdin_text.csv", "0, 1, 0, 0, 0, 1, 0, 0, 0, 1\nx\n"),
       "<stdin>:2: "},
      {"--bandwidth 1 --at " + make_file("at_text.txt", "2.5\nabc\n") + " " + small,
       "at_text.txt:2: not a number: 'abc'"},
      {"--bandwidth 1 --at " + make_file("at_two.txt", "# t\n2.5 3\n") + " " + small,
       "at_two.txt:2: expected 1 timestamp, found 2 numbers"},
      {"--bandwidth 1 --at " + make_file("at_nan.txt", "2.5\n3\nnan\n") + " " + small,
       "at_nan.txt:3: not a finite number: 'nan'"},
      {"--bandwidth 1 --at " + make_file("at_empty.txt", "# none\n") + " " + small,
       "at_empty.txt: no timestamps"},
      {"--bandwidth 1 --at " + make_file("at_after.txt", "2.5\n5.0000001\n") + " " + small,
       "at_after.txt:2: timestamp '5.0000001' is outside the data's range [2, 5]"},
      {"--bandwidth 1 --at " + make_file("at_before.txt", "1.999\n") + " " + small,
       "at_before.txt:1: timestamp '1.999' is outside the data's range"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Run run = run_tool("--group SO3 " + c.args);
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    REQUIRE(run.err.rfind("bireg_smooth: ", 0) == 0);
    REQUIRE(run.err.find(c.expected) != std::string::npos);
    REQUIRE(run.err.find('\n') == run.err.size() - 1);
  }
}

TEST_CASE("bireg_smooth: bad usage gives exit 2 with the message and the usage", "[tool]") {
  const std::string small = " \"" + data("so3_small.csv") + "\"";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--bandwidth 1" + small, "--group is required"},
      {"--group SO3 --bandwidth 0" + small, "--bandwidth needs a positive number or auto"},
      {"--group SO3 --bandwidth 1 --kernel box" + small, "unknown kernel 'box'"},
      {"--group SO3 --bandwidth 1 --rate -2" + small, "--rate needs a positive number"},
      {"--group SO3 --bandwidth 1 --rate 2 --at x.txt" + small, "--at and --rate exclude"},
      {"--group SO4 --bandwidth 1" + small, "unknown group 'SO4'"},
      {"--group SO3 --bandwidth 1 --threads 0" + small, "--threads needs an integer in [1, 1024]"},
      {"--group SE2 --bandwidth 1 --output-format tum" + small,
       "the tum format holds SE3 or SO3 poses, not SE2"},
      {"--group SO3 --method cubic" + small, "unknown method 'cubic' (local or spline)"},
      {"--group SO3 --method spline --bandwidth 1" + small,
       "--bandwidth applies to --method local only"},
      {"--group SO3 --method spline --kernel tricube" + small,
       "--kernel applies to --method local only"},
      {"--group SO3 --degree 3" + small, "--degree applies to --method spline only"},
      {"--group SO3 --knot-spacing 1" + small, "--knot-spacing applies to --method spline only"},
      {"--group SO3 --method spline --degree 4" + small, "--degree needs 1, 2 or 3"},
      {"--group SO3 --method spline --knot-spacing -1" + small,
       "--knot-spacing needs a positive number or auto"},
      {"--group SO3 --bandwidth 1 --cv-table t.csv" + small,
       "--cv-table goes with --bandwidth auto"},
      {"--group SO3 --method spline --knot-spacing 1 --cv-table t.csv" + small,
       "--cv-table goes with --knot-spacing auto or --roughness-penalty auto"},
      {"--group SO3 --roughness-penalty 1" + small,
       "--roughness-penalty applies to --method spline only"},
      {"--group SO3 --method spline --roughness-penalty -1" + small,
       "--roughness-penalty needs a number >= 0 or auto, got '-1'"},
      {"--group SO3 --method spline --roughness-penalty smooth" + small,
       "--roughness-penalty needs a number >= 0 or auto, got 'smooth'"},
  };
  for (const auto& [args, expected] : cases) {
    CAPTURE(args);
    const Run run = run_tool(args);
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 2);
    REQUIRE(run.out.empty());
    REQUIRE(run.err.find(expected) != std::string::npos);
  }
}

// Tolerance: the local fit of noise-free geodesic data converges to the
// geodesic itself (the estimating equations vanish there); what is left is
// rounding in the matrices written with 17 digits and in the fit, a few
// 1e-16 times the ~20 observations per window, far below 1e-10.
TEST_CASE("bireg_smooth: a noise-free SO3 geodesic is smoothed to its poses and velocity",
          "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.8, -0.4, 1.1), 60);
  const std::string input = make_file("so3_geodesic.csv", file.text);
  const fs::path velocity = work_dir() / "so3_velocity.csv";
  // Bandwidths whose windows (4 h wide for the Gaussian, 2 h for the
  // others) turn through about 1.2 rad at |X| = 1.4 rad/s: well inside the
  // estimator's domain (less than pi end to end).
  const std::vector<std::pair<std::string, std::string>> kernels = {
      {"gaussian", "0.2"}, {"epanechnikov", "0.4"}, {"tricube", "0.4"}};
  for (const auto& [kernel, bandwidth] : kernels) {
    CAPTURE(kernel);
    const Run run = run_tool("--group SO3 --bandwidth " + bandwidth + " --kernel " + kernel +
                             " --velocity \"" + velocity.string() + "\" " + input);
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 0);
    const std::vector<Line> poses = parse_csv(run.out);
    const std::vector<Line> input_lines = parse_csv(file.text);
    REQUIRE(poses.size() == input_lines.size());
    const std::vector<std::string> csv = split(slurp(velocity), '\n');
    REQUIRE(csv.at(0) == "t,wx,wy,wz,se_wx,se_wy,se_wz,status");
    const std::vector<Line> velocities = parse_csv(slurp(velocity).substr(csv.at(0).size() + 1));
    REQUIRE(velocities.size() == poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k) {
      // The input's timestamp text, exactly.
      REQUIRE(poses[k].time == input_lines[k].time);
      REQUIRE(velocities[k].time == input_lines[k].time);
      const double t = static_cast<double>(k) / 10.0;
      REQUIRE((element_of<G>(poses[k].numbers) - file.at(t)).norm() < 1e-10);
      REQUIRE(velocities[k].numbers.size() == 6);
      REQUIRE(velocities[k].status == "ok");
      for (int i = 0; i < 3; ++i) {
        REQUIRE(std::abs(velocities[k].numbers[static_cast<std::size_t>(i)] - file.velocity[i]) <
                1e-10);
        // No residuals: the standard error is undefined (an empty field,
        // never NaN in the file) or at the rounding level.
        const double error = velocities[k].numbers[static_cast<std::size_t>(3 + i)];
        REQUIRE((std::isnan(error) || std::abs(error) < 1e-10));
      }
    }
  }
}

// A cubic spline reproduces a geodesic exactly (control points along it
// give equal increments, whose exponentials commute, and the cumulative
// basis sums to 1 + u: the product is the geodesic), so the fit's
// residuals vanish there; what is left is the Gauss-Newton tolerance
// (1e-10 on the control points) over the knot spacing of 0.5 s and the
// 17-digit matrices: 1e-8 on poses and velocities.
TEST_CASE("bireg_smooth --method spline: a noise-free SO3 geodesic, its velocity, and refusals",
          "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.8, -0.4, 1.1), 60);
  const std::string input = make_file("so3_geodesic_spline.csv", file.text);
  const fs::path velocity = work_dir() / "so3_spline_velocity.csv";
  const Run run = run_tool("--group SO3 --method spline --knot-spacing 0.5 --velocity \"" +
                           velocity.string() + "\" " + input);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<Line> poses = parse_csv(run.out);
  REQUIRE(poses.size() == 60);
  const std::string text = slurp(velocity);
  const std::string header = split(text, '\n').at(0);
  REQUIRE(header == "t,wx,wy,wz,se_wx,se_wy,se_wz,status");
  const std::vector<Line> rows = parse_csv(text.substr(header.size() + 1));
  REQUIRE(rows.size() == 60);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    REQUIRE((element_of<G>(poses[k].numbers) - file.at(static_cast<double>(k) / 10.0)).norm() <
            1e-8);
    REQUIRE(rows[k].status == "ok");
    for (int i = 0; i < 3; ++i)
      REQUIRE(std::abs(rows[k].numbers[static_cast<std::size_t>(i)] - file.velocity[i]) < 1e-8);
  }

  // Noise-free: no standard errors (empty fields), and stderr says why.
  REQUIRE(run.err.find("no velocity standard errors: the residuals vanish") != std::string::npos);
  REQUIRE(std::isnan(rows[0].numbers[3]));

  // With noise of 0.01 rad: every row has standard errors, and the
  // velocity is within 4 of them of the truth (the cubic spline holds the
  // geodesic exactly, so the estimate is unbiased). Their size away from
  // the ends: about sigma sqrt(M / N) / h = 0.01 x sqrt(15 / 60) / 0.5 =
  // 0.01 rad/s; within a segment of the ends about 10x that, where the
  // end control point is pinned only by the few observations near it
  // (B_0 = (1 - u)^3 / 6).
  std::mt19937 rng(8);
  const std::string noisy =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.8, -0.4, 1.1), 60, 0.01, &rng).text;
  const fs::path noisy_velocity = work_dir() / "so3_spline_noisy_velocity.csv";
  const Run banded =
      run_tool("--group SO3 --method spline --knot-spacing 0.5 --velocity \"" +
               noisy_velocity.string() + "\" " + make_file("so3_spline_noisy.csv", noisy));
  CAPTURE(banded.err);
  REQUIRE(banded.exit_code == 0);
  const std::string noisy_text = slurp(noisy_velocity);
  const std::vector<Line> noisy_rows =
      parse_csv(noisy_text.substr(split(noisy_text, '\n').at(0).size() + 1));
  REQUIRE(noisy_rows.size() == 60);
  for (std::size_t k = 0; k < noisy_rows.size(); ++k) {
    const Line& row = noisy_rows[k];
    CAPTURE(row.time);
    REQUIRE(row.status == "ok");
    const bool interior = k >= 5 && k < 55;
    for (std::size_t i = 0; i < 3; ++i) {
      const double se = row.numbers[3 + i];
      REQUIRE(se > (interior ? 0.002 : 0.0));
      REQUIRE(se < (interior ? 0.05 : 0.5));
      REQUIRE(std::abs(row.numbers[i] - file.velocity[int(i)]) < 4 * se);
    }
  }

  // auto: the choice on stderr, the curve in --cv-table.
  const fs::path table = work_dir() / "so3_spline_cv.csv";
  const Run chosen =
      run_tool("--group SO3 --method spline --cv-table \"" + table.string() + "\" " + input);
  CAPTURE(chosen.err);
  REQUIRE(chosen.exit_code == 0);
  REQUIRE(chosen.err.find("bireg_smooth: knot spacing auto: ") == 0);
  const std::vector<std::string> curve = split(slurp(table), '\n');
  REQUIRE(curve.at(0) == "knot_spacing,criterion,failures,refused");
  REQUIRE(curve.size() >= 25);  // the header and 24 spacings

  // A knot span that turns by 2.56 rad (5.2 rad/s; the 5.9 s range cut
  // into 12 spans of 0.4917 s, the fewest no longer than 0.5 s): a warning
  // that names the control points.
  const GeodesicFile<G> fast =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.0, 5.2, 0.0), 60);
  const Run turning = run_tool("--group SO3 --method spline --knot-spacing 0.5 " +
                               make_file("so3_spline_fast.csv", fast.text));
  CAPTURE(turning.err);
  REQUIRE(turning.exit_code == 0);
  REQUIRE(turning.err.find("warning: the spline turns by 2.56 rad between control points") !=
          std::string::npos);
  REQUIRE(turning.err.find("use a narrower --knot-spacing") != std::string::npos);

  // Knots the data cannot determine: invalid input, named.
  const Run dense = run_tool("--group SO3 --method spline --knot-spacing 0.01 " + input);
  REQUIRE(dense.exit_code == 2);
  REQUIRE(dense.err.find("control points for 60 observations; use a wider spacing") !=
          std::string::npos);
}

// --roughness-penalty auto on noisy samples of a geodesic (0.01 rad, 60
// samples 0.1 s apart): a geodesic is in the penalty's null space
// (docs/splines.md §12), so cross-validation chooses a strong penalty, at
// least 10 w (w = 1.5 observations per span of 0.15 s). The penalty adds
// no bias there, and the velocity's error is the noise averaged over the
// smoothing window, about h (lambda / w)^(1/4) wide (§12), capped at the
// 5.9 s range: a local line through n = T / 0.1 s samples over T has a
// slope error of 0.01 sqrt(12 / (n T^2)) per axis; 4 of them bound it.
TEST_CASE("bireg_smooth --method spline --roughness-penalty: chosen, said, tabled, refused",
          "[tool]") {
  using G = bireg::SO3<double>;
  std::mt19937 rng(9);
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.8, -0.4, 1.1), 60, 0.01, &rng);
  const std::string input = make_file("so3_spline_penalised.csv", file.text);
  const fs::path velocity = work_dir() / "so3_spline_penalised_velocity.csv";
  const fs::path table = work_dir() / "so3_spline_penalised_cv.csv";
  const Run run = run_tool("--group SO3 --method spline --roughness-penalty auto --velocity \"" +
                           velocity.string() + "\" --cv-table \"" + table.string() + "\" " + input);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.err.find("bireg_smooth: knot spacing auto with --roughness-penalty auto: 0.1") == 0);
  REQUIRE(run.err.find(" s (1.5 median sample spacings)\n") != std::string::npos);
  const std::string said = "\nbireg_smooth: roughness penalty auto: ";
  const std::size_t at = run.err.find(said);
  REQUIRE(at != std::string::npos);
  const double lambda = std::strtod(run.err.c_str() + at + said.size(), nullptr);
  REQUIRE(lambda >= 10 * 1.5);
  const double window = std::min(5.9, 0.15 * std::pow(lambda / 1.5, 0.25));
  const double bound = 4 * 0.01 * std::sqrt(12 / (window / 0.1 * window * window));
  REQUIRE(run.err.find("no velocity standard errors: the covariance of a spline fitted with a "
                       "roughness penalty") != std::string::npos);
  const std::vector<std::string> curve = split(slurp(table), '\n');
  REQUIRE(curve.at(0) == "roughness_penalty,criterion,failures,refused");
  const std::string text = slurp(velocity);
  const std::vector<Line> rows = parse_csv(text.substr(split(text, '\n').at(0).size() + 1));
  REQUIRE(rows.size() == 60);
  for (const Line& row : rows) {
    CAPTURE(row.time);
    REQUIRE(row.status == "ok");
    for (std::size_t i = 0; i < 3; ++i) {
      REQUIRE(std::abs(row.numbers[i] - file.velocity[int(i)]) < bound);
      REQUIRE(std::isnan(row.numbers[3 + i]));  // no standard errors
    }
  }

  // A lambda given: no cross-validation; degree 1 with one: refused.
  const Run given =
      run_tool("--group SO3 --method spline --knot-spacing 0.5 --roughness-penalty 2 " + input);
  CAPTURE(given.err);
  REQUIRE(given.exit_code == 0);
  REQUIRE(given.err.find("auto") == std::string::npos);
  const Run linear = run_tool(
      "--group SO3 --method spline --degree 1 --knot-spacing 0.5 --roughness-penalty 2 " + input);
  REQUIRE(linear.exit_code == 2);
  REQUIRE(linear.err.find("bireg_smooth: --roughness-penalty needs --degree 2 or 3") == 0);
  const Run linear_auto =
      run_tool("--group SO3 --method spline --degree 1 --roughness-penalty auto " + input);
  REQUIRE(linear_auto.exit_code == 2);
  REQUIRE(linear_auto.err.find("bireg_smooth: --roughness-penalty needs --degree 2 or 3") == 0);
}

TEST_CASE("bireg_smooth: SE3 velocity columns are translation first, as the group's tangent",
          "[tool]") {
  using G = bireg::SE3<double>;
  G::Tangent start, velocity;
  start << 0.5, -1.0, 2.0, 0.2, 0.4, -0.3;
  velocity << 1.5, -0.25, 0.75, 0.3, -0.9, 0.6;
  const GeodesicFile<G> file = geodesic_file<G>(start, velocity, 40);
  const fs::path csv = work_dir() / "se3_velocity.csv";
  const Run run = run_tool("--group SE3 --bandwidth 0.3 --velocity \"" + csv.string() + "\" " +
                           make_file("se3_geodesic.csv", file.text));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::string text = slurp(csv);
  const std::string header = split(text, '\n').at(0);
  REQUIRE(header == "t,vx,vy,vz,wx,wy,wz,se_vx,se_vy,se_vz,se_wx,se_wy,se_wz,status");
  const std::vector<Line> rows = parse_csv(text.substr(header.size() + 1));
  REQUIRE(rows.size() == 40);
  const std::vector<Line> poses = parse_csv(run.out);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    REQUIRE((element_of<G>(poses[k].numbers) - file.at(static_cast<double>(k) / 10.0)).norm() <
            1e-10);
    for (int i = 0; i < 6; ++i)
      REQUIRE(std::abs(rows[k].numbers[static_cast<std::size_t>(i)] - velocity[i]) < 1e-10);
  }
}

TEST_CASE("bireg_smooth: --at evaluates between samples and keeps the file's timestamp text",
          "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.1, 0.2, 0.3), G::Tangent(-0.5, 0.9, 0.2), 50);
  const std::string input = make_file("so3_geodesic_at.csv", file.text);
  // In the input's convention (seconds, as the file's first column), in any
  // order, with the first and last sample's times included (the range is
  // closed) and spellings that must come back unchanged.
  const std::vector<std::string> at = {"103.250", "100", "104.9", "101.0500", "1.0205e2"};
  std::string at_text = "# query times\n";
  for (const std::string& t : at)
    at_text += t + "\n";
  const Run run =
      run_tool("--group SO3 --bandwidth 0.3 --at " + make_file("at.txt", at_text) + " " + input);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<Line> poses = parse_csv(run.out);
  REQUIRE(poses.size() == at.size());
  for (std::size_t q = 0; q < at.size(); ++q) {
    CAPTURE(at[q]);
    REQUIRE(poses[q].time == at[q]);
    const double t = std::strtod(at[q].c_str(), nullptr) - file.origin;
    REQUIRE((element_of<G>(poses[q].numbers) - file.at(t)).norm() < 1e-10);
  }
}

TEST_CASE("bireg_smooth: --rate resamples from the first timestamp, exactly", "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.1, 0.2, 0.3), G::Tangent(-0.5, 0.9, 0.2), 50);
  const Run run = run_tool("--group SO3 --bandwidth 0.3 --rate 4 " +
                           make_file("so3_geodesic_rate.csv", file.text));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<Line> poses = parse_csv(run.out);
  // 100 to 104.9 s at 4 Hz: 100, 100.25, ..., 104.75.
  REQUIRE(poses.size() == 20);
  REQUIRE(poses[0].time == "100");
  REQUIRE(poses[1].time == "100.25");
  REQUIRE(poses[19].time == "104.75");
  for (std::size_t q = 0; q < poses.size(); ++q) {
    REQUIRE((element_of<G>(poses[q].numbers) - file.at(static_cast<double>(q) / 4.0)).norm() <
            1e-10);
  }
}

TEST_CASE("bireg_smooth: reads TUM and writes the input's format, and write errors exit 4",
          "[tool]") {
  const std::string tum = "\"" + data("se3_small.tum") + "\"";
  const Run run = run_tool("--group SE3 --bandwidth 0.5 " + tum);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<std::string> in = split(slurp(data("se3_small.tum")), '\n');
  const std::vector<std::string> out = split(run.out, '\n');
  std::vector<std::string> in_times;
  for (const std::string& line : in) {
    if (!line.empty() && line[0] != '#') in_times.push_back(split(line, ' ').at(0));
  }
  REQUIRE(out.size() == in_times.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    REQUIRE(split(out[k], ' ').size() == 8);
    REQUIRE(split(out[k], ' ')[0] == in_times[k]);
  }
  const Run unwritable =
      run_tool("--group SE3 --bandwidth 0.5 --velocity /nonexistent_dir/v.csv " + tum);
  REQUIRE(unwritable.exit_code == 4);
  REQUIRE(unwritable.err.find("/nonexistent_dir/v.csv: cannot write file") != std::string::npos);
}

TEST_CASE("bireg_smooth: --bandwidth auto chooses a bandwidth, says so, and smooths with it",
          "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.4, -0.2, 0.3), 40);
  const Run run =
      run_tool("--group SO3 --bandwidth auto " + make_file("so3_geodesic_auto.csv", file.text));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  REQUIRE(run.err.rfind("bireg_smooth: bandwidth auto: ", 0) == 0);
  // The choice, and at most a warning line (a noise-free geodesic is best
  // fitted at the grid's smallest bandwidth, which the warning says).
  const std::vector<std::string> err_lines = split(run.err, '\n');
  for (std::size_t k = 1; k < err_lines.size(); ++k) {
    if (!err_lines[k].empty())
      REQUIRE(err_lines[k].rfind("bireg_smooth: warning: bandwidth auto: ", 0) == 0);
  }
  // A noise-free geodesic is recovered at any bandwidth: whichever was chosen.
  const std::vector<Line> poses = parse_csv(run.out);
  REQUIRE(poses.size() == 40);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    REQUIRE((element_of<G>(poses[k].numbers) - file.at(static_cast<double>(k) / 10.0)).norm() <
            1e-10);
  }
}

// 2500 samples of a curve that is not a geodesic (the windows have
// residuals): three blocks of 1024 queries, which the threads share out.
// The output, poses and velocity CSV with standard errors, is byte for
// byte the same for 1, 2 and 7 threads. (--bandwidth auto splits its
// leave-one-out passes the same way, tested in the library's
// test_threads; here its O(N^2) widest windows would cost minutes under
// the sanitizers.)
TEST_CASE("bireg_smooth: the output does not depend on --threads", "[tool]") {
  using G = bireg::SO3<double>;
  std::string text;
  for (int k = 0; k < 2500; ++k) {
    const double t = k * 1e-3;
    const G::Element g =
        G::exp(G::Tangent(0.3 * std::sin(20 * t), 0.2 * t, 0.1 * std::cos(30 * t)));
    text += std::to_string(k / 1000) + "." + std::to_string(1000 + k % 1000).substr(1);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        text += ", " + number_text(g(r, c));
    }
    text += '\n';
  }
  const std::string input = make_file("so3_threads.csv", text);
  std::vector<std::string> outputs;
  for (const std::string threads : {"1", "2", "7"}) {
    const std::string velocity = (work_dir() / ("threads_" + threads + ".csv")).string();
    const Run run = run_tool("--group SO3 --bandwidth 0.0025 --threads " + threads +
                             " --velocity \"" + velocity + "\" " + input);
    CAPTURE(threads, run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(parse_csv(run.out).size() == 2500);
    outputs.push_back(run.out + slurp(velocity));
  }
  REQUIRE(outputs[1] == outputs[0]);
  REQUIRE(outputs[2] == outputs[0]);
}

TEST_CASE("bireg_smooth: --help and --version answer on stdout with exit 0", "[tool]") {
  const Run help = run_tool("--help");
  REQUIRE(help.exit_code == 0);
  REQUIRE(help.err.empty());
  for (const char* option : {"--group", "--format", "--times", "--project", "--bandwidth",
                             "--kernel", "--at", "--rate", "--velocity", "--cv-table", "--output",
                             "--output-format", "--threads", "--progress", "--version"}) {
    CAPTURE(option);
    REQUIRE(help.out.find(option) != std::string::npos);
  }
  REQUIRE(help.out.find("Exit codes") != std::string::npos);
  const Run version = run_tool("--version");
  REQUIRE(version.exit_code == 0);
  REQUIRE(version.out == std::string("bireg_smooth ") + bireg::version + "\n");
}

// A planted failing region: a geodesic sampled at 100.0 .. 101.9 and
// 104.0 .. 105.9 s, smoothed with a Gaussian of 0.04 s (support 0.16 s)
// at --rate 10: the queries from 102.0 to 103.9 s have at most one
// observation in their window. Each of those rows fails, says why, and has no numbers;
// its pose is left out; the exit code is 3; the rows around it are ok.
TEST_CASE("bireg_smooth: failed rows carry a status, no numbers, and exit 3", "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.4, -0.2, 0.3), 60);
  std::string text;
  int k = 0;
  for (const std::string& line : split(file.text, '\n')) {
    if (!line.empty() && (k < 20 || k >= 40)) text += line + '\n';
    ++k;
  }
  const std::string input = make_file("so3_gap.csv", text);
  const fs::path velocity = work_dir() / "so3_gap_velocity.csv";
  const Run run = run_tool("--group SO3 --bandwidth 0.04 --rate 10 --velocity \"" +
                           velocity.string() + "\" " + input);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 3);
  REQUIRE(run.err.find("failed (pose): fewer than two distinct covariates") != std::string::npos);
  const std::vector<Line> rows = parse_csv(slurp(velocity).substr(slurp(velocity).find('\n') + 1));
  REQUIRE(rows.size() == 60);
  std::size_t failed = 0;
  for (const Line& row : rows) {
    const double t = std::strtod(row.time.c_str(), nullptr);
    CAPTURE(row.time, row.status);
    const bool in_gap = t > 101.95 && t < 103.95;
    if (in_gap) {
      ++failed;
      // "failed: <reason>", in quotes when the reason holds a comma.
      REQUIRE((row.status.rfind("failed: ", 0) == 0 || row.status.rfind("\"failed: ", 0) == 0));
      for (const double x : row.numbers)
        REQUIRE(std::isnan(x));  // empty fields
    } else {
      REQUIRE(row.status == "ok");
      for (int i = 0; i < 3; ++i)
        REQUIRE(std::abs(row.numbers[static_cast<std::size_t>(i)] - file.velocity[i]) < 1e-9);
    }
  }
  REQUIRE(failed == 20);
  REQUIRE(parse_csv(run.out).size() == 60 - failed);
}

TEST_CASE("bireg_smooth: --cv-table writes both cross-validation curves", "[tool]") {
  using G = bireg::SO3<double>;
  const GeodesicFile<G> file =
      geodesic_file<G>(G::Tangent(0.3, -1.2, 0.5), G::Tangent(0.4, -0.2, 0.3), 40);
  const fs::path table = work_dir() / "cv_table.csv";
  const Run run = run_tool("--group SO3 --cv-table \"" + table.string() + "\" " +
                           make_file("so3_geodesic_cv.csv", file.text));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<std::string> lines = split(slurp(table), '\n');
  REQUIRE(lines.at(0) ==
          "bandwidth,criterion,failures,refused,velocity_criterion,velocity_failures,"
          "velocity_refused,cubic_velocity_criterion");
  std::size_t rows = 0;
  double previous = 0;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    if (lines[k].empty()) continue;
    ++rows;
    const double bandwidth = std::strtod(lines[k].c_str(), nullptr);
    REQUIRE(bandwidth > previous);  // ascending
    previous = bandwidth;
  }
  REQUIRE(rows == 20);
  // From half the spacing (0.1 s) to the whole range (3.9 s).
  REQUIRE(std::abs(std::strtod(lines[1].c_str(), nullptr) - 0.05) < 1e-12);
  REQUIRE(std::abs(previous - 3.9) < 1e-9);
}
