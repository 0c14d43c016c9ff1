// Hostile input above fit() (issues 36 and 37): model selection on NaN,
// non-element and overflowing poses, covariates that are not finite or
// far from zero (EuRoC nanoseconds as doubles), enumerations out of range,
// worker threads the system refuses, and quantiles at huge degrees of
// freedom. Each entry point refuses with a status and a message naming the
// observation, or answers correctly; none aborts or returns NaN.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <random>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "bireg/testing/random.hpp"
#include "catch.hpp"

namespace {

using Pose = Eigen::Matrix4d;
using bireg::SE3d;
using bireg::SO3d;

}  // namespace

namespace {

using Regression = bireg::GeodesicRegression<SE3d>;

// n poses about a geodesic (test_threads.cpp's scene): exp(t x + noise).
void scattered_poses(std::size_t n, std::vector<Pose>& f, std::vector<double>& t) {
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> uniform(-1, 1);
  SE3d::Tangent x;
  for (int k = 0; k < SE3d::dof; ++k)
    x[k] = uniform(rng);
  for (std::size_t i = 0; i < n; ++i) {
    SE3d::Tangent noise;
    for (int k = 0; k < SE3d::dof; ++k)
      noise[k] = 0.2 * uniform(rng);
    const double covariate = static_cast<double>(i) / static_cast<double>(n - 1);
    f.push_back(SE3d::exp(covariate * x + noise));
    t.push_back(covariate);
  }
}

bool identical(const Regression::Result& a, const Regression::Result& b) {
  if (a.status != b.status || a.iterations != b.iterations || !a.geodesic || !b.geodesic) {
    return false;
  }
  if (a.geodesic->start() != b.geodesic->start() || a.geodesic->end() != b.geodesic->end()) {
    return false;
  }
  if (a.residuals.size() != b.residuals.size()) return false;
  for (std::size_t i = 0; i < a.residuals.size(); ++i)
    if (a.residuals[i] != b.residuals[i]) return false;
  return a.step_norms == b.step_norms;
}

Regression::Result fit_with_threads(int threads, const std::vector<Pose>& f,
                                    const std::vector<double>& t) {
  Regression::Options options;
  options.threads = threads;
  return Regression(options).fit(f, t);
}

// How many threads this process can have running at once, up to `most`.
int startable_threads(int most) {
  std::mutex mutex;
  std::condition_variable release;
  bool done = false;
  std::vector<std::thread> started;
  for (int k = 0; k < most; ++k) {
    try {
      started.emplace_back([&] {
        std::unique_lock<std::mutex> lock(mutex);
        release.wait(lock, [&] { return done; });
      });
    } catch (const std::system_error&) {
      break;
    }
  }
  {
    const std::lock_guard<std::mutex> lock(mutex);
    done = true;
  }
  release.notify_all();
  for (std::thread& thread : started)
    thread.join();
  return static_cast<int>(started.size());
}

// Exit codes of the child below.
constexpr int kChildSame = 0, kChildDifferent = 1, kChildFitFailed = 2, kChildLimitIgnored = 3,
              kChildNoLimit = 4;

}  // namespace

TEST_CASE("a fit whose worker threads the system refuses still answers (issue 37 item 3)",
          "[hostile][threads]") {
  // 40000 observations: 10 chunks, so threads = 8 asks for 7 workers. In a
  // forked child the process limit is lowered to 4 tasks (as root, whom
  // RLIMIT_NPROC does not bind, the child first becomes the user nobody,
  // which owns no other process here): the child and at most 3 workers.
  // The fit must return the serial answer bit for bit, not terminate.
  std::vector<Pose> f;
  std::vector<double> t;
  scattered_poses(40000, f, t);
  const Regression::Result serial = fit_with_threads(1, f, t);
  REQUIRE(serial.ok());
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(kChildNoLimit);
    const rlimit limit{4, 4};
    if (setrlimit(RLIMIT_NPROC, &limit) != 0) _exit(kChildNoLimit);
    if (startable_threads(8) >= 7) _exit(kChildLimitIgnored);
    const Regression::Result limited = fit_with_threads(8, f, t);
    if (!limited.ok()) _exit(kChildFitFailed);
    _exit(identical(serial, limited) ? kChildSame : kChildDifferent);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  INFO("the child " << (WIFSIGNALED(status) ? "was killed by signal " : "exited with ")
                    << (WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status)));
  REQUIRE(WIFEXITED(status));
  if (WEXITSTATUS(status) == kChildLimitIgnored || WEXITSTATUS(status) == kChildNoLimit) {
    WARN("the process limit could not be lowered here: covered by the test seam below only");
    return;
  }
  REQUIRE(WEXITSTATUS(status) == kChildSame);
}

