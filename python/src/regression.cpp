// The regression layer: fit() and what a fitted geodesic tells by itself
// (its endpoints, velocities, poses at new covariates, residuals and
// diagnostics). The GIL is released while the library works.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>

#include "fit_handle.hpp"

namespace bireg_python {
namespace {

bireg::RegressionOptions<double> regression_options(const std::string& solver,
                                                    const std::string& method, double tolerance,
                                                    int max_iterations, int threads) {
  bireg::RegressionOptions<double> options;
  options.solver = parse_choice(solver,
                                {bireg::Solver::gauss_newton, bireg::Solver::preconditioned,
                                 bireg::Solver::optimal_linear, bireg::Solver::paper},
                                "solver");
  options.method =
      parse_choice(method, {bireg::Method::exact, bireg::Method::series_adaptive}, "method");
  options.tolerance = tolerance;
  options.max_iterations = max_iterations;
  options.threads = threads;
  if (auto rejection = bireg::validate_options(options))
    throw nb::value_error(rejection->message.c_str());
  return options;
}

// The robust options, or none for loss "none".
std::optional<bireg::RobustOptions<double>> robust_options(const std::string& loss,
                                                           double loss_scale) {
  if (loss == "none") return std::nullopt;
  bireg::RobustOptions<double> options;
  options.loss = parse_choice(loss, {bireg::Loss::huber, bireg::Loss::cauchy, bireg::Loss::tukey},
                              "loss (or none)");
  if (!(loss_scale >= 0) || !std::isfinite(loss_scale))
    refuse("loss_scale must be a finite non-negative number (0: 95% efficiency)");
  options.loss_scale = loss_scale;
  return options;
}

template <class G>
nb::dict robust_report(const GroupFit<G>& fit) {
  nb::dict out;
  if (!fit.robust) return out;
  const bireg::RobustResult<G>& r = *fit.robust;
  out["status"] = std::string(to_string(r.status));
  out["message"] = r.message;
  out["loss"] = std::string(to_string(r.loss));
  out["loss_scale"] = r.loss_scale;
  out["rounds"] = r.rounds;
  NewArray weights({r.robust_weights.size()}), distances({r.distances.size()});
  std::copy(r.robust_weights.begin(), r.robust_weights.end(), weights.data());
  std::copy(r.distances.begin(), r.distances.end(), distances.data());
  out["weights"] = weights.release();
  out["distances"] = distances.release();
  nb::list outliers;
  for (std::size_t i : r.outliers)
    outliers.append(i);
  out["outliers"] = outliers;
  return out;
}

// The geodesic if the fit left a finite one (a diverged fit may not).
template <class G>
const bireg::Geodesic<G>* finite_geodesic(const GroupFit<G>& fit) {
  const auto& g = fit.result.geodesic;
  if (!g || !g->start().allFinite() || !g->end().allFinite() || !g->body_velocity().allFinite())
    return nullptr;
  return &*g;
}

template <class G>
const bireg::Geodesic<G>& geodesic_or_refuse(const GroupFit<G>& fit, const char* what) {
  const bireg::Geodesic<G>* g = finite_geodesic(fit);
  if (!g)
    refuse(std::string(what) + ": the fit left no finite geodesic (status " +
           to_string(fit.result.status) + ")");
  return *g;
}

template <class G>
Output predict(const GroupFit<G>& fit, const Vector& t) {
  const bireg::Geodesic<G>& geodesic = geodesic_or_refuse(fit, "predict");
  check_covariates(t, "predict");
  const std::size_t count = t.shape(0), n = std::size_t(side<G>());
  NewArray out({count, n, n});
  {
    nb::gil_scoped_release release;
    for (std::size_t i = 0; i < count; ++i)
      write_row_major(geodesic(t.data()[i]), out.data() + i * n * n);
  }
  return out.release();
}

template <class G>
Output spatial_velocity(const GroupFit<G>& fit, const Vector& t) {
  const bireg::Geodesic<G>& geodesic = geodesic_or_refuse(fit, "spatial_velocity");
  check_covariates(t, "spatial_velocity");
  std::vector<typename G::Tangent> rows(t.shape(0));
  for (std::size_t i = 0; i < rows.size(); ++i)
    rows[i] = geodesic.spatial_velocity(t.data()[i]);
  return tangent_rows<G>(rows);
}

template <class G>
nb::dict diagnostics(const GroupFit<G>& fit) {
  const bireg::RegressionDiagnostics<double>& d = fit.result.diagnostics;
  nb::dict out;
  out["mu_min"] = d.mu_min;
  out["mu_max"] = d.mu_max;
  out["condition_number"] = d.condition_number;
  out["step_size"] = d.step_size;
  out["backtracks"] = d.backtracks;
  out["contraction_factor"] = d.contraction_factor;
  out["series_order"] = d.series_order;
  out["series_truncation_bound"] = d.series_truncation_bound;
  out["force_norm"] = d.force_norm;
  out["residual_rms"] = d.residual_rms;
  out["residual_rms_about_mean"] = d.residual_rms_about_mean;
  out["explained_variance"] = d.explained_variance;
  out["largest_residual_angle"] = d.largest_residual_angle;
  out["largest_residual_observation"] = d.largest_residual_observation;
  out["beyond_domain"] = d.beyond_domain;
  return out;
}

// Calls f(fit) with the handle as its group's fit.
template <class F>
auto on_fit(const FitHandle& handle, F&& f) {
  return with_group(handle.group, [&](auto tag) {
    using G = typename decltype(tag)::type;
    return f(as_group_fit<G>(handle));
  });
}

}  // namespace

// The array properties return new arrays that Python owns (rv_policy::move;
// a property's default, reference_internal, would tie them to the fit).
void bind_regression(nb::module_& m) {
  nb::class_<FitHandle>(m, "FitHandle",
                        "A geodesic fitted by bireg::GeodesicRegression, with its data.")
      .def_ro("group", &FitHandle::group)
      .def_ro("chunked", &FitHandle::chunked)
      .def_prop_ro("status",
                   [](const FitHandle& h) {
                     return on_fit(
                         h, [](const auto& f) { return std::string(to_string(f.result.status)); });
                   })
      .def_prop_ro(
          "ok",
          [](const FitHandle& h) { return on_fit(h, [](const auto& f) { return f.result.ok(); }); })
      .def_prop_ro("iterations",
                   [](const FitHandle& h) {
                     return on_fit(h, [](const auto& f) { return f.result.iterations; });
                   })
      .def_prop_ro("has_geodesic",
                   [](const FitHandle& h) {
                     return on_fit(h, [](const auto& f) { return finite_geodesic(f) != nullptr; });
                   })
      .def_prop_ro("interval",
                   [](const FitHandle& h) {
                     return on_fit(h, [](const auto& f) {
                       const auto& g = geodesic_or_refuse(f, "interval");
                       return std::make_pair(double(g.t_min()), double(g.t_max()));
                     });
                   })
      .def_prop_ro(
          "g0",
          [](const FitHandle& h) {
            return on_fit(
                h, [](const auto& f) { return matrix_array(geodesic_or_refuse(f, "g0").start()); });
          },
          nb::rv_policy::move)
      .def_prop_ro(
          "g1",
          [](const FitHandle& h) {
            return on_fit(
                h, [](const auto& f) { return matrix_array(geodesic_or_refuse(f, "g1").end()); });
          },
          nb::rv_policy::move)
      .def_prop_ro(
          "body_velocity",
          [](const FitHandle& h) {
            return on_fit(h, [](const auto& f) {
              return vector_array(geodesic_or_refuse(f, "body_velocity").body_velocity());
            });
          },
          nb::rv_policy::move)
      .def_prop_ro(
          "residuals",
          [](const FitHandle& h) {
            return on_fit(h, [](const auto& f) {
              using G = typename std::decay_t<decltype(f)>::Group;
              return tangent_rows<G>(f.result.residuals);
            });
          },
          nb::rv_policy::move)
      .def_prop_ro(
          "step_norms",
          [](const FitHandle& h) {
            return on_fit(h, [](const auto& f) { return vector_array(f.result.step_norms); });
          },
          nb::rv_policy::move)
      .def_prop_ro("diagnostics",
                   [](const FitHandle& h) {
                     return on_fit(h, [](const auto& f) { return diagnostics(f); });
                   })
      .def_prop_ro(
          "robust",
          [](const FitHandle& h) {
            return on_fit(h, [](const auto& f) { return robust_report(f); });
          },
          "A robust fit's status, weights, distances and outliers (empty otherwise).")
      .def(
          "predict",
          [](const FitHandle& h, const Vector& t) {
            return on_fit(h, [&](const auto& f) { return predict(f, t); });
          },
          nb::arg("t"), "The fitted geodesic at each covariate: (M,) -> (M, n, n).")
      .def(
          "spatial_velocity",
          [](const FitHandle& h, const Vector& t) {
            return on_fit(h, [&](const auto& f) { return spatial_velocity(f, t); });
          },
          nb::arg("t"), "Ad_gamma(t) of the body velocity at each covariate: (M,) -> (M, d).");

  m.def(
      "fit",
      [](const std::string& group, const Vector& t, const Stack& y, const Vector& w,
         const std::string& solver, const std::string& method, double tolerance, int max_iterations,
         int threads, const std::string& loss, double loss_scale) {
        const bireg::RegressionOptions<double> options =
            regression_options(solver, method, tolerance, max_iterations, threads);
        const auto robust = robust_options(loss, loss_scale);
        const FitRequest request{group, t, y, w, options, robust};
        return with_group(group, [&](auto tag) {
          return GroupFitter<typename decltype(tag)::type>::fit(request);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("y"), nb::arg("weights"), nb::arg("solver"),
      nb::arg("method"), nb::arg("tol"), nb::arg("max_iter"), nb::arg("threads"), nb::arg("loss"),
      nb::arg("loss_scale"),
      "bireg::GeodesicRegression<G>::fit (or RobustGeodesicRegression with a loss) of y at t "
      "with weights (empty: all 1). ValueError for invalid input.");

  m.def(
      "fit_by_chunks",
      [](const std::string& group, const nb::callable& reduce, const std::string& solver,
         const std::string& method, double tolerance, int max_iterations) {
        const bireg::RegressionOptions<double> options =
            regression_options(solver, method, tolerance, max_iterations, 1);
        return with_group(group, [&](auto tag) {
          return GroupFitter<typename decltype(tag)::type>::fit_by_chunks(group, reduce, options);
        });
      },
      nb::arg("group"), nb::arg("reduce"), nb::arg("solver"), nb::arg("method"), nb::arg("tol"),
      nb::arg("max_iter"),
      "bireg::fit_by_chunks<G>: fit()'s steps on observations held in chunks elsewhere. "
      "reduce(request) gets a request's numbers and returns every chunk's chunk_sums numbers, "
      "in chunk order. ValueError for invalid input; what reduce raises passes through.");
  m.def(
      "chunk_sums",
      [](const std::string& group, const Vector& request, const Vector& t, const Stack& y,
         const Vector& w, std::size_t offset) {
        return with_group(group, [&](auto tag) {
          return GroupFitter<typename decltype(tag)::type>::chunk_sums(request, t, y, w, offset);
        });
      },
      nb::arg("group"), nb::arg("request"), nb::arg("t"), nb::arg("y"), nb::arg("weights"),
      nb::arg("offset"),
      "bireg::chunk_sums<G> of one chunk (observation i is the whole set's offset + i), "
      "request and sums as numbers. The GIL is released.");
}

}  // namespace bireg_python
