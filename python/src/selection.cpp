// The statistics layer's model selection (bireg/statistics/selection/):
// which motion model a pose sequence needs (select_motion_model), whether
// an element of any group moves along its covariate at all
// (select_static_or_geodesic), and which curve the data need: a geodesic,
// a piecewise geodesic or a cubic spline (select_curve). Each returns the
// library's table as a dict for bireg/selection.py; a refused input is a
// ValueError with the library's message. The GIL is released while the
// library works.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "common.hpp"

#include "bireg/statistics/selection/curve_selection.hpp"
#include "bireg/statistics/selection/motion_models.hpp"
#include "bireg/statistics/selection/static_or_geodesic.hpp"

namespace bireg_python {
namespace {

// A number of a candidate that was scored, or None for one that was not.
nb::object scored(bool fitted, double value) {
  return fitted ? nb::object(nb::float_(value)) : nb::none();
}

nb::object optional_number(const std::optional<double>& value) {
  return value ? nb::object(nb::float_(*value)) : nb::none();
}

// What every table row has: model, k, whether it was scored and why not,
// log det S and the criterion, the margin and the recommendation.
template <class Candidate>
nb::dict common_row(const Candidate& c, std::string model) {
  nb::dict row;
  row["model"] = std::move(model);
  row["parameters"] = static_cast<long long>(c.parameters);
  row["fitted"] = c.fitted;
  row["note"] = c.note;
  row["log_det"] = scored(c.fitted, c.log_det);
  row["criterion"] = scored(c.fitted, c.criterion);
  row["within_margin"] = c.within_margin;
  row["recommended"] = c.recommended;
  return row;
}

// The table: for each candidate, common_row under name(c), then the
// columns extra(c, row) adds.
template <class Candidate, class Name, class Extra>
nb::list table(const std::vector<Candidate>& candidates, Name name, Extra extra) {
  nb::list rows;
  for (const Candidate& c : candidates) {
    nb::dict row = common_row(c, name(c));
    extra(c, row);
    rows.append(row);
  }
  return rows;
}

// The status and message of a selection, or ValueError for a refusal.
template <class Selection>
nb::dict selection_header(const Selection& s) {
  if (s.status == bireg::SelectionStatus::invalid_input) refuse(s.message);
  nb::dict out;
  out["status"] = std::string(to_string(s.status));
  out["message"] = s.message;
  return out;
}

bireg::ModelSelectionOptions selection_options(int folds, int threads) {
  if (threads < 1) refuse("threads must be at least 1, got " + std::to_string(threads));
  bireg::ModelSelectionOptions options;
  options.folds = folds;
  options.threads = threads;
  return options;
}

nb::dict motion_model(const std::string& group, const Vector& t, const Stack& y, int folds,
                      int threads) {
  if (group != "SE3" && group != "Sim3")
    refuse("select_motion_model: group " + group +
           ": expected SE3 (rigid poses) or Sim3 (similarities)");
  bireg::ModelSelectionOptions options = selection_options(folds, threads);
  options.group = group == "Sim3" ? bireg::PoseGroup::sim3 : bireg::PoseGroup::se3;
  const std::vector<double> covariates = to_vector(t);
  bireg::ModelSelection s;
  {
    nb::gil_scoped_release release;
    s = bireg::select_motion_model(StackView<bireg::SE3d>(y), covariates, options);
  }
  nb::dict out = selection_header(s);
  const bool similarities = options.group == bireg::PoseGroup::sim3;
  out["candidates"] = table(
      s.candidates, [](const bireg::CandidateReport& c) { return to_string(c.model); },
      [similarities](const bireg::CandidateReport& c, nb::dict& row) {
        row["rotation_rms_degrees"] = scored(c.fitted, c.rotation_rms_degrees);
        row["translation_rms"] = scored(c.fitted, c.translation_rms);
        row["log_scale_rms"] = scored(c.fitted && similarities, c.log_scale_rms);
        row["cv_error"] = optional_number(c.cv_error);
      });
  out["ambiguous"] = s.ambiguous;
  out["recommended"] = s.recommended ? nb::object(nb::str(to_string(*s.recommended))) : nb::none();
  if (s.prediction) {
    // The recommended model's poses at the data's covariates.
    NewArray fitted({covariates.size(), 4, 4});
    for (std::size_t i = 0; i < covariates.size(); ++i)
      write_row_major((*s.prediction)(covariates[i]), fitted.data() + i * 16);
    out["fitted"] = fitted.release();
  } else {
    out["fitted"] = nb::none();
  }
  return out;
}

template <class G>
nb::dict static_or_geodesic(const Vector& t, const Stack& y, int folds, int threads) {
  const bireg::ModelSelectionOptions options = selection_options(folds, threads);
  const std::vector<double> covariates = to_vector(t);
  bireg::TrendSelection<G> s;
  {
    nb::gil_scoped_release release;
    s = bireg::select_static_or_geodesic<G>(StackView<G>(y), covariates, options);
  }
  nb::dict out = selection_header(s);
  out["candidates"] = table(
      s.candidates, [](const bireg::TrendCandidate& c) { return to_string(c.model); },
      [](const bireg::TrendCandidate& c, nb::dict& row) {
        row["residual_rms"] = scored(c.fitted, c.residual_rms);
        row["cv_error"] = optional_number(c.cv_error);
      });
  out["recommended"] = s.recommended ? nb::object(nb::str(to_string(*s.recommended))) : nb::none();
  if (s.static_element) {
    out["static_element"] = matrix_array(*s.static_element);
  } else {
    out["static_element"] = nb::none();
  }
  if (s.geodesic) {
    out["g0"] = matrix_array(s.geodesic->start());
    out["g1"] = matrix_array(s.geodesic->end());
    out["interval"] = nb::make_tuple(double(s.geodesic->t_min()), double(s.geodesic->t_max()));
  } else {
    out["g0"] = nb::none();
    out["g1"] = nb::none();
    out["interval"] = nb::none();
  }
  return out;
}

template <class G>
nb::dict curve(const Vector& t, const Stack& y, const Vector& knot_spacings, int threads) {
  if (threads < 1) refuse("threads must be at least 1, got " + std::to_string(threads));
  bireg::CurveSelectionOptions options;
  options.knot_spacings = to_vector(knot_spacings);
  options.threads = threads;
  const std::vector<double> covariates = to_vector(t);
  bireg::CurveSelection<G> s;
  {
    nb::gil_scoped_release release;
    s = bireg::select_curve<G>(StackView<G>(y), covariates, options);
  }
  nb::dict out = selection_header(s);
  out["candidates"] = table(
      s.candidates, [](const bireg::CurveCandidate& c) { return bireg::describe(c); },
      [](const bireg::CurveCandidate& c, nb::dict& row) {
        row["degree"] = c.degree;
        row["segments"] = static_cast<long long>(c.segments);
        row["knot_spacing"] = c.knot_spacing;
        row["residual_rms"] = scored(c.fitted, c.residual_rms);
      });
  if (s.recommended) {
    out["recommended"] = bireg::describe(s.candidates[*s.recommended]);
    out["recommended_index"] = static_cast<long long>(*s.recommended);
  } else {
    out["recommended"] = nb::none();
    out["recommended_index"] = nb::none();
  }
  return out;
}

}  // namespace

void bind_selection(nb::module_& m) {
  m.def("select_motion_model", &motion_model, nb::arg("group"), nb::arg("t"), nb::arg("Y"),
        nb::arg("folds"), nb::arg("threads"),
        "bireg::select_motion_model on SE3 poses or Sim3 similarities: the candidates' table, "
        "the recommendation and its poses at t.");
  m.def(
      "select_static_or_geodesic",
      [](const std::string& group, const Vector& t, const Stack& y, int folds, int threads) {
        return with_group(group, [&](auto tag) {
          return static_or_geodesic<typename decltype(tag)::type>(t, y, folds, threads);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("Y"), nb::arg("folds"), nb::arg("threads"),
      "bireg::select_static_or_geodesic<G>: the two candidates, the recommendation, the mean "
      "and the geodesic.");
  m.def(
      "select_curve",
      [](const std::string& group, const Vector& t, const Stack& y, const Vector& knot_spacings,
         int threads) {
        return with_group(group, [&](auto tag) {
          return curve<typename decltype(tag)::type>(t, y, knot_spacings, threads);
        });
      },
      nb::arg("group"), nb::arg("t"), nb::arg("Y"), nb::arg("knot_spacings"), nb::arg("threads"),
      "bireg::select_curve<G>: the geodesic, piecewise geodesics and cubic splines scored by "
      "the invariant criterion (empty knot_spacings: auto_knot_spacing_grid).");
}

}  // namespace bireg_python