TEST_CASE("workers are capped and a refused worker leaves fewer (issue 37 item 3)",
          "[hostile][threads]") {
  // The cap: never more workers than tasks minus one, nor than kMaxWorkers.
  REQUIRE(bireg::ChunkPool(10000, 3).threads() == 3);
  REQUIRE(bireg::ChunkPool(10000, 1).threads() == 1);
  REQUIRE(bireg::ChunkPool(10000).threads() == bireg::kMaxThreads);
  REQUIRE(bireg::kMaxThreads == 256);

  // The seam: the third worker's start fails as a refused std::thread does.
  std::vector<Pose> f;
  std::vector<double> t;
  scattered_poses(40000, f, t);
  const Regression::Result serial = fit_with_threads(1, f, t);
  REQUIRE(serial.ok());
  for (const std::size_t refused_from : {std::size_t(0), std::size_t(2)}) {
    CAPTURE(refused_from);
    static std::size_t first_refused;
    first_refused = refused_from;
    bireg::parallel_detail::refuse_worker_for_testing = [](std::size_t worker) {
      return worker >= first_refused;
    };
    const int threads = bireg::ChunkPool(8, 100).threads();
    const Regression::Result limited = fit_with_threads(8, f, t);
    bireg::parallel_detail::refuse_worker_for_testing = nullptr;
    REQUIRE(threads == static_cast<int>(refused_from) + 1);
    REQUIRE(limited.ok());
    REQUIRE(identical(serial, limited));
  }
  // 10000 threads asked for on 8200 observations (2 chunks): one worker.
  std::vector<Pose> g(f.begin(), f.begin() + 8200);
  std::vector<double> u(t.begin(), t.begin() + 8200);
  REQUIRE(identical(fit_with_threads(1, g, u), fit_with_threads(10000, g, u)));
}

TEST_CASE("Hotelling's quantile is never NaN where p and nu are both huge",
          "[hostile][distributions]") {
  // nu p / (nu - p + 1) = inf while F(1e300, 1)'s quantile is 0: the
  // product would be NaN (fuzz_statistics' input).
  const auto q = bireg::hotelling_quantile(0.73460570541357173, 1e300, 1e300);
  CHECK((!q || (!std::isnan(*q) && *q >= 0)));
  CHECK(!bireg::hotelling_quantile(0.73460570541357173, 1e300, 1e300).has_value());
}

