// Every entry point above fit() against every class of hostile input
// (issue "Hostile input above fit()", "What to build": one table-driven
// test). The table is docs/hostile_input.md, section "Every entry point
// against every input class": this test reads it and, on SO(3), SE(3) and
// GL+(3), runs each entry point on each input class and asserts the
// documented outcome --
//   refused  the entry point's refusal (invalid_input, or its own refusing
//            status), with a message;
//   status   a documented failure status, with a message;
//   finite   an ok result whose numbers are all finite;
//   -        the entry point takes no such input.
// Whatever the cell says, no outcome is a crash, an assertion, a NaN under
// an ok status or a refusal without a message; CI runs this file under
// AddressSanitizer, UndefinedBehaviorSanitizer and _GLIBCXX_ASSERTIONS.
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "bireg/statistics/smoothing/bandwidth.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

using GLp3d = bireg::GLp<3, double>;

// The documented outcomes, and what a run gave.
enum class Outcome { refused, status, finite, not_applicable };

const char* name(Outcome outcome) {
  switch (outcome) {
    case Outcome::refused:
      return "refused";
    case Outcome::status:
      return "status";
    case Outcome::finite:
      return "finite";
    case Outcome::not_applicable:
      return "-";
  }
  return "?";
}

struct Observed {
  Outcome outcome = Outcome::not_applicable;
  std::string message;  // the refusal's or the status's; empty for finite
  bool finite = true;   // for finite: every number of the result finite
};

Observed refused(const std::string& message) {
  return {Outcome::refused, message, true};
}
Observed failed(const std::string& message) {
  return {Outcome::status, message, true};
}
Observed answered(bool all_finite) {
  return {Outcome::finite, "", all_finite};
}
const Observed kNotApplicable{};

// The data of one input class: observations, covariates, weights.
template <class G>
struct Input {
  std::vector<typename G::Element> f;
  std::vector<double> t;
  std::vector<double> w;
};

// 16 noisy observations along exp(s x), s in [0, 1], at t = 0.1 i, weights 1.
template <class G>
Input<G> valid_input() {
  std::mt19937 rng(37);
  typename G::Tangent x;
  for (int k = 0; k < G::dof; ++k)
    x[k] = 0.4 - 0.07 * k;
  Input<G> in;
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    const auto e = bireg_test::normal_tangent<typename G::Tangent>(rng, 0.05);
    const double s = i / double(n - 1);
    in.f.push_back(G::compose(G::exp(typename G::Tangent(s * x)), G::exp(e)));
    in.t.push_back(0.1 * i);
    in.w.push_back(1.0);
  }
  return in;
}

// The input classes, keyed by the table's column names.
template <class G>
std::map<std::string, Input<G>> input_classes() {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr double inf = std::numeric_limits<double>::infinity();
  const Input<G> valid = valid_input<G>();
  std::map<std::string, Input<G>> classes;
  // `valid` with one change.
  const auto variant = [&](const std::string& name, const auto& change) {
    Input<G> in = valid;
    change(in);
    classes[name] = std::move(in);
  };
  const auto each = [](std::vector<double>& values, const auto& value_at) {
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = value_at(double(i));
  };
  variant("valid", [](Input<G>&) {});
  variant("nan_obs", [&](Input<G>& in) { in.f[3](0, 1) = nan; });
  variant("inf_obs", [&](Input<G>& in) { in.f[3](0, 1) = inf; });
  // Determinant -1 (SO3, SE3's rotation) or negative (GL+(3)).
  variant("non_element", [](Input<G>& in) { in.f[3].row(0) *= -1.0; });
  classes["empty"] = Input<G>{};
  variant("single", [](Input<G>& in) {
    in.f.resize(1);
    in.t.resize(1);
    in.w.resize(1);
  });
  variant("nan_cov", [&](Input<G>& in) { in.t[3] = nan; });
  variant("inf_cov", [&](Input<G>& in) { in.t[3] = inf; });
  variant("equal_cov", [&](Input<G>& in) { each(in.t, [](double) { return 2.0; }); });
  // A range double holds but a velocity over it does not (1.5e-299).
  variant("tiny_range", [&](Input<G>& in) { each(in.t, [](double i) { return 1e-300 * i; }); });
  // EuRoC nanoseconds as doubles: the same data, 5 ms apart, at 1.4e18.
  variant("ns_offset",
          [&](Input<G>& in) { each(in.t, [](double i) { return 1.4e18 + 5e6 * i; }); });
  variant("short_cov", [](Input<G>& in) { in.t.pop_back(); });
  variant("neg_weight", [](Input<G>& in) { in.w[3] = -1.0; });
  variant("nan_weight", [&](Input<G>& in) { in.w[3] = nan; });
  variant("zero_weights", [&](Input<G>& in) { each(in.w, [](double) { return 0.0; }); });
  variant("huge_weights", [&](Input<G>& in) { each(in.w, [](double) { return 1e308; }); });
  return classes;
}

