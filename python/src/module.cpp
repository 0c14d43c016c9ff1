// The compiled part of the Python package bireg: one binding file per
// layer of the library (groups, regression with the spline beside it,
// statistics, model selection, io, cohorts). The Python
// modules in python/bireg/ give it its scikit-learn-style face.
#include "common.hpp"

#include "bireg/version.hpp"

NB_MODULE(_bireg, m) {
  m.doc() = "bireg's compiled core: bi-invariant regression on Lie groups";
  m.attr("__version__") = bireg::version;
  bireg_python::bind_groups(m);
  bireg_python::bind_regression(m);
  bireg_python::bind_spline(m);
  bireg_python::bind_statistics(m);
  bireg_python::bind_io(m);
  bireg_python::bind_cohorts(m);
  bireg_python::bind_selection(m);
}