TEST_CASE("quantiles at huge degrees of freedom are the chi-square limit (issue 37 item 14)",
          "[hostile][distributions]") {
  const double level = 0.95;
  const double chi6 = *bireg::chi_square_quantile(level, 6);
  const double chi12 = *bireg::chi_square_quantile(level, 12);
  const auto relative = [](double value, double reference) {
    return std::abs(value - reference) / reference;
  };
  // F(d1, d2) = (chi2_{d1} / d1) / (chi2_{d2} / d2), chi2_{d2} / d2 -> 1
  // with standard deviation sqrt(2 / d2): at d2 >= 1e16 the limit holds to
  // ~1e-15, so 1e-12 relative leaves the bisection's rounding room.
  for (const double nu : {1e16, 1e100, 1e300}) {
    CAPTURE(nu);
    REQUIRE(relative(*bireg::f_quantile(level, 6, nu), chi6 / 6) < 1e-12);
    REQUIRE(relative(*bireg::hotelling_quantile(level, 6, nu), chi6) < 1e-12);
    REQUIRE(relative(*bireg::ellipsoid_quantile(level, 6, 1, nu), chi6) < 1e-12);
    REQUIRE(relative(*bireg::ellipsoid_quantile(level, 6, 2, nu), chi12) < 1e-12);
  }
  // Large but not huge d2: F_{0.95}(6, d2) computed independently of
  // bireg (mpmath, 40 digits: findroot of betainc(3, d2/2, 0, 6f/(6f + d2),
  // regularized) - 0.95). The first correction of the chi-square limit
  // leaves O(x^3 / d2^2) ~ 1e-13 relative at d2 = 1e7, so 1e-12 is rounding
  // room; the incomplete beta's continued fraction was off by 1e-10 at 1e8
  // and 2e-6 at 1e12 (too few terms for b = d2/2).
  struct Reference {
    double d2, quantile;
  };
  for (const Reference r :
       {Reference{1e7, 2.098598775471848116482114}, Reference{1e8, 2.09859796410876535233364},
        Reference{1e10, 2.098597874858844250292262}, Reference{1e12, 2.098597873966345057290078}}) {
    CAPTURE(r.d2);
    REQUIRE(relative(*bireg::f_quantile(level, 6, r.d2), r.quantile) < 1e-12);
  }
}

namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("enumerations out of range are refused with a message (issue 37 item 2)",
          "[hostile][enumerations]") {
  std::mt19937 rng(2);
  std::normal_distribution<double> normal(0.0, 0.05);
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<double> times;
  for (int i = 0; i < 30; ++i) {
    const double t = i / 29.0;
    const Eigen::Vector3d e = bireg::testing::draw_vector<Eigen::Vector3d>(rng, normal);
    rotations.push_back(SO3d::exp(Eigen::Vector3d(0.5 * t, 0.0, -0.3 * t) + e));
    times.push_back(t);
  }

  SECTION("Loss") {
    bireg::RobustOptions<double> options;
    options.loss = static_cast<bireg::Loss>(7);
    const auto robust = bireg::RobustGeodesicRegression<SO3d>(options).fit(rotations, times);
    CAPTURE(robust.message);
    REQUIRE(robust.status == bireg::RobustStatus::invalid_input);
    REQUIRE(contains(robust.message, "loss"));
    options.loss = bireg::Loss::tukey;
    REQUIRE(bireg::RobustGeodesicRegression<SO3d>(options).fit(rotations, times).status ==
            bireg::RobustStatus::converged);
  }
  SECTION("CovarianceFlavour") {
    const auto fit = bireg::GeodesicRegression<SO3d>().fit(rotations, times);
    REQUIRE(fit.ok());
    for (const int flavour : {2, 7, -1}) {
      CAPTURE(flavour);
      const auto c =
          bireg::covariance(fit, times, {}, static_cast<bireg::CovarianceFlavour>(flavour));
      CAPTURE(c.message);
      REQUIRE(c.status == bireg::CovarianceStatus::invalid_input);
      REQUIRE(contains(c.message, "flavour"));
    }
    REQUIRE(bireg::covariance(fit, times, {}, bireg::CovarianceFlavour::robust).defined());
  }
  SECTION("PoseGroup") {
    std::vector<Pose> poses(rotations.size(), Pose::Identity());
    for (std::size_t i = 0; i < poses.size(); ++i)
      poses[i].topLeftCorner<3, 3>() = rotations[i];
    bireg::ModelSelectionOptions options;
    options.group = static_cast<bireg::PoseGroup>(5);
    const bireg::ModelSelection selection = bireg::select_motion_model(poses, times, options);
    CAPTURE(selection.message);
    REQUIRE(selection.status == bireg::SelectionStatus::invalid_input);
    REQUIRE(contains(selection.message, "group"));
    REQUIRE_FALSE(selection.recommended);
    REQUIRE_FALSE(bireg::fit_motion_model(bireg::MotionModel::static_pose, poses, times,
                                          static_cast<bireg::PoseGroup>(5)));
  }
}

