// The statistics layer: the bi-invariant mean, a fit's covariance,
// confidence band, explained variance and trend test, and local
// regression with the automatic bandwidth. Each function calls the
// library's (statistics_impl.hpp) and converts; the GIL is released while
// it works.
#include <cstdint>
#include <string>

#include "statistics_impl.hpp"

namespace bireg_python {

void bind_statistics(nb::module_& m) {
  m.def(
      "mean",
      [](const std::string& group, const Stack& y, const Vector& w, double tolerance,
         int max_iterations) {
        return with_group(group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::mean(y, w, tolerance,
                                                                     max_iterations);
        });
      },
      nb::arg("group"), nb::arg("y"), nb::arg("weights"), nb::arg("tol"), nb::arg("max_iter"),
      "bireg::mean<G>: a dict with the mean, status, iterations, residuals.");
  m.def(
      "covariance",
      [](const FitHandle& h, const std::string& flavour) {
        return with_group(h.group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::covariance(h, flavour);
        });
      },
      nb::arg("fit"), nb::arg("flavour"),
      "bireg::covariance of a fit: endpoint, velocity and residual covariances.");
  m.def(
      "confidence_band",
      [](const FitHandle& h, const Vector& t, double level, const std::string& flavour) {
        return with_group(h.group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::confidence_band(h, t, level,
                                                                                flavour);
        });
      },
      nb::arg("fit"), nb::arg("t"), nb::arg("level"), nb::arg("flavour"),
      "Half-widths of the pose's confidence region per covariate: (M,) -> (M, d).");
  m.def(
      "score",
      [](const FitHandle& h, const Vector& t, const Stack& y) {
        return with_group(h.group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::score(h, t, y);
        });
      },
      nb::arg("fit"), nb::arg("t"), nb::arg("y"),
      "The generalised explained variance of the fitted geodesic on (t, y).");
  m.def(
      "trend_test",
      [](const FitHandle& h, int permutations, std::uint64_t seed, int threads) {
        return with_group(h.group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::trend_test(h, permutations, seed,
                                                                           threads);
        });
      },
      nb::arg("fit"), nb::arg("permutations"), nb::arg("seed"), nb::arg("threads"),
      "bireg::trend_test with the fit's options: statistic and p_value.");
  m.def(
      "smooth",
      [](const std::string& group, const Vector& t, const Stack& y, const Vector& queries,
         const std::string& kernel, double bandwidth, double velocity_bandwidth,
         int velocity_degree, int threads) {
        const auto options = statistics_detail::local_options(kernel, bandwidth, threads);
        if (!(velocity_bandwidth > 0) || !std::isfinite(velocity_bandwidth))
          refuse("velocity bandwidth must be a finite positive number");
        if (velocity_degree < 1 || velocity_degree > 3)
          refuse("velocity_degree must be 1, 2 or 3, got " + std::to_string(velocity_degree));
        return with_group(group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::smooth(
              t, y, queries, options, velocity_bandwidth, velocity_degree);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("y"), nb::arg("queries"), nb::arg("kernel"),
      nb::arg("bandwidth"), nb::arg("velocity_bandwidth"), nb::arg("velocity_degree"),
      nb::arg("threads"),
      "LocalGeodesicRegression<G>::smooth_at: pose, velocity, standard errors, status per query.");
  m.def(
      "select_bandwidth",
      [](const std::string& group, const Vector& t, const Stack& y, const std::string& kernel,
         int threads) {
        const auto options = statistics_detail::local_options(kernel, 1.0, threads);
        return with_group(group, [&](auto tag) {
          return GroupStatistics<typename decltype(tag)::type>::select_bandwidth(t, y, options);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("y"), nb::arg("kernel"), nb::arg("threads"),
      "bireg::select_bandwidth over auto_bandwidth_grid: the pose's and the velocity's "
      "bandwidths.");
}

}  // namespace bireg_python
