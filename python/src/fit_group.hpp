// The fit of one group (GroupFitter<G>::fit, fit_handle.hpp), included by
// that group's fit_<group>.cpp alone.
#pragma once

#include <memory>

#include "fit_handle.hpp"

#include "bireg/regression/chunked_fit.hpp"

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

namespace chunk_numbers {

// The record of numbers that a Python transport carried; ValueError when
// bireg::from_numbers refuses them: their count is not this module's
// layout (another bireg version wrote them), a number does not fit its
// field, or the request is one a worker must not run.
template <class Record>
Record read(const double* numbers, std::size_t count, const char* what) {
  auto record = bireg::from_numbers<Record>(numbers, count);
  if (!record) {
    refuse(std::string("the ") + what + " has " + std::to_string(count) +
           " numbers that this bireg version refuses: another version's layout (every worker "
           "needs the client's version), a value that does not fit its field, or, for a "
           "request, one that a worker must not run");
  }
  return *record;
}

}  // namespace chunk_numbers

template <class G>
std::unique_ptr<FitHandle> GroupFitter<G>::fit_by_chunks(
    const std::string& group, const nb::callable& reduce,
    const bireg::RegressionOptions<double>& options) {
  const auto reduce_chunks = [&](const bireg::ChunkRequest<G>& request) {
    const nb::object parts = reduce(vector_array(bireg::to_numbers(request)));
    bireg::ChunkSums<G> total;
    for (nb::handle part : parts) {
      const Vector numbers = nb::cast<Vector>(part);
      total.add(chunk_numbers::read<bireg::ChunkSums<G>>(numbers.data(), numbers.shape(0),
                                                         "chunk's sums"));
    }
    return total;
  };
  auto fit = std::make_unique<GroupFit<G>>();
  fit->group = group;
  fit->chunked = true;
  fit->options = options;
  fit->result = bireg::fit_by_chunks<G>(options, reduce_chunks);
  if (fit->result.status == bireg::Status::invalid_input) refuse(fit->result.message);
  return fit;
}

template <class G>
Output GroupFitter<G>::chunk_sums(const Vector& request, const Vector& t, const Stack& y,
                                  const Vector& w, std::size_t offset) {
  const auto parsed =
      chunk_numbers::read<bireg::ChunkRequest<G>>(request.data(), request.shape(0), "request");
  if (t.shape(0) != y.shape(0) || (w.shape(0) != 0 && w.shape(0) != y.shape(0))) {
    refuse("a chunk's covariates, poses and weights differ in length (" +
           std::to_string(t.shape(0)) + ", " + std::to_string(y.shape(0)) + ", " +
           std::to_string(w.shape(0)) + ")");
  }
  std::vector<double> numbers;
  {
    nb::gil_scoped_release release;
    const std::vector<double> covariates = to_vector(t), weights = to_vector(w);
    const bireg::ChunkSums<G> sums =
        bireg::chunk_sums<G>(parsed, StackView<G>(y), covariates, weights, offset);
    numbers = bireg::to_numbers(sums);
  }
  return vector_array(numbers);
}

}  // namespace bireg_python
