"""Bi-invariant spline regression: one cumulative B-spline through a whole
trajectory (bireg::SplineRegression, include/bireg/spline_regression.hpp;
the derivation in docs/splines.md), scikit-learn style.
"""

import warnings

import numpy as np

from . import _arrays, _bireg
from . import groups as _groups
from .regression import ConvergenceWarning

_SUCCESS = ("converged", "rounding_floor")


class SplineRegression:
    """``degree`` 1 (piecewise geodesic), 2 or 3; ``knot_spacing`` the largest
    spacing of the uniform knots in covariate units, or ``"auto"``: chosen
    by cross-validation (``bireg::select_knot_spacing`` over
    ``auto_knot_spacing_grid``), its curve in ``knot_selection_``.
    ``roughness_penalty`` lambda >= 0 of the second-difference penalty
    (``SplineOptions::roughness_penalty``, docs/splines.md §12; degree 2 or
    3; 0: none), or ``"auto"``: chosen by cross-validation
    (``bireg::select_roughness_penalty`` over
    ``auto_roughness_penalty_grid``) at the knot spacing given or, with
    ``knot_spacing="auto"``, at fine knots (``fine_knot_spacing``: 1.5
    median sample spacings), its curve in ``roughness_selection_``. ``tol``
    and ``max_iter`` of the Gauss-Newton iteration; ``threads`` for its
    passes (results do not depend on it).

    Attributes set by ``fit``: ``control_points_`` (M, n, n),
    ``first_knot_``, ``knot_spacing_`` (the spacing used: the range cut into
    equal segments no longer than asked), ``status_``, ``n_iter_``,
    ``equation_norm_``, ``residuals_`` (N, d), ``knot_selection_`` (a dict
    for "auto", else None), ``roughness_penalty_`` (the lambda used),
    ``roughness_selection_`` (a dict for "auto", else None),
    ``diagnostics_`` (a dict: the largest residual
    and knot-span angles and where they are, and ``beyond_domain``: either
    past 3 pi / 4, near the log's cut locus; a UserWarning says so), and of the sandwich covariance of the control
    points (``bireg::spline_covariance``, docs/splines.md §10):
    ``noise_covariance_`` (d, d) and ``degrees_of_freedom_`` (N - M for
    unit weights), None where it is undefined (a penalised fit among the
    reasons), with the reason in ``covariance_message_``.
    """

    def __init__(self, group="SE3", degree=3, knot_spacing="auto", roughness_penalty=0.0,
                 tol=1e-10, max_iter=100, threads=1):
        self.group = group
        self.degree = degree
        self.knot_spacing = knot_spacing
        self.roughness_penalty = roughness_penalty
        self.tol = tol
        self.max_iter = max_iter
        self.threads = threads

    def fit(self, t, Y, sample_weight=None):
        """Fits the spline to Y[i] at t[i]; returns self. ValueError for
        invalid input (a knot spacing the data cannot determine names the
        control point and its span); a fit that does not converge sets
        ``status_`` and warns with ConvergenceWarning."""
        group = _groups.get(self.group)
        t, Y = _arrays.trajectory(t, Y, group.matrix_size)
        w = _arrays.weights(sample_weight, t.shape[0])
        degree = _arrays.positive_int(self.degree, "degree")
        if isinstance(self.knot_spacing, str):
            if self.knot_spacing != "auto":
                raise ValueError(
                    f"knot_spacing must be 'auto' or a number, got {self.knot_spacing!r}")
            spacing = 0.0
        else:
            spacing = float(self.knot_spacing)
            if not spacing > 0:
                raise ValueError("knot_spacing must be a positive number (inf: one segment) or "
                                 f"'auto', got {self.knot_spacing!r}")
        roughness_auto = isinstance(self.roughness_penalty, str)
        if roughness_auto:
            if self.roughness_penalty != "auto":
                raise ValueError("roughness_penalty must be 'auto' or a number >= 0, got "
                                 f"{self.roughness_penalty!r}")
            roughness = 0.0
        else:
            try:
                roughness = float(self.roughness_penalty)
            except (TypeError, ValueError):
                roughness = float("nan")
            if not (roughness >= 0 and np.isfinite(roughness)):
                raise ValueError("roughness_penalty must be a finite number >= 0 or 'auto', "
                                 f"got {self.roughness_penalty!r}")
        out = _bireg.spline_fit(group.name, t, Y, w, degree, spacing, roughness, roughness_auto,
                                float(self.tol),
                                _arrays.positive_int(self.max_iter, "max_iter"),
                                _arrays.positive_int(self.threads, "threads"))
        self.control_points_ = out["control_points"]
        self.first_knot_ = out["first_knot"]
        self.knot_spacing_ = out["knot_spacing"]
        self.status_ = out["status"]
        self.n_iter_ = out["iterations"]
        self.equation_norm_ = out["equation_norm"]
        self.residuals_ = out["residuals"]
        self.diagnostics_ = out["diagnostics"]
        self.knot_selection_ = out.get("knot_selection")
        self.roughness_penalty_ = out["roughness_penalty"]
        self.roughness_selection_ = out.get("roughness_selection")
        self.noise_covariance_ = out.get("noise_covariance")
        self.degrees_of_freedom_ = out.get("degrees_of_freedom")
        self.covariance_message_ = out["covariance_message"]
        self._band = out.get("covariance_band")
        self._group, self._degree = group, degree
        if self.knot_selection_ is not None and self.knot_selection_["message"]:
            warnings.warn(f"knot spacing auto: {self.knot_selection_['message']}", UserWarning,
                          stacklevel=2)
        if self.roughness_selection_ is not None and self.roughness_selection_["message"]:
            warnings.warn(f"roughness penalty auto: {self.roughness_selection_['message']}",
                          UserWarning, stacklevel=2)
        if self.diagnostics_["beyond_domain"] and self.status_ in _SUCCESS:
            d = self.diagnostics_
            warnings.warn(
                "the spline nears the log's cut locus (beyond 3 pi/4): the largest residual "
                f"angle is {d['largest_residual_angle']:.3g} rad (observation "
                f"{d['largest_residual_observation']}), the largest knot span's turn "
                f"{d['largest_increment_angle']:.3g} rad (control points "
                f"{d['largest_increment'] - 1} to {d['largest_increment']}); a gross outlier, "
                "or knots too sparse for the motion", UserWarning, stacklevel=2)
        if self.status_ not in _SUCCESS:
            warnings.warn(f"the spline fit ended {self.status_}: {out['message']}",
                          ConvergenceWarning, stacklevel=2)
        return self

    def _check_fitted(self):
        if not hasattr(self, "control_points_"):
            raise ValueError("this SplineRegression is not fitted yet: call fit(t, Y) first")

    def _evaluate(self, t_new):
        self._check_fitted()
        return _bireg.spline_evaluate(self._group.name, self._degree, self.first_knot_,
                                      self.knot_spacing_, self.control_points_,
                                      _arrays.covariates(t_new))

    def predict(self, t_new):
        """The curve at each covariate: (M,) -> (M, n, n). A covariate beyond
        the knots is evaluated at the nearer end."""
        return self._evaluate(t_new)["pose"]

    def velocity(self, t_new):
        """Body velocity T^{-1} dT/dt per covariate unit: (M,) -> (M, d)."""
        return self._evaluate(t_new)["velocity"]

    def acceleration(self, t_new):
        """Body acceleration d/dt (T^{-1} dT/dt): (M,) -> (M, d)."""
        return self._evaluate(t_new)["acceleration"]

    def confidence_band(self, t_new, level=0.95, quantity="pose"):
        """Per covariate, the half-widths of the pointwise ``level``
        confidence region of the pose (left-trivialised: T^ = T exp(eps)) or
        of the body velocity (``quantity="velocity"``) along each body-frame
        coordinate (Hotelling's T^2 with ``degrees_of_freedom_``): (M,) ->
        (M, d). ValueError where the covariance is undefined (noise-free
        data, no degrees of freedom left, too many control points)."""
        self._check_fitted()
        if self._band is None:
            raise ValueError(f"the spline's covariance is undefined: {self.covariance_message_}")
        return _bireg.spline_band(self._group.name, self._degree, self.first_knot_,
                                  self.knot_spacing_, self.control_points_, self._band,
                                  self.noise_covariance_, float(self.degrees_of_freedom_),
                                  _arrays.covariates(t_new), float(level), str(quantity))
