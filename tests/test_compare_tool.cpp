// bireg_compare, run as a user would: its JSON against the library's
// two_sample_test and compare_trends on the same data, independent of the
// thread count and of which cohort the manifest names first, a failed
// subject left out with exit 3, and every hostile manifest or element file
// refused with exit 2 and one line naming file:line.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/version.hpp"
#include "catch.hpp"
#include "test_support.hpp"
#include "tool_runner.hpp"

namespace {

namespace fs = std::filesystem;
using bireg_test::json_numbers;
using bireg_test::json_string;
using bireg_test::Run;
using bireg_test::work_dir;
using SE3 = bireg::SE3d;
using SO3 = bireg::SO3d;

Run run_tool(const std::string& arguments) {
  return bireg_test::run_executable(BIREG_COMPARE_EXECUTABLE, arguments);
}

// A folder of its own in the work directory for one test's files.
fs::path folder(const std::string& name) {
  const fs::path dir = work_dir() / ("compare_" + name);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A matrix's entries, row-major, with 17 significant digits: read back,
// the same doubles.
template <class Matrix>
std::string entries(const Matrix& m, const char* separator) {
  std::string text;
  char number[32];
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) {
      std::snprintf(number, sizeof number, "%.17g", m(r, c));
      text += (r + c > 0 ? separator : "") + std::string(number);
    }
  }
  return text;
}

// Two SE(3) samples of 12 and 10, the second's mean moved; each cohort's
// elements in three files of the folder, listed in a manifest (a relative
// path, one of them quoted), cohort A first unless `b_first`.
struct ElementStudy {
  std::vector<SE3::Element> a, b;
  fs::path manifest;
};

ElementStudy element_study(bool b_first) {
  ElementStudy study;
  std::mt19937 rng(41);
  const SE3::Element shift = SE3::exp(SE3::Tangent(0.1, 0.0, 0.2, 0.15, 0.0, 0.0));
  for (int i = 0; i < 12; ++i)
    study.a.push_back(SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 0.3)));
  for (int i = 0; i < 10; ++i) {
    study.b.push_back(
        SE3::compose(shift, SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 0.3))));
  }
  const fs::path dir = folder(b_first ? "elements_swapped" : "elements");
  std::string rows[2];
  for (int cohort = 0; cohort < 2; ++cohort) {
    const std::vector<SE3::Element>& sample = cohort == 0 ? study.a : study.b;
    for (int file = 0; file < 3; ++file) {
      const std::string name =
          std::string(cohort == 0 ? "knee_a" : "knee_b") + std::to_string(file) + ".txt";
      std::string text = "# one SE(3) element per line\n";
      for (std::size_t i = std::size_t(file); i < sample.size(); i += 3)
        text += entries(sample[i], file == 1 ? " " : ", ") + "\n";
      write(dir / name, text);
      rows[cohort] += (file == 2 ? "\"" + name + "\"" : name) + "," +
                      (cohort == 0 ? "healthy" : "grade 3") + ",s" + std::to_string(file) + "\n";
    }
  }
  study.manifest = dir / "manifest.csv";
  write(study.manifest, "path,cohort,subject\n" + rows[b_first ? 1 : 0] + rows[b_first ? 0 : 1]);
  return study;
}

// Element order within a cohort as the tool reads it: file by file.
std::vector<SE3::Element> as_read(const std::vector<SE3::Element>& sample) {
  std::vector<SE3::Element> out;
  for (std::size_t file = 0; file < 3; ++file) {
    for (std::size_t i = file; i < sample.size(); i += 3)
      out.push_back(sample[i]);
  }
  return out;
}

std::string quoted(const fs::path& path) {
  return "\"" + path.string() + "\"";
}

}  // namespace