// An input class the entry point does not take: weights for an entry point
// without weights, covariates for one without covariates.
bool about_weights(const std::string& input) {
  return input.find("weight") != std::string::npos;
}
bool about_covariates(const std::string& input) {
  return input.find("_cov") != std::string::npos || input == "tiny_range" || input == "ns_offset";
}

template <class G>
bool finite_element(const typename G::Element& g) {
  return g.allFinite();
}

template <class G>
bool finite_geodesic(const bireg::Geodesic<G>& geodesic, const std::vector<double>& t) {
  for (const double s : t)
    if (!finite_element<G>(geodesic(s))) return false;
  return true;
}

template <class G>
bool finite_fit(const bireg::RegressionResult<G>& fit, const std::vector<double>& t) {
  if (!fit.geodesic || !finite_geodesic<G>(*fit.geodesic, t)) return false;
  for (const auto& r : fit.residuals)
    if (!r.allFinite()) return false;
  return fit.geodesic->body_velocity().allFinite();
}

template <class G>
Observed from_fit(const bireg::RegressionResult<G>& fit, const std::vector<double>& t) {
  if (fit.status == bireg::Status::invalid_input) return refused(fit.message);
  if (!fit.ok()) return failed(fit.message.empty() ? to_string(fit.status) : fit.message);
  return answered(finite_fit<G>(fit, t));
}

// ---- the entry points, the table's rows --------------------------------------

template <class G>
Observed run_fit(const std::string&, const Input<G>& in) {
  return from_fit<G>(bireg::GeodesicRegression<G>().fit(in.f, in.t, in.w), in.t);
}

template <class G>
Observed run_fit_from(const std::string&, const Input<G>& in) {
  const std::pair<typename G::Element, typename G::Element> start{G::identity(), G::identity()};
  return from_fit<G>(bireg::GeodesicRegression<G>().fit_from(start, in.f, in.t, in.w), in.t);
}

template <class G>
Observed run_mean(const std::string& input, const Input<G>& in) {
  if (about_covariates(input)) return kNotApplicable;
  const auto m = bireg::mean<G>(in.f, in.w);
  if (m.status == bireg::Status::invalid_input) return refused(m.message);
  if (!m.ok()) return failed(m.message.empty() ? to_string(m.status) : m.message);
  bool finite = m.mean && finite_element<G>(*m.mean);
  for (const auto& r : m.residuals)
    finite = finite && r.allFinite();
  return answered(finite);
}

template <class G>
Observed run_covariance(const std::string&, const Input<G>& in) {
  const auto fit = bireg::GeodesicRegression<G>().fit(in.f, in.t, in.w);
  if (!fit.ok()) return from_fit<G>(fit, in.t);
  const auto c = bireg::covariance(fit, in.t, in.w);
  if (c.status == bireg::CovarianceStatus::invalid_input) return refused(c.message);
  if (c.status != bireg::CovarianceStatus::defined) return failed(c.message);
  const double t_mid = 0.5 * (in.t.front() + in.t.back());
  return answered(c.endpoints.allFinite() && bireg::velocity_covariance(c).allFinite() &&
                  bireg::pose_covariance(c, t_mid).allFinite());
}

