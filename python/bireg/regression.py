"""Geodesic regression and the bi-invariant mean, scikit-learn style.

``GeodesicRegression(group=...).fit(t, Y)`` calls the C++ library's
``bireg::GeodesicRegression<G>::fit`` (include/bireg/regression.hpp) on the
arrays as given; attributes ending in ``_`` are set by ``fit``, except
``residuals_``, an (N, d) array copied from the fit when first read (at
N = 1e5 the copy was 1.5 % of the fit's time, which a caller who never
reads it need not pay).
"""

import warnings

import numpy as np

from . import _arrays, _bireg
from . import groups as _groups


class ConvergenceWarning(UserWarning):
    """A fit or mean stopped before converging; ``status_`` says how."""


_SUCCESS = ("converged", "rounding_floor")


class GeodesicRegression:
    """The bi-invariant geodesic regression of the paper *Bi-invariant
    Geodesic Regression* (Hanik and von Tycowicz).

    Parameters mirror ``bireg::RegressionOptions``: ``solver`` one of
    gauss_newton, preconditioned, optimal_linear, paper; ``method`` exact or
    series_adaptive; ``tol`` the step norm at convergence; ``max_iter``;
    ``threads`` for the force's chunks (results do not depend on it).
    ``loss`` None, or huber, cauchy or tukey for a robust fit
    (``bireg::RobustGeodesicRegression``) with constant ``loss_scale`` in
    Mahalanobis units (0: 95 % Gaussian efficiency); its weights and
    outliers are in ``robust_``.
    """

    def __init__(self, group="SE3", solver="gauss_newton", method="exact", tol=1e-10,
                 max_iter=1000, threads=1, loss=None, loss_scale=0.0):
        self.group = group
        self.solver = solver
        self.method = method
        self.tol = tol
        self.max_iter = max_iter
        self.threads = threads
        self.loss = loss
        self.loss_scale = loss_scale

    def fit(self, t, Y, sample_weight=None):
        """Fits the geodesic to Y[i] at t[i]; returns self.

        Raises ValueError for invalid input (the message names the
        observation); a fit that does not converge sets ``status_`` and
        warns with ConvergenceWarning.
        """
        group = _groups.get(self.group)
        t, Y = _arrays.trajectory(t, Y, group.matrix_size)
        w = _arrays.weights(sample_weight, t.shape[0])
        return self._adopt(_bireg.fit(group.name, t, Y, w, self.solver, self.method,
                                      float(self.tol),
                                      _arrays.positive_int(self.max_iter, "max_iter"),
                                      _arrays.positive_int(self.threads, "threads"),
                                      "none" if self.loss is None else str(self.loss),
                                      float(self.loss_scale)), stacklevel=3)

    def _adopt(self, fit, stacklevel):
        """Takes a fitted handle's results as this estimator's (fit, and
        bireg.dask.fit); warns at the caller `stacklevel` frames up."""
        self._fit = fit
        self.robust_ = fit.robust if self.loss is not None else None
        self.status_ = fit.status
        self.n_iter_ = fit.iterations
        self.diagnostics_ = fit.diagnostics
        self._residuals = None
        self.step_norms_ = fit.step_norms
        if fit.has_geodesic:
            self.g0_, self.g1_ = fit.g0, fit.g1
            self.interval_ = fit.interval
            self.body_velocity_ = fit.body_velocity
            self.spatial_velocity_ = fit.spatial_velocity(np.array([self.interval_[0]]))[0]
        else:
            self.g0_ = self.g1_ = self.interval_ = None
            self.body_velocity_ = self.spatial_velocity_ = None
        if self.status_ not in _SUCCESS:
            warnings.warn(f"the fit stopped with status {self.status_} after {self.n_iter_} "
                          "iterations", ConvergenceWarning, stacklevel=stacklevel)
        elif self.robust_ is not None and self.robust_["status"] != "converged":
            warnings.warn(f"the robust reweighting stopped with status {self.robust_['status']}: "
                          f"{self.robust_['message']}", ConvergenceWarning, stacklevel=stacklevel)
        return self

    @property
    def residuals_(self):
        """log(gamma(t_i)^-1 Y_i) of each observation at the fit, (N, d)."""
        if not hasattr(self, "_fit"):
            raise AttributeError("residuals_: this GeodesicRegression is not fitted yet")
        if self._fit.chunked:
            raise AttributeError("residuals_: a fit by bireg.dask.fit keeps its residuals with "
                                 "the chunks")
        if self._residuals is None:
            self._residuals = self._fit.residuals
        return self._residuals

    def _fitted(self):
        if not hasattr(self, "_fit"):
            raise ValueError("this GeodesicRegression is not fitted yet: call fit(t, Y) first")
        return self._fit

    def predict(self, t):
        """The fitted geodesic at t: (M,) -> (M, n, n)."""
        return self._fitted().predict(_arrays.covariates(t))

    def spatial_velocity(self, t):
        """The spatial velocity Ad_gamma(t) of the body velocity: (M,) -> (M, d)."""
        return self._fitted().spatial_velocity(_arrays.covariates(t))

    def score(self, t, Y):
        """The bi-invariant explained variance 1 - det S_res / det S_tot of the
        fitted geodesic on (t, Y)."""
        fit = self._fitted()
        group = _groups.get(self.group)
        t = _arrays.covariates(t)
        Y = _arrays.matrices(Y, group.matrix_size)
        return _bireg.score(fit, t, Y)

    def covariance(self, flavour="robust"):
        """Endpoint and velocity covariances (left-trivialised) and standard
        errors: a dict (bireg::covariance and velocity_covariance)."""
        return _bireg.covariance(self._fitted(), flavour)

    def confidence_band(self, t, level=0.95, flavour="robust"):
        """Per covariate, the half-widths of the pose's confidence region
        along each body-frame coordinate: (M,) -> (M, d)."""
        return _bireg.confidence_band(self._fitted(), _arrays.covariates(t), float(level),
                                      flavour)

    def trend_test(self, permutations=999, seed=0, threads=1):
        """The permutation test of 'no trend' (Wilks' Lambda): a dict with
        statistic and p_value (bireg::trend_test)."""
        return _bireg.trend_test(self._fitted(), _arrays.positive_int(permutations, "permutations"),
                                 _arrays.positive_int(seed, "seed"),
                                 _arrays.positive_int(threads, "threads"))


def mean(Y, group, sample_weight=None, tol=1e-10, max_iter=100):
    """The bi-invariant mean of Y (bireg::mean): an (n, n) array.

    Raises ValueError for invalid input; warns with ConvergenceWarning and
    returns the last usable iterate if the iteration did not converge.
    """
    g = _groups.get(group)
    Y = _arrays.matrices(Y, g.matrix_size)
    w = _arrays.weights(sample_weight, Y.shape[0])
    result = _bireg.mean(g.name, Y, w, float(tol), _arrays.positive_int(max_iter, "max_iter"))
    if result["status"] not in _SUCCESS:
        warnings.warn(f"the mean stopped with status {result['status']}", ConvergenceWarning,
                      stacklevel=2)
        if "mean" not in result:
            raise ValueError(f"the mean failed (status {result['status']}) with no finite iterate")
    return result["mean"]