// The statistic is the library's on the same doubles (the files hold them
// with 17 digits), so it agrees to rounding in the means' iterations
// (1e-12 relative); the p-value counts the same relabellings exactly.
TEST_CASE("bireg_compare --elements: the library's test, any thread count", "[tool]") {
  const ElementStudy study = element_study(false);
  bireg::TwoSampleOptions<double> options;
  options.permutations = 199;
  options.seed = 7;
  const auto expected = bireg::two_sample_test<SE3>(as_read(study.a), as_read(study.b), options);
  REQUIRE(expected.ok());
  std::string outputs[2];
  for (const int threads : {1, 2}) {
    const Run run = run_tool("--group SE3 --elements --permutations 199 --seed 7 --threads " +
                             std::to_string(threads) + " " + quoted(study.manifest));
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 0);
    REQUIRE(json_string(run.out, "statistic") == "hotelling");
    REQUIRE(json_string(run.out, "variant") == "invariant");
    REQUIRE(json_string(run.out, "compared") == "elements");
    const double value = json_numbers(run.out, "value").at(0);
    CHECK(std::abs(value - expected.value) <= 1e-12 * expected.value);
    CHECK(json_numbers(run.out, "p_value").at(0) == expected.p_value);
    CHECK(json_numbers(run.out, "permutations").at(0) == 199);
    CHECK(run.out.find("\"name\": \"healthy\", \"size\": 12") != std::string::npos);
    CHECK(run.out.find("\"name\": \"grade 3\", \"size\": 10") != std::string::npos);
    const std::vector<double> mean = json_numbers(run.out, "mean");
    REQUIRE(mean.size() == 16);
    for (int k = 0; k < 16; ++k)
      CHECK(std::abs(mean[std::size_t(k)] - (*expected.mean_a)(k / 4, k % 4)) < 1e-12);
    outputs[threads - 1] = run.out;
  }
  CHECK(outputs[0] == outputs[1]);
}

// The invariant variant does not depend on which cohort is A (docs/cohorts.md
// proves it): the manifest listing grade 3 first gives the same statistic.
TEST_CASE("bireg_compare: naming the other cohort first leaves the statistic", "[tool]") {
  double values[2] = {0.0, 0.0};
  for (const bool b_first : {false, true}) {
    const ElementStudy study = element_study(b_first);
    const Run run = run_tool("--group SE3 --elements --permutations 0 " + quoted(study.manifest));
    CAPTURE(run.err);
    REQUIRE(run.exit_code == 0);
    values[b_first ? 1 : 0] = json_numbers(run.out, "value").at(0);
  }
  CHECK(std::abs(values[0] - values[1]) <= 1e-9 * values[0]);
}

