// A fitted geodesic as Python holds it: the fit's result with the data it
// was fitted to (kept alive, not copied), so that the statistics layer can
// compute covariances, bands and tests from it. One class per group behind
// one base, so that a Python object needs no template.
#pragma once

#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"

#include "bireg/regression.hpp"
#include "bireg/statistics/robust/regression.hpp"

namespace bireg_python {

struct FitHandle {
  virtual ~FitHandle() = default;
  std::string group;
  // Fitted by chunks elsewhere (fit_by_chunks): the observations and the
  // residuals are not here.
  bool chunked = false;
};

template <class G>
struct GroupFit final : FitHandle {
  using Group = G;
  Stack poses;  // the observations, owned by Python
  std::vector<double> covariates;
  std::vector<double> weights;  // empty: all 1
  bireg::RegressionOptions<double> options;
  bireg::RegressionResult<G> result;
  // Set for a robust fit (RobustGeodesicRegression): `result` is its last
  // fit, whose weights are the robust weights times `weights`.
  std::optional<bireg::RobustResult<G>> robust;

  StackView<G> observations() const { return StackView<G>(poses); }

  // ValueError naming `what` for a chunked fit, which has neither the
  // observations nor the residuals here (call with the GIL held).
  void require_observations(const char* what) const {
    if (chunked) {
      refuse(std::string(what) +
             ": this fit's observations are with its chunks (bireg.dask.fit), not here");
    }
  }
};

// What fit() was asked, checked: the data Python holds and the options.
struct FitRequest {
  std::string group;
  Vector t;
  Stack y;
  Vector w;  // empty: all 1
  bireg::RegressionOptions<double> options;
  std::optional<bireg::RobustOptions<double>> robust;  // none: least squares
};

// bireg::GeodesicRegression<G> (or RobustGeodesicRegression<G>) on a
// request, with the GIL released; ValueError for refused input. Defined in
// fit_group.hpp and instantiated for each group in a small file of its own
// (fit_<group>.cpp), which python/CMakeLists.txt links first: there GCC
// inlines the per-observation work's helpers (SO3::log into SE3::log, the
// small-angle series), and the linker keeps those copies. With the copies
// of the large statistics files a fit of 1e5 SE(3) poses from Python took
// 11 % longer than in C++; compiled beside the other groups' fits, a fit
// took about 10 % longer too (bench/README.md, "Python against C++").
template <class G>
struct GroupFitter {
  static std::unique_ptr<FitHandle> fit(const FitRequest& request);

  // bireg::fit_by_chunks (regression/chunked_fit.hpp) with a Python
  // transport: reduce(request) takes a request's numbers and returns a
  // list of every chunk's sums' numbers (chunk_sums below, on the
  // workers), in chunk order; they are joined here in that order. The
  // handle has the fit and no observations.
  static std::unique_ptr<FitHandle> fit_by_chunks(const std::string& group,
                                                  const nb::callable& reduce,
                                                  const bireg::RegressionOptions<double>& options);
  // bireg::chunk_sums of one chunk (y[i] at t[i] with weights w, empty: all
  // 1, the whole set's observation offset + i), the GIL released: the
  // request's numbers in, the sums' numbers out.
  static Output chunk_sums(const Vector& request, const Vector& t, const Stack& y, const Vector& w,
                           std::size_t offset);
};

// The handle as the group's fit; the group is the handle's own.
template <class G>
const GroupFit<G>& as_group_fit(const FitHandle& handle) {
  return static_cast<const GroupFit<G>&>(handle);
}

// The enumerator whose to_string is `name`; ValueError naming the choices.
template <class Enum>
Enum parse_choice(const std::string& name, std::initializer_list<Enum> choices, const char* what) {
  std::string known;
  for (Enum e : choices) {
    if (name == to_string(e)) return e;
    known += (known.empty() ? "" : ", ") + std::string(to_string(e));
  }
  throw nb::value_error(
      (std::string("unknown ") + what + " '" + name + "': expected one of " + known).c_str());
}

}  // namespace bireg_python
