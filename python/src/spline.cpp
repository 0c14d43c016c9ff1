// The regression layer's spline (bireg/spline_regression.hpp): the fit, with
// the knot spacing by cross-validation when asked and its sandwich
// covariance (bireg/statistics/inference/spline_covariance.hpp), the
// curve's pose, body velocity and acceleration at new covariates, and the
// pointwise confidence half-widths. The GIL is released while the library
// works.
#include <cmath>
#include <string>
#include <vector>

#include "bireg/spline_regression.hpp"
#include "bireg/statistics/inference/spline_covariance.hpp"
#include "bireg/statistics/smoothing/spline_knots.hpp"
#include "bireg/statistics/smoothing/spline_roughness.hpp"
#include "common.hpp"

namespace bireg_python {
namespace {

template <class G>
Output element_stack(const std::vector<typename G::Element>& elements) {
  const std::size_t n = std::size_t(side<G>());
  NewArray stack({elements.size(), n, n});
  for (std::size_t c = 0; c < elements.size(); ++c)
    write_row_major(elements[c], stack.data() + c * n * n);
  return stack.release();
}

// The cross-validation curve of a selection, as a dict: the choice under
// `key`, the grid, the criterion (inf where refused), the refusals and the
// message.
template <class Selection>
nb::dict selection_dict(const Selection& selection, const char* key, double chosen) {
  nb::dict out;
  out[key] = chosen;
  out["grid"] = vector_array(selection.grid);
  out["criterion"] = vector_array(selection.criterion);
  nb::list refusals;
  for (const std::string& r : selection.refusals)
    refusals.append(r);
  out["refusals"] = refusals;
  out["at_edge"] = selection.at_edge;
  out["message"] = selection.message;
  return out;
}

// knot_spacing <= 0: chosen by select_knot_spacing over
// auto_knot_spacing_grid, the curve returned under "knot_selection";
// with roughness_auto, fine_knot_spacing instead. roughness_auto: lambda
// chosen by select_roughness_penalty over auto_roughness_penalty_grid, the
// curve under "roughness_selection"; else roughness_penalty as given.
template <class G>
nb::dict fit_spline(const Vector& t, const Stack& y, const Vector& w, int degree,
                    double knot_spacing, double roughness_penalty, bool roughness_auto,
                    double tolerance, int max_iterations, int threads) {
  const StackView<G> poses(y);
  const std::vector<double> covariates = to_vector(t), weights = to_vector(w);
  bireg::SplineOptions<double> options;
  options.degree = degree;
  options.tolerance = tolerance;
  options.max_iterations = max_iterations;
  options.threads = threads;
  nb::dict out;
  bireg::SplineResult<G> fit;
  bireg::SplineCovariance<G> covariance;
  bireg::KnotSpacingSelection<double> selection;
  bireg::RoughnessPenaltySelection<double> roughness;
  const bool automatic = !(knot_spacing > 0) && !roughness_auto;
  // A lambda given is the model whose knot spacing is cross-validated.
  if (!roughness_auto) options.roughness_penalty = roughness_penalty;
  {
    nb::gil_scoped_release release;
    if (automatic) {
      selection = bireg::select_knot_spacing<G>(poses, covariates, options,
                                                bireg::auto_knot_spacing_grid(covariates));
      options.knot_spacing = selection.knot_spacing;
    } else if (knot_spacing > 0) {
      options.knot_spacing = knot_spacing;
    } else {
      options.knot_spacing = bireg::fine_knot_spacing(covariates);
    }
    if (roughness_auto) {
      roughness = bireg::select_roughness_penalty<G>(
          poses, covariates, options,
          bireg::auto_roughness_penalty_grid(covariates, double(options.knot_spacing)));
      options.roughness_penalty = roughness.roughness_penalty;
    }
    if ((!automatic || selection.ok()) && (!roughness_auto || roughness.ok()))
      fit = bireg::SplineRegression<G>(options).fit(poses, covariates, weights);
    if (fit.ok()) covariance = bireg::spline_covariance(fit, poses, covariates, weights);
  }
  if (automatic) {
    if (!selection.ok()) refuse("knot spacing auto: " + selection.message);
    out["knot_selection"] = selection_dict(selection, "knot_spacing", selection.knot_spacing);
  }
  if (roughness_auto) {
    if (!roughness.ok()) refuse("roughness penalty auto: " + roughness.message);
    out["roughness_selection"] =
        selection_dict(roughness, "roughness_penalty", roughness.roughness_penalty);
  }
  if (fit.status == bireg::Status::invalid_input) refuse(fit.message);
  out["status"] = std::string(to_string(fit.status));
  out["message"] = fit.message;
  out["iterations"] = fit.iterations;
  out["roughness_penalty"] = fit.roughness_penalty;
  out["equation_norm"] = fit.equation_norm;
  out["first_knot"] = fit.spline->first_knot();
  out["knot_spacing"] = fit.spline->knot_spacing();
  out["control_points"] = element_stack<G>(fit.spline->control_points());
  out["residuals"] = tangent_rows<G>(fit.residuals);
  nb::dict diagnostics;  // SplineResult's cut-locus report
  diagnostics["largest_residual_angle"] = fit.largest_residual_angle;
  diagnostics["largest_residual_observation"] = fit.largest_residual_observation;
  diagnostics["largest_increment_angle"] = fit.largest_increment_angle;
  diagnostics["largest_increment"] = fit.largest_increment;
  diagnostics["beyond_domain"] = fit.beyond_domain;
  out["diagnostics"] = diagnostics;
  // The covariance's band, (M (2k + 1), d, d) in SplineCovariance's order,
  // S and nu; or why it is undefined.
  out["covariance_message"] = covariance.message;
  if (covariance.defined()) {
    const std::size_t d = std::size_t(G::dof);
    NewArray band({covariance.band.size(), d, d});
    for (std::size_t b = 0; b < covariance.band.size(); ++b)
      write_row_major(covariance.band[b], band.data() + b * d * d);
    out["covariance_band"] = band.release();
    out["noise_covariance"] = matrix_array(covariance.residual);
    out["degrees_of_freedom"] = covariance.degrees_of_freedom;
  }
  return out;
}

// The curve of a fit's knots and control points, checked.
template <class G>
bireg::Spline<G> curve_of(int degree, double first_knot, double spacing, const Stack& points) {
  if (degree < 1 || degree > bireg::kMaxSplineDegree) refuse("degree must be 1, 2 or 3");
  if (!(spacing > 0) || !std::isfinite(first_knot)) refuse("the knots must be finite, spacing > 0");
  if (points.shape(0) <= std::size_t(degree)) refuse("too few control points for the degree");
  const StackView<G> view(points);
  std::vector<typename G::Element> elements;
  for (std::size_t c = 0; c < view.size(); ++c)
    elements.push_back(view[c]);
  return bireg::Spline<G>(degree, first_knot, spacing, std::move(elements));
}

// The curve of control points `points` at t: pose, body velocity and body
// acceleration (per covariate unit).
template <class G>
nb::dict evaluate_spline(int degree, double first_knot, double spacing, const Stack& points,
                         const Vector& t) {
  const bireg::Spline<G> curve = curve_of<G>(degree, first_knot, spacing, points);
  check_covariates(t, "spline");
  const std::size_t count = t.shape(0), n = std::size_t(side<G>());
  NewArray pose({count, n, n});
  std::vector<typename G::Tangent> velocity(count), acceleration(count);
  for (std::size_t q = 0; q < count; ++q) {
    const double at = t.data()[q];
    write_row_major(curve(at), pose.data() + q * n * n);
    velocity[q] = curve.body_velocity(at);
    acceleration[q] = curve.body_acceleration(at);
  }
  nb::dict out;
  out["pose"] = pose.release();
  out["velocity"] = tangent_rows<G>(velocity);
  out["acceleration"] = tangent_rows<G>(acceleration);
  return out;
}

// The half-widths of the pointwise `level` confidence regions of the pose
// or the body velocity at t (bireg::pointwise_quantile, half_widths), from
// the covariance fit_spline returned.
template <class G>
Output spline_band(int degree, double first_knot, double spacing, const Stack& points,
                   const Stack& band, const Matrix& noise, double nu, const Vector& t, double level,
                   const std::string& quantity) {
  using AdMatrix = typename G::AdMatrix;
  constexpr std::size_t d = std::size_t(G::dof);
  if (!(level > 0 && level < 1)) refuse("confidence_band: level must lie in (0, 1)");
  if (quantity != "pose" && quantity != "velocity")
    refuse("confidence_band: quantity must be 'pose' or 'velocity', got '" + quantity + "'");
  bireg::SplineCovariance<G> c;
  c.spline = curve_of<G>(degree, first_knot, spacing, points);
  const std::size_t expected = points.shape(0) * (2 * std::size_t(degree) + 1);
  if (band.shape(0) != expected || band.shape(1) != d || band.shape(2) != d ||
      noise.shape(0) != d || noise.shape(1) != d)
    refuse("confidence_band: the covariance does not match the control points");
  c.band.resize(expected);
  for (std::size_t b = 0; b < expected; ++b)
    c.band[b] = Eigen::Map<const Eigen::Matrix<double, int(d), int(d), Eigen::RowMajor>>(
        band.data() + b * d * d);
  c.residual =
      Eigen::Map<const Eigen::Matrix<double, int(d), int(d), Eigen::RowMajor>>(noise.data());
  c.degrees_of_freedom = nu;
  c.status = bireg::CovarianceStatus::defined;
  check_covariates(t, "confidence_band");
  const std::optional<double> q = bireg::pointwise_quantile(c, level);
  if (!q) refuse("confidence_band: too few degrees of freedom for a quantile at this level");
  std::vector<typename G::Tangent> rows(t.shape(0));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double at = t.data()[i];
    const AdMatrix covariance =
        quantity == "pose" ? bireg::pose_covariance(c, at) : bireg::velocity_covariance(c, at);
    rows[i] = bireg::half_widths(covariance, *q);
  }
  return tangent_rows<G>(rows);
}

}  // namespace