// Trends: 8 + 8 subjects of SO(3) trajectories (matrix format, times on
// one clock, each subject starting at its own time), the cohorts' rates
// differing by 0.4 rad/s about y. The tool's statistic is the library's
// compare_trends on fit_many's trends over the shared interval; one
// subject with a single observation fails its fit, is listed with its
// status, left out, and the exit code is 3.
TEST_CASE("bireg_compare: trends, the library's comparison, a failed subject left out", "[tool]") {
  const fs::path dir = folder("trends");
  std::mt19937 rng(5);
  std::vector<bireg::SubjectData<SO3>> cohorts[2];
  std::string manifest = "cohort,path\n";  // columns in either order
  for (int cohort = 0; cohort < 2; ++cohort) {
    const SO3::Tangent rate(0.5, cohort == 0 ? 0.0 : 0.4, 0.0);
    for (int s = 0; s < 8; ++s) {
      bireg::SubjectData<SO3> subject;
      const SO3::Element start = SO3::exp(bireg_test::normal_tangent<SO3::Tangent>(rng, 0.1));
      std::string text;
      for (int i = 0; i < 8; ++i) {
        const double t = 0.05 * s + 0.25 * i;  // the subject's times on the study's clock
        const SO3::Element r = SO3::compose(
            start, SO3::exp(t * rate + bireg_test::normal_tangent<SO3::Tangent>(rng, 0.05)));
        subject.observations.push_back(r);
        subject.covariates.push_back(t);
        char time[32];
        std::snprintf(time, sizeof time, "%.17g", t);
        text += std::string(time) + ", " + entries(r, ", ") + "\n";
      }
      const std::string name = "subject_" + std::to_string(cohort) + std::to_string(s) + ".csv";
      write(dir / name, text);
      manifest += std::string(cohort == 0 ? "A" : "B") + "," + name + "\n";
      cohorts[cohort].push_back(subject);
    }
  }
  write(dir / "one_pose.csv", "0.5, 1, 0, 0, 0, 1, 0, 0, 0, 1\n");
  write(dir / "manifest.csv", manifest + "B,one_pose.csv\n");
  std::vector<bireg::SubjectData<SO3>> all = cohorts[0];
  all.insert(all.end(), cohorts[1].begin(), cohorts[1].end());
  const bireg::GeodesicRegression<SO3> regression{bireg::RegressionOptions<double>()};
  const auto fits = bireg::fit_many<SO3>(regression, all);
  REQUIRE(fits.ok());
  const std::vector<bireg::Trend<SO3>> a(fits.trends.begin(), fits.trends.begin() + 8);
  const std::vector<bireg::Trend<SO3>> b(fits.trends.begin() + 8, fits.trends.end());
  bireg::TwoSampleOptions<double> options;
  options.permutations = 99;
  const auto expected = bireg::compare_trends<SO3>(a, b, options);
  REQUIRE(expected.ok());
  const Run run =
      run_tool("--group SO3 --permutations 99 --population " + quoted(dir / "manifest.csv"));
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 3);
  REQUIRE(run.err.find("manifest.csv:18: the fit failed (invalid_input") != std::string::npos);
  REQUIRE(json_string(run.out, "compared") == "trends");
  const std::vector<double> interval = json_numbers(run.out, "interval");
  CHECK(interval == std::vector<double>{fits.t0, fits.t1});
  // The failed subject's time (0.5) lies inside [0, 2.1]: the interval
  // does not move without it.
  const double value = json_numbers(run.out, "value").at(0);
  CHECK(std::abs(value - expected.value) <= 1e-10 * expected.value);
  CHECK(json_numbers(run.out, "p_value").at(0) == expected.p_value);
  CHECK(expected.p_value == 0.01);  // a 0.4 rad/s difference: no relabelling reaches it
  CHECK(run.out.find("\"path\": \"one_pose.csv\", \"cohort\": \"B\", \"subject\": \"\", "
                     "\"status\": \"invalid_input\"") != std::string::npos);
  CHECK(run.out.find("\"name\": \"B\", \"size\": 8") != std::string::npos);
  // The population of all 16 (more than 2d + 1 = 7) is estimated; a
  // cohort of 8 is too, and its velocity's standard errors are reported.
  const std::size_t population = run.out.find(
      "\"population\": {\"all\": {\"subjects\": 16, "
      "\"status\": \"ok\"");
  CHECK(population != std::string::npos);
}

