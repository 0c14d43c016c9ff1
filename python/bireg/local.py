"""Local (kernel-weighted) geodesic regression: the pose and velocity along
a trajectory, as ``bireg_smooth`` computes them
(bireg::LocalGeodesicRegression, include/bireg/statistics/smoothing/local_geodesic.hpp).
"""

import warnings

import numpy as np

from . import _arrays, _bireg
from . import groups as _groups


class LocalRegression:
    """``bandwidth="auto"``: chosen by cross-validation over
    bireg::auto_bandwidth_grid, one bandwidth for the poses and one for the
    velocity (bireg::select_bandwidth), as ``bireg_smooth --bandwidth auto``;
    the velocity's local polynomial degree (``velocity_degree_``: 2, the
    local quadratic, or 3, the local cubic) is chosen with its bandwidth.
    A float: that bandwidth, in covariate units, for both, and the quadratic.
    """

    def __init__(self, group="SE3", bandwidth="auto", kernel="gaussian", threads=1):
        self.group = group
        self.bandwidth = bandwidth
        self.kernel = kernel
        self.threads = threads

    def fit(self, t, Y):
        group = _groups.get(self.group)
        t, Y = _arrays.trajectory(t, Y, group.matrix_size)
        threads = _arrays.positive_int(self.threads, "threads")
        if isinstance(self.bandwidth, str):
            if self.bandwidth != "auto":
                raise ValueError(f"bandwidth must be 'auto' or a number, got {self.bandwidth!r}")
            selection = _bireg.select_bandwidth(group.name, t, Y, self.kernel, threads)
            self.bandwidth_ = selection["bandwidth"]
            self.velocity_bandwidth_ = selection["velocity_bandwidth"]
            self.velocity_degree_ = selection["velocity_degree"]
            self.bandwidth_selection_ = selection
            if selection["message"]:
                warnings.warn(f"bandwidth auto: {selection['message']}", UserWarning,
                              stacklevel=2)
        else:
            self.bandwidth_ = self.velocity_bandwidth_ = float(self.bandwidth)
            self.velocity_degree_ = 2
            self.bandwidth_selection_ = None
        self._t, self._Y, self._group = t, Y, group
        return self

    def _smooth(self, t_new):
        if not hasattr(self, "_t"):
            raise ValueError("this LocalRegression is not fitted yet: call fit(t, Y) first")
        return _bireg.smooth(self._group.name, self._t, self._Y, _arrays.covariates(t_new),
                             self.kernel, self.bandwidth_, self.velocity_bandwidth_,
                             self.velocity_degree_,
                             _arrays.positive_int(self.threads, "threads"))

    def predict(self, t_new):
        """The local pose at each query: (M,) -> (M, n, n). ValueError if a
        query's local fit failed (``velocity`` reports per-query status)."""
        out = self._smooth(t_new)
        failed = np.flatnonzero(out["ok"] == 0)
        if failed.size:
            q = int(failed[0])
            raise ValueError(f"the local fit at query {q} failed: {out['message'][q]}")
        return out["pose"]

    def velocity(self, t_new):
        """Per query: the body velocity (per covariate unit), its standard
        errors (``velocity_standard_error_defined`` says where they exist),
        the pose, and ``ok``/``status``/``message`` per query. A dict."""
        out = self._smooth(t_new)
        out["ok"] = out["ok"].astype(bool)
        out["velocity_standard_error_defined"] = out["velocity_standard_error_defined"].astype(bool)
        return out