void bind_spline(nb::module_& m) {
  m.def(
      "spline_fit",
      [](const std::string& group, const Vector& t, const Stack& y, const Vector& w, int degree,
         double knot_spacing, double roughness_penalty, bool roughness_auto, double tolerance,
         int max_iterations, int threads) {
        return with_group(group, [&](auto tag) {
          return fit_spline<typename decltype(tag)::type>(t, y, w, degree, knot_spacing,
                                                          roughness_penalty, roughness_auto,
                                                          tolerance, max_iterations, threads);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("y"), nb::arg("weights"), nb::arg("degree"),
      nb::arg("knot_spacing"), nb::arg("roughness_penalty"), nb::arg("roughness_auto"),
      nb::arg("tol"), nb::arg("max_iter"), nb::arg("threads"),
      "bireg::SplineRegression<G>::fit (knot_spacing <= 0: chosen by select_knot_spacing, or "
      "fine_knot_spacing with roughness_auto; roughness_auto: lambda by "
      "select_roughness_penalty).");
  m.def(
      "spline_evaluate",
      [](const std::string& group, int degree, double first_knot, double spacing,
         const Stack& points, const Vector& t) {
        return with_group(group, [&](auto tag) {
          return evaluate_spline<typename decltype(tag)::type>(degree, first_knot, spacing, points,
                                                               t);
        });
      },
      nb::arg("group"), nb::arg("degree"), nb::arg("first_knot"), nb::arg("spacing"),
      nb::arg("control_points"), nb::arg("t"),
      "bireg::Spline<G>: pose, body velocity and acceleration at t.");
  m.def(
      "spline_band",
      [](const std::string& group, int degree, double first_knot, double spacing,
         const Stack& points, const Stack& band, const Matrix& noise, double nu, const Vector& t,
         double level, const std::string& quantity) {
        return with_group(group, [&](auto tag) {
          return spline_band<typename decltype(tag)::type>(degree, first_knot, spacing, points,
                                                           band, noise, nu, t, level, quantity);
        });
      },
      nb::arg("group"), nb::arg("degree"), nb::arg("first_knot"), nb::arg("spacing"),
      nb::arg("control_points"), nb::arg("band"), nb::arg("noise"), nb::arg("nu"), nb::arg("t"),
      nb::arg("level"), nb::arg("quantity"),
      "bireg::pose_covariance / velocity_covariance of a SplineCovariance: half-widths at t.");
}

}  // namespace bireg_python