namespace {

using bireg::SelectionStatus;

// Issue 36's newcomer data: 20 poses with rotation exp((0.05 i, 0.01 (i mod
// 3), 0)) and translation (0.1 i + 0.01 (i mod 2), 0.002 (i mod 5), 0), t = i.
void newcomer_poses(std::vector<Pose>& poses, std::vector<double>& times) {
  for (int i = 0; i < 20; ++i) {
    Pose f = Pose::Identity();
    f.topLeftCorner<3, 3>() = SO3d::exp(Eigen::Vector3d(0.05 * i, 0.01 * (i % 3), 0));
    f.topRightCorner<3, 1>() = Eigen::Vector3d(0.1 * i + 0.01 * (i % 2), 0.002 * (i % 5), 0);
    poses.push_back(f);
    times.push_back(i);
  }
}

// Every number a selection reports is finite (the contract: never NaN).
void require_finite_report(const bireg::ModelSelection& selection) {
  for (const bireg::CandidateReport& c : selection.candidates) {
    CAPTURE(bireg::to_string(c.model));
    REQUIRE(std::isfinite(c.criterion));
    REQUIRE(std::isfinite(c.log_det));
    REQUIRE(std::isfinite(c.rotation_rms_degrees));
    REQUIRE(std::isfinite(c.translation_rms));
    REQUIRE(std::isfinite(c.log_scale_rms));
    if (c.cv_error) REQUIRE(std::isfinite(*c.cv_error));
  }
}

}  // namespace

TEST_CASE("model selection refuses a NaN pose, naming it (issue 36)", "[hostile][selection]") {
  std::vector<Pose> poses;
  std::vector<double> times;
  newcomer_poses(poses, times);
  // The clean data are selected (the reproduction is about the NaN alone).
  REQUIRE(bireg::select_motion_model(poses, times).ok());
  poses[3](0, 3) = std::numeric_limits<double>::quiet_NaN();
  const bireg::ModelSelection selection = bireg::select_motion_model(poses, times);
  CAPTURE(selection.message);
  REQUIRE(selection.status == SelectionStatus::invalid_input);
  REQUIRE_FALSE(selection.ok());
  REQUIRE(selection.bad_index == 3);
  REQUIRE(contains(selection.message, "observation 3"));
  REQUIRE_FALSE(selection.recommended);
  REQUIRE_FALSE(selection.prediction);
}

TEST_CASE("model selection names a pose that is not a rigid motion (issues 36 and 37)",
          "[hostile][selection]") {
  std::vector<Pose> clean;
  std::vector<double> times;
  newcomer_poses(clean, times);
  struct Damage {
    int row, column;
    double value;
  };
  // A rotation block that is not a rotation, and the last rows (0, 0, 0.5, 1)
  // and (0, 0, 0, 2) of issue 37 item 12.
  for (const Damage damage : {Damage{0, 0, 1.1}, Damage{3, 2, 0.5}, Damage{3, 3, 2.0}}) {
    for (const int observation : {0, 7, 19}) {
      CAPTURE(damage.row, damage.column, observation);
      std::vector<Pose> poses = clean;
      poses[static_cast<std::size_t>(observation)](damage.row, damage.column) = damage.value;
      const bireg::ModelSelection selection = bireg::select_motion_model(poses, times);
      CAPTURE(selection.message);
      REQUIRE(selection.status == SelectionStatus::invalid_input);
      REQUIRE(selection.bad_index == observation);
      REQUIRE(contains(selection.message, "observation " + std::to_string(observation)));
      REQUIRE_FALSE(selection.recommended);
      // A sub-model that splits off the rotation block and the positions
      // would not see the last row: fit_motion_model refuses as well.
      REQUIRE_FALSE(bireg::fit_motion_model(bireg::MotionModel::rotation_only, poses, times));
      REQUIRE_FALSE(bireg::fit_motion_model(bireg::MotionModel::rotation_and_line, poses, times));
    }
  }
  REQUIRE(bireg::fit_motion_model(bireg::MotionModel::rotation_only, clean, times));
}

