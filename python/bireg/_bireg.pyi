"""bireg's compiled core: bi-invariant regression on Lie groups"""

from collections.abc import Callable, Sequence
from typing import Annotated

import numpy
from numpy.typing import NDArray


def group_info(group: str) -> tuple[int, int]:
    """The group's (algebra dimension, matrix size)."""

def group_exp(group: str, x: Annotated[NDArray[numpy.float64], dict(shape=(None, None), order='C', device='cpu', writable=False)], out: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu')] | None) -> object:
    """
    exp of each row of x: (M, d) -> (M, n, n), a new array, or written to out (None returned).
    """

def group_log(group: str, g: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], out: Annotated[NDArray[numpy.float64], dict(shape=(None, None), order='C', device='cpu')] | None) -> object:
    """
    The principal log of each element: (M, n, n) -> (M, d), a new array, or written to out (None returned).
    """

def group_compose(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
    """a[i] b[i]: (M, n, n) twice -> (M, n, n)."""

def group_inverse(group: str, g: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
    """The inverse of each element."""

def group_Ad(group: str, g: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
    """The adjoint matrix of each element: (M, n, n) -> (M, d, d)."""

def group_right_jacobian(group: str, x: Annotated[NDArray[numpy.float64], dict(shape=(None, None), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
    """J_r(x) of each row of x: (M, d) -> (M, d, d)."""

def group_is_element(group: str, g: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], tol: float) -> NDArray[numpy.bool_]:
    """Whether each matrix is an element to tol: (M, n, n) -> (M,)."""

class FitHandle:
    """A geodesic fitted by bireg::GeodesicRegression, with its data."""

    @property
    def group(self) -> str: ...

    @property
    def chunked(self) -> bool: ...

    @property
    def status(self) -> str: ...

    @property
    def ok(self) -> bool: ...

    @property
    def iterations(self) -> int: ...

    @property
    def has_geodesic(self) -> bool: ...

    @property
    def interval(self) -> tuple[float, float]: ...

    @property
    def g0(self) -> NDArray[numpy.float64]: ...

    @property
    def g1(self) -> NDArray[numpy.float64]: ...

    @property
    def body_velocity(self) -> NDArray[numpy.float64]: ...

    @property
    def residuals(self) -> NDArray[numpy.float64]: ...

    @property
    def step_norms(self) -> NDArray[numpy.float64]: ...

    @property
    def diagnostics(self) -> dict: ...

    @property
    def robust(self) -> dict:
        """
        A robust fit's status, weights, distances and outliers (empty otherwise).
        """

    def predict(self, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
        """The fitted geodesic at each covariate: (M,) -> (M, n, n)."""

    def spatial_velocity(self, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)]) -> NDArray[numpy.float64]:
        """Ad_gamma(t) of the body velocity at each covariate: (M,) -> (M, d)."""

def fit(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], weights: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], solver: str, method: str, tol: float, max_iter: int, threads: int, loss: str, loss_scale: float) -> FitHandle:
    """
    bireg::GeodesicRegression<G>::fit (or RobustGeodesicRegression with a loss) of y at t with weights (empty: all 1). ValueError for invalid input.
    """

def fit_by_chunks(group: str, reduce: Callable, solver: str, method: str, tol: float, max_iter: int) -> FitHandle:
    """
    bireg::fit_by_chunks<G>: fit()'s steps on observations held in chunks elsewhere. reduce(request) gets a request's numbers and returns every chunk's chunk_sums numbers, in chunk order. ValueError for invalid input; what reduce raises passes through.
    """

def chunk_sums(group: str, request: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], weights: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], offset: int) -> NDArray[numpy.float64]:
    """
    bireg::chunk_sums<G> of one chunk (observation i is the whole set's offset + i), request and sums as numbers. The GIL is released.
    """

def spline_fit(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], weights: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], degree: int, knot_spacing: float, roughness_penalty: float, roughness_auto: bool, tol: float, max_iter: int, threads: int) -> dict:
    """
    bireg::SplineRegression<G>::fit (knot_spacing <= 0: chosen by select_knot_spacing, or fine_knot_spacing with roughness_auto; roughness_auto: lambda by select_roughness_penalty).
    """

def spline_evaluate(group: str, degree: int, first_knot: float, spacing: float, control_points: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)]) -> dict:
    """bireg::Spline<G>: pose, body velocity and acceleration at t."""

def spline_band(group: str, degree: int, first_knot: float, spacing: float, control_points: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], band: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], noise: Annotated[NDArray[numpy.float64], dict(shape=(None, None), order='C', device='cpu', writable=False)], nu: float, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], level: float, quantity: str) -> NDArray[numpy.float64]:
    """
    bireg::pose_covariance / velocity_covariance of a SplineCovariance: half-widths at t.
    """