TEST_CASE("bireg_compare: hostile manifests and element files, exit 2 naming file:line", "[tool]") {
  const fs::path dir = folder("hostile");
  const SE3::Element g = SE3::exp(SE3::Tangent(0.1, 0.2, 0.3, 0.1, 0.2, 0.3));
  std::string good;
  for (int i = 0; i < 8; ++i) {  // 8 + 8 elements: the pooled covariance is regular
    const SE3::Tangent step = SE3::Tangent::Unit(i % 6) * 0.1 * (1 + i);
    good += entries(SE3::compose(g, SE3::exp(step)), " ") + "\n";
  }
  write(dir / "good.txt", good);
  write(dir / "short.txt", good + "1 2 3\n");
  write(dir / "word.txt", good + entries(g, " ").replace(0, 1, "x") + "\n");
  Eigen::Matrix4d not_rigid = g;
  not_rigid(3, 0) = 0.5;
  write(dir / "not_rigid.txt", good + entries(not_rigid, " ") + "\n");
  write(dir / "empty.txt", "# nothing\n");
  const auto manifest = [&](const std::string& name, const std::string& text) {
    write(dir / name, text);
    return quoted(dir / name);
  };
  const std::string two = "path,cohort\ngood.txt,A\n";
  const struct {
    std::string args, expected;
  } cases[] = {
      {manifest("no_cohort.csv", "path,group\ngood.txt,A\n"),
       "no_cohort.csv:1: the header must name the columns path and cohort"},
      {manifest("three.csv", two + "good.txt,B\ngood.txt,C\n"),
       "exactly two cohorts are compared, found 3 ('A', 'B', 'C')"},
      {manifest("one.csv", two + "good.txt,A\n"), "exactly two cohorts are compared, found 1"},
      {manifest("blank.csv", "\n\n"), "blank.csv: empty"},
      {manifest("fields.csv", two + "good.txt,B,extra\n"),
       "fields.csv:3: expected 2 fields as in the header, found 3"},
      {manifest("quote.csv", two + "\"good.txt,B\n"), "quote.csv:3: a quoted field is not closed"},
      {manifest("missing.csv", two + "nowhere.txt,B\n"), "nowhere.txt: cannot open file"},
      {manifest("short.csv", two + "short.txt,B\n"),
       "short.txt:9: expected 16 numbers (a 4x4 matrix, row-major), found 3"},
      {manifest("word.csv", two + "word.txt,B\n"), "word.txt:9: not a number"},
      {manifest("not_rigid.csv", two + "not_rigid.txt,B\n"), "not_rigid.txt:9: "},
      {manifest("empty.csv", two + "empty.txt,B\n"), "empty.txt: no elements"},
  };
  for (const auto& c : cases) {
    const Run run = run_tool("--group SE3 --elements " + c.args);
    CAPTURE(c.args, run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.out.empty());
    CHECK(run.err.rfind("bireg_compare: ", 0) == 0);
    CHECK(run.err.find(c.expected) != std::string::npos);
    CHECK(run.err.find('\n') == run.err.size() - 1);
  }
  // A trajectory that cannot be read names its file and the manifest line.
  const Run trajectory = run_tool("--group SE3 " + manifest("t.csv", two + "good.txt,B\n"));
  CAPTURE(trajectory.err);
  CHECK(trajectory.exit_code == 2);
  CHECK(trajectory.err.find("t.csv:2)") != std::string::npos);
  // Usage.
  const std::string any = quoted(dir / "one.csv");
  const struct {
    std::string args, expected;
  } usage[] = {
      {"--group SE3 --elements --population " + any, "--population goes with trends"},
      {"--group SE3 --elements --trend " + any, "--elements and --trend exclude each other"},
      {"--group SE3 --elements --format tum " + any, "--format and --project go with"},
      {"--group SE4 " + any, "unknown group 'SE4'"},
      {"--group SE3 --seed 1 --seed 2 " + any, "option --seed given twice"},
      {"--group SE3 --statistic t " + any, "unknown statistic 't'"},
      {"--group SE3 --permutations -1 " + any, "--permutations needs an integer"},
      {"--group SE3", "no manifest"},
      {any, "--group is required"},
  };
  for (const auto& c : usage) {
    const Run run = run_tool(c.args);
    CAPTURE(c.args, run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.out.empty());
    CHECK(run.err.find(c.expected) != std::string::npos);
  }
}

TEST_CASE("bireg_compare: --help and --version answer on stdout with exit 0", "[tool]") {
  const Run help = run_tool("--help");
  CHECK(help.exit_code == 0);
  CHECK(help.out.rfind("usage: bireg_compare", 0) == 0);
  for (const char* option : {"--elements", "--trend", "--population", "--statistic", "--variant",
                             "--permutations", "--seed", "--threads", "Exit codes"}) {
    CHECK(help.out.find(option) != std::string::npos);
  }
  const Run version = run_tool("--version");
  CHECK(version.exit_code == 0);
  CHECK(version.out == std::string("bireg_compare ") + bireg::version + "\n");
}