template <class G>
Observed run_trend_test(const std::string&, const Input<G>& in) {
  bireg::TrendTestOptions options;
  options.permutations = 19;
  const auto test = bireg::trend_test(bireg::GeodesicRegression<G>(), in.f, in.t, in.w, options);
  if (test.status == bireg::Status::invalid_input) return refused(test.message);
  if (!test.ok()) return failed(test.message);
  return answered(std::isfinite(test.statistic) && std::isfinite(test.p_value));
}

template <class G>
Observed run_robust(const std::string&, const Input<G>& in) {
  const auto robust = bireg::RobustGeodesicRegression<G>().fit(in.f, in.t, in.w);
  // fit_failed because the plain fit refused the data is a refusal.
  if (robust.status == bireg::RobustStatus::invalid_input ||
      (robust.status == bireg::RobustStatus::fit_failed &&
       robust.fit.status == bireg::Status::invalid_input)) {
    return refused(robust.message);
  }
  if (!robust.ok()) return failed(robust.message);
  bool finite = finite_fit<G>(robust.fit, in.t);
  for (const double u : robust.robust_weights)
    finite = finite && std::isfinite(u);
  return answered(finite);
}

template <class G>
Observed run_smooth_at(const std::string& input, const Input<G>& in) {
  if (about_weights(input)) return kNotApplicable;
  // A fifth of the covariates' range (ns_offset: 1.5e7 ns), or 0.3.
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 0.3;
  if (!in.t.empty() && std::isfinite(in.t.back() - in.t.front()) && in.t.back() > in.t.front())
    options.bandwidth = 0.2 * (in.t.back() - in.t.front());
  // At a covariate of the data (ns_offset: its own clock), or at 0.
  const double query = in.t.empty() ? 0.0 : in.t[in.t.size() / 2];
  const auto estimates = bireg::LocalGeodesicRegression<G>(options).smooth_at(in.f, in.t, {query});
  if (estimates.size() != 1) return failed("smooth_at returned no estimate");
  const auto& e = estimates[0];
  if (e.status == bireg::Status::invalid_input) return refused(e.message);
  if (!e.ok()) return failed(e.message);
  return answered(finite_element<G>(e.pose) && e.velocity.allFinite() &&
                  e.velocity_error.allFinite());
}

template <class G>
Observed run_select_bandwidth(const std::string& input, const Input<G>& in) {
  if (about_weights(input)) return kNotApplicable;
  // The grid the tools' --bandwidth auto uses (empty where the covariates
  // give none: select_bandwidth then refuses).
  const auto selection =
      bireg::select_bandwidth<G>(in.f, in.t, {}, bireg::auto_bandwidth_grid(in.t));
  if (!selection.ok()) return refused(selection.message);
  return answered(std::isfinite(selection.bandwidth) &&
                  std::isfinite(selection.velocity_bandwidth));
}

template <class G>
Observed run_static_or_geodesic(const std::string& input, const Input<G>& in) {
  if (about_weights(input)) return kNotApplicable;
  const auto selection = bireg::select_static_or_geodesic<G>(in.f, in.t);
  if (selection.status == bireg::SelectionStatus::invalid_input) return refused(selection.message);
  if (!selection.ok()) return failed(selection.message);
  bool finite = true;
  for (const auto& candidate : selection.candidates)
    if (candidate.fitted) finite = finite && std::isfinite(candidate.criterion);
  if (selection.geodesic) finite = finite && finite_geodesic<G>(*selection.geodesic, in.t);
  if (selection.static_element) finite = finite && finite_element<G>(*selection.static_element);
  return answered(finite);
}