TEST_CASE("model selection on overflowing translations reports a status, never aborts (issue 37)",
          "[hostile][selection]") {
  // Issue 37 item 1: exp((0.1 i, 0.02 i, 0, 0.01 i + 0.01 sin 3i, 0.02 i,
  // 0.03 i)) ((rho, omega) order), t = 0.1 i, i < 30, translations times
  // 1e200 or 1e300, or one translation entry 1e308. Residual translations
  // are then ~1e198 or larger: their squares overflow, no candidate can be
  // scored, and the documented outcome is no_candidate with a message.
  std::vector<Pose> base;
  std::vector<double> times;
  for (int i = 0; i < 30; ++i) {
    SE3d::Tangent xi;
    xi << 0.1 * i, 0.02 * i, 0, 0.01 * i + 0.01 * std::sin(3.0 * i), 0.02 * i, 0.03 * i;
    base.push_back(SE3d::exp(xi));
    times.push_back(0.1 * i);
  }
  const bireg::ModelSelection clean = bireg::select_motion_model(base, times);
  REQUIRE(clean.ok());
  require_finite_report(clean);

  std::vector<std::vector<Pose>> cases;
  for (const double scale : {1e200, 1e300}) {
    std::vector<Pose> poses = base;
    for (Pose& f : poses)
      f.topRightCorner<3, 1>() *= scale;
    cases.push_back(poses);
  }
  cases.push_back(base);
  cases.back()[11](1, 3) = 1e308;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    CAPTURE(k);
    for (const int threads : {1, 3}) {
      bireg::ModelSelectionOptions options;
      options.threads = threads;
      const bireg::ModelSelection selection = bireg::select_motion_model(cases[k], times, options);
      CAPTURE(selection.message);
      REQUIRE(selection.status == SelectionStatus::no_candidate);
      REQUIRE_FALSE(selection.recommended);
      REQUIRE_FALSE(selection.prediction);
      REQUIRE_FALSE(selection.message.empty());
      for (const bireg::CandidateReport& c : selection.candidates) {
        REQUIRE_FALSE(c.fitted);
        REQUIRE_FALSE(c.recommended);
        REQUIRE_FALSE(c.note.empty());
      }
      require_finite_report(selection);
    }
  }
}

TEST_CASE("static or geodesic refuses covariates that are not finite or overflow (issue 37)",
          "[hostile][selection]") {
  std::mt19937 rng(37);
  std::normal_distribution<double> normal(0.0, 0.05);
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<double> clean_times;
  for (int i = 0; i < 30; ++i) {
    rotations.push_back(SO3d::exp(bireg::testing::draw_vector<Eigen::Vector3d>(rng, normal)));
    clean_times.push_back(i);
  }
  REQUIRE(bireg::select_static_or_geodesic<SO3d>(rotations, clean_times).ok());
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), inf, -inf, 1e308, -1e308}) {
    for (const int index : {0, 13, 29}) {
      CAPTURE(bad, index);
      std::vector<double> times = clean_times;
      times[static_cast<std::size_t>(index)] = bad;
      const auto selection = bireg::select_static_or_geodesic<SO3d>(rotations, times);
      CAPTURE(selection.message);
      REQUIRE(selection.status == SelectionStatus::invalid_input);
      REQUIRE(selection.bad_index == index);
      REQUIRE(contains(selection.message, "covariate " + std::to_string(index)));
      REQUIRE_FALSE(selection.recommended);
      // The same refusal in the motion models' selection.
      std::vector<Pose> poses(rotations.size(), Pose::Identity());
      for (std::size_t i = 0; i < poses.size(); ++i)
        poses[i].topLeftCorner<3, 3>() = rotations[i];
      const bireg::ModelSelection motion = bireg::select_motion_model(poses, times);
      REQUIRE(motion.status == SelectionStatus::invalid_input);
      REQUIRE(motion.bad_index == index);
    }
  }
}

