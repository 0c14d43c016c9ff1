"""bireg: bi-invariant geodesic regression on Lie groups.

A Python face for the header-only C++ library of the same name: the
groups with vectorised operations, ``GeodesicRegression``,
``LocalRegression`` and ``SplineRegression`` in scikit-learn's style, the bi-invariant ``mean``,
model selection (motion models, static or geodesic, which curve), the
two-sample tests of cohorts and their trends, and the trajectory
readers and writers; ``bireg.dask`` (imported on its own, with the ``dask`` extra)
runs the cohorts on a Dask cluster. The README maps each name to its C++
counterpart.
"""

from ._bireg import __version__
from .cohorts import (ElementwiseResult, FitManyResult, PopulationTrend, TwoSampleResult,
                      compare_trends, compare_trends_at, compare_velocities, fit_many,
                      population_trend, two_sample_test)
from .groups import GLp3, SE2, SE3, SL3, SO2, SO3, Group, Sim3
from .io import read_trajectory, write_trajectory
from .local import LocalRegression
from .regression import ConvergenceWarning, GeodesicRegression, mean
from .selection import (CurveSelection, MotionModelSelection, SelectionWarning, TrendSelection,
                        select_curve, select_motion_model, select_static_or_geodesic)
from .spline import SplineRegression

__all__ = [
    "__version__", "Group", "SO2", "SO3", "SE2", "SE3", "Sim3", "SL3", "GLp3",
    "GeodesicRegression", "LocalRegression", "SplineRegression", "ConvergenceWarning", "mean",
    "read_trajectory", "write_trajectory",
    "two_sample_test", "TwoSampleResult", "ElementwiseResult", "fit_many", "FitManyResult",
    "compare_trends", "compare_trends_at", "compare_velocities", "population_trend",
    "PopulationTrend", "select_motion_model", "select_static_or_geodesic", "select_curve",
    "MotionModelSelection", "TrendSelection", "CurveSelection", "SelectionWarning",
]