template <class G>
Observed run_explained_variance(const std::string&, const Input<G>& in) {
  const auto fit = bireg::GeodesicRegression<G>().fit(in.f, in.t, in.w);
  if (!fit.ok()) return from_fit<G>(fit, in.t);
  const auto m = bireg::mean<G>(in.f, in.w);
  const auto r2 = bireg::explained_variance(fit, m, in.w);
  if (!r2.defined) return failed(r2.message);
  return answered(std::isfinite(r2.euclidean) && std::isfinite(r2.generalized));
}

// The first half of the observations against the second.
template <class G>
Observed run_two_sample(const std::string& input, const Input<G>& in) {
  if (about_weights(input) || about_covariates(input)) return kNotApplicable;
  const std::size_t half = in.f.size() / 2;
  const std::vector<typename G::Element> a(in.f.begin(), in.f.begin() + std::ptrdiff_t(half));
  const std::vector<typename G::Element> b(in.f.begin() + std::ptrdiff_t(half), in.f.end());
  bireg::TwoSampleOptions<double> options;
  options.permutations = 19;
  const auto test = bireg::two_sample_test<G>(a, b, options);
  if (test.status == bireg::Status::invalid_input) return refused(test.message);
  if (!test.ok()) return failed(test.message);
  return answered(std::isfinite(test.value) && std::isfinite(test.p_value) && test.mean_a &&
                  finite_element<G>(*test.mean_a) && test.mean_b &&
                  finite_element<G>(*test.mean_b));
}

// Two subjects, the first half of the data and the second.
template <class G>
Observed run_fit_many(const std::string& input, const Input<G>& in) {
  if (about_weights(input)) return kNotApplicable;
  std::vector<bireg::SubjectData<G>> subjects(2);
  for (std::size_t i = 0; i < in.f.size(); ++i) {
    auto& subject = subjects[2 * i < in.f.size() ? 0 : 1];
    subject.observations.push_back(in.f[i]);
    if (i < in.t.size()) subject.covariates.push_back(in.t[i]);
  }
  const auto fits = bireg::fit_many(bireg::GeodesicRegression<G>(), subjects);
  if (fits.status == bireg::Status::invalid_input) return refused(fits.message);
  if (!fits.ok()) return failed(fits.message);
  bool finite = std::isfinite(fits.t0) && std::isfinite(fits.t1);
  for (const auto& trend : fits.trends)
    finite = finite && trend.first.allFinite() && trend.second.allFinite();
  return answered(finite);
}

// SE(3) poses only (the motion models are rigid motions).
template <class G>
Observed run_motion_model(const std::string& input, const Input<G>& in) {
  if constexpr (!std::is_same_v<G, bireg::SE3d>) {
    (void)in;
    return kNotApplicable;
  } else {
    if (about_weights(input)) return kNotApplicable;
    const auto selection = bireg::select_motion_model(in.f, in.t);
    if (selection.status == bireg::SelectionStatus::invalid_input)
      return refused(selection.message);
    if (!selection.ok()) return failed(selection.message);
    bool finite = selection.prediction.has_value();
    for (const auto& candidate : selection.candidates)
      if (candidate.fitted) finite = finite && std::isfinite(candidate.criterion);
    for (const double t : in.t)
      finite = finite && (*selection.prediction)(t).allFinite();
    return answered(finite);
  }
}

template <class G>
using EntryPoint = Observed (*)(const std::string&, const Input<G>&);

template <class G>
std::map<std::string, EntryPoint<G>> entry_points() {
  return {{"fit", &run_fit<G>},
          {"fit_from", &run_fit_from<G>},
          {"mean", &run_mean<G>},
          {"covariance", &run_covariance<G>},
          {"trend_test", &run_trend_test<G>},
          {"RobustGeodesicRegression::fit", &run_robust<G>},
          {"LocalGeodesicRegression::smooth_at", &run_smooth_at<G>},
          {"select_bandwidth", &run_select_bandwidth<G>},
          {"select_static_or_geodesic", &run_static_or_geodesic<G>},
          {"explained_variance", &run_explained_variance<G>},
          {"two_sample_test", &run_two_sample<G>},
          {"fit_many", &run_fit_many<G>},
          {"select_motion_model", &run_motion_model<G>}};
}

