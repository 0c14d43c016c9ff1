// The fit of one group (GroupFitter<G>::fit, fit_handle.hpp), included by
// that group's fit_<group>.cpp alone.
#pragma once

#include <memory>

#include "fit_handle.hpp"

namespace bireg_python {

template <class G>
std::unique_ptr<FitHandle> GroupFitter<G>::fit(const FitRequest& request) {
  auto fit = std::make_unique<GroupFit<G>>();
  fit->group = request.group;
  fit->poses = request.y;
  fit->covariates = to_vector(request.t);
  fit->weights = to_vector(request.w);
  fit->options = request.options;
  {
    nb::gil_scoped_release release;
    if (request.robust) {
      fit->robust = bireg::RobustGeodesicRegression<G>(*request.robust, request.options)
                        .fit(fit->observations(), fit->covariates, fit->weights);
      fit->result = fit->robust->fit;
    } else {
      fit->result = bireg::GeodesicRegression<G>(request.options)
                        .fit(fit->observations(), fit->covariates, fit->weights);
    }
  }
  if (fit->result.status == bireg::Status::invalid_input) refuse(fit->result.message);
  if (fit->robust && fit->robust->status == bireg::RobustStatus::invalid_input)
    refuse(fit->robust->message);
  return fit;
}

}  // namespace bireg_python