TEST_CASE("static data at nanosecond covariates far from zero are static (issue 37 item 11)",
          "[hostile][selection]") {
  // 40 observations of one rotation with noise e_i ~ N(0, s^2 I_3), s =
  // 0.02 / sqrt(3), so that E|e|^2 = 0.02^2; covariates offset + 5e6 i
  // (EuRoC timestamps in nanoseconds). About the mean the static residual
  // RMS^2 is s^2 chi2_{3(N-1)} / N: expectation 0.02^2 (N-1)/N (RMS
  // 0.0197) and a relative standard deviation of the RMS of
  // sqrt(2 / (3 (N-1))) / 2 = 0.065, so 0.02 +- 0.005 is about 4 standard
  // deviations. The static candidate does not use the covariates: its RMS
  // must be the same at every offset, to rounding (the constant geodesic
  // (m, m) moves by |log(m^{-1} m)| ~ 1e-15 over its interval).
  constexpr int n = 40;
  const double s = 0.02 / std::sqrt(3.0);
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, s);
  const Eigen::Matrix3d centre = SO3d::exp(Eigen::Vector3d(0.4, -0.7, 1.1));
  std::vector<Eigen::Matrix3d> rotations;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d e = bireg::testing::draw_vector<Eigen::Vector3d>(rng, normal);
    rotations.push_back(SO3d::compose(centre, SO3d::exp(e)));
  }
  const auto at_offset = [&](double offset) {
    std::vector<double> times;
    for (int i = 0; i < n; ++i)
      times.push_back(offset + 5e6 * i);
    return times;
  };
  const std::vector<double> plain_times = at_offset(0);
  const auto plain = bireg::select_static_or_geodesic<SO3d>(rotations, plain_times);
  REQUIRE(plain.ok());
  REQUIRE(plain.recommended == bireg::TrendModel::static_element);
  const double static_rms = plain.candidates[0].residual_rms;
  REQUIRE(std::abs(static_rms - 0.02) < 0.005);
  for (const double offset : {1e9, 1e12, 1.4e18}) {
    CAPTURE(offset);
    const std::vector<double> times = at_offset(offset);
    const auto selection = bireg::select_static_or_geodesic<SO3d>(rotations, times);
    CAPTURE(selection.message);
    REQUIRE(selection.ok());
    REQUIRE(selection.recommended == bireg::TrendModel::static_element);
    REQUIRE(selection.candidates[0].fitted);
    REQUIRE(std::abs(selection.candidates[0].residual_rms - 0.02) < 0.005);
    REQUIRE(std::abs(selection.candidates[0].residual_rms - static_rms) < 1e-12);
    // The geodesic candidate is returned in the user's covariates. At
    // 1.4e18 the covariates are rounded to multiples of 256 ns: the
    // normalised t moves by at most 128 / (39 * 5e6) = 7e-7, and the fitted
    // velocity of static data (~0.01 rad over the range) turns that into
    // 1e-8 rad; 1e-6 rad bounds it with room.
    REQUIRE(selection.geodesic);
    for (int i = 0; i < n; i += 13) {
      const Eigen::Matrix3d here = (*selection.geodesic)(times[static_cast<std::size_t>(i)]);
      const Eigen::Matrix3d there = (*plain.geodesic)(plain_times[static_cast<std::size_t>(i)]);
      REQUIRE(SO3d::log(SO3d::compose(SO3d::inverse(there), here)).norm() < 1e-6);
    }
  }
}