// ---- the table, read from docs/ ------------------------------------------------

struct Table {
  std::vector<std::string> columns;                                  // input classes
  std::map<std::string, std::vector<std::string>> rows;              // entry point -> cells
  std::map<std::string, std::map<std::string, std::string>> groups;  // exceptions: see cell()
};

std::vector<std::string> split_row(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line.substr(1));
  std::string cell;
  while (std::getline(stream, cell, '|')) {
    const auto first = cell.find_first_not_of(' ');
    const auto last = cell.find_last_not_of(' ');
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
  }
  return cells;
}

std::string unquote(const std::string& cell) {
  if (cell.size() >= 2 && cell.front() == '`' && cell.back() == '`')
    return cell.substr(1, cell.size() - 2);
  return cell;
}

Table read_table() {
  const std::string path = BIREG_TEST_DATA_DIR "/../../docs/hostile_input.md";
  std::ifstream file(path);
  REQUIRE(file.good());
  Table table;
  std::string line;
  bool in_section = false;
  while (std::getline(file, line)) {
    if (line.rfind("## ", 0) == 0) {
      in_section = line == "## Every entry point against every input class";
      continue;
    }
    if (!in_section || line.rfind("| ", 0) != 0 || line.rfind("|---", 0) == 0) continue;
    const std::vector<std::string> cells = split_row(line);
    if (cells.front() == "entry point") {
      for (std::size_t k = 1; k < cells.size(); ++k)
        table.columns.push_back(unquote(cells[k]));
      continue;
    }
    table.rows[unquote(cells.front())] = std::vector<std::string>(cells.begin() + 1, cells.end());
  }
  return table;
}

// A cell is an outcome, or "outcome; Group: outcome" where one group's differs.
std::string expected_for(const std::string& cell, const std::string& group) {
  const auto semicolon = cell.find("; ");
  if (semicolon == std::string::npos) return cell;
  const std::string exception = cell.substr(semicolon + 2);
  const auto colon = exception.find(": ");
  if (exception.substr(0, colon) == group) return exception.substr(colon + 2);
  return cell.substr(0, semicolon);
}

template <class G>
void check_group(const Table& table, const std::string& group) {
  const auto classes = input_classes<G>();
  const auto points = entry_points<G>();
  // The table names every entry point and every input class, and nothing else.
  REQUIRE(table.rows.size() == points.size());
  REQUIRE(table.columns.size() == classes.size());
  for (const auto& [entry, cells] : table.rows) {
    INFO("entry point " << entry);
    REQUIRE(points.count(entry) == 1);
    REQUIRE(cells.size() == table.columns.size());
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const std::string& input = table.columns[k];
      INFO(group << ", input class " << input);
      REQUIRE(classes.count(input) == 1);
      const Observed observed = points.at(entry)(input, classes.at(input));
      // Whatever is documented: a refusal or a status says why, an answer
      // is finite.
      if (observed.outcome == Outcome::refused || observed.outcome == Outcome::status) {
        CHECK_FALSE(observed.message.empty());
      }
      CHECK(observed.finite);
      INFO("message: " << observed.message);
      CHECK(name(observed.outcome) == expected_for(cells[k], group));
    }
  }
}

}  // namespace

TEST_CASE("Every entry point against every input class answers as docs/hostile_input.md says",
          "[hostile]") {
  const Table table = read_table();
  REQUIRE_FALSE(table.rows.empty());
  SECTION("SO3") {
    check_group<bireg::SO3d>(table, "SO3");
  }
  SECTION("SE3") {
    check_group<bireg::SE3d>(table, "SE3");
  }
  SECTION("GLp3") {
    check_group<GLp3d>(table, "GLp3");
  }
}