def mean(group: str, y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], weights: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], tol: float, max_iter: int) -> dict:
    """bireg::mean<G>: a dict with the mean, status, iterations, residuals."""

def covariance(fit: FitHandle, flavour: str) -> dict:
    """
    bireg::covariance of a fit: endpoint, velocity and residual covariances.
    """

def confidence_band(fit: FitHandle, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], level: float, flavour: str) -> NDArray[numpy.float64]:
    """
    Half-widths of the pose's confidence region per covariate: (M,) -> (M, d).
    """

def score(fit: FitHandle, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)]) -> float:
    """The generalised explained variance of the fitted geodesic on (t, y)."""

def trend_test(fit: FitHandle, permutations: int, seed: int, threads: int) -> dict:
    """bireg::trend_test with the fit's options: statistic and p_value."""

def smooth(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], queries: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], kernel: str, bandwidth: float, velocity_bandwidth: float, velocity_degree: int, threads: int) -> dict:
    """
    LocalGeodesicRegression<G>::smooth_at: pose, velocity, standard errors, status per query.
    """

def select_bandwidth(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], kernel: str, threads: int) -> dict:
    """
    bireg::select_bandwidth over auto_bandwidth_grid: the pose's and the velocity's bandwidths.
    """

def read_trajectory(path: str, group: str, format: str, project: bool) -> dict:
    """bireg::io::read_trajectory<G>: t, Y, timestamps, lines, format."""

def format_trajectory(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], Y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], format: str, timestamps: Sequence[str] | None, timestamps_format: str) -> str:
    """
    bireg::io::format_trajectory<G>: the text of a trajectory file in `format`.
    """

def two_sample_test(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], statistic: str, variant: str, permutations: int, seed: int, threads: int, first_permutation: int = 0) -> dict:
    """
    bireg::two_sample_test<G>: a dict with the statistic, p-value, means and covariances; relabellings first_permutation .. first_permutation + permutations - 1.
    """

def combine_two_sample(group: str, shares: Sequence[dict]) -> dict:
    """
    bireg::combine_two_sample<G>: one test from two_sample_test's shares of its relabellings.
    """

def combine_elementwise(group: str, slices: Sequence[dict]) -> dict:
    """
    bireg::combine_elementwise<G>: one map from the maps of consecutive slices of the elements.
    """

def elementwise_two_sample_test(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], subjects_a: int, b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], subjects_b: int, elements: int, statistic: str, variant: str, permutations: int, seed: int, threads: int, mode: str, first_element: int = 0) -> dict:
    """
    bireg::elementwise_two_sample_test<G>: per-element statistics, p-, q- and FWER p-values.
    """

def fit_many(group: str, t: Sequence[Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)]], y: Sequence[Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)]], t0: float, t1: float, threads: int, first_subject: int = 0) -> dict:
    """
    bireg::fit_many<G>: every subject's trend (gamma(t0), gamma(t1)) on one interval.
    """

def compare_trends(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], statistic: str, variant: str, permutations: int, seed: int, threads: int, first_permutation: int = 0) -> dict:
    """
    bireg::compare_trends<G>: the two-sample test of two cohorts' trends in G x G.
    """

def compare_trends_at(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], t0: float, t1: float, t: float, statistic: str, variant: str, permutations: int, seed: int, threads: int) -> dict:
    """
    bireg::compare_trends_at<G>: the two-sample test of the trends' elements at t, in G.
    """

def compare_velocities(group: str, a: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], b: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], t0: float, t1: float, statistic: str, permutations: int, seed: int, threads: int) -> dict:
    """
    bireg::compare_velocities<G>: the two-sample test of the trends' body velocities.
    """

def population_trend(group: str, trends: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None, None), order='C', device='cpu', writable=False)], t0: float, t1: float, level: float, outlier_level: float) -> dict:
    """
    bireg::population_trend<G>: the mean trend, its confidence region, outlying subjects.
    """

def select_motion_model(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], Y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], folds: int, threads: int) -> dict:
    """
    bireg::select_motion_model on SE3 poses or Sim3 similarities: the candidates' table, the recommendation and its poses at t.
    """

def select_static_or_geodesic(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], Y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], folds: int, threads: int) -> dict:
    """
    bireg::select_static_or_geodesic<G>: the two candidates, the recommendation, the mean and the geodesic.
    """

def select_curve(group: str, t: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], Y: Annotated[NDArray[numpy.float64], dict(shape=(None, None, None), order='C', device='cpu', writable=False)], knot_spacings: Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C', device='cpu', writable=False)], threads: int) -> dict:
    """
    bireg::select_curve<G>: the geodesic, piecewise geodesics and cubic splines scored by the invariant criterion (empty knot_spacings: auto_knot_spacing_grid).
    """
