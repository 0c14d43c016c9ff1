"""Comparing cohorts: the bi-invariant two-sample test of group elements and
the element-wise map (bireg/statistics/cohorts/, docs/cohorts.md).

``two_sample_test(A, B, group=...)`` calls ``bireg::two_sample_test<G>`` on
two samples of shape (m, n, n) and (k, n, n), or
``bireg::elementwise_two_sample_test<G>`` on subjects of K elements each,
(m, K, n, n) and (k, K, n, n). ``fit_many`` fits each subject's geodesic
and evaluates it on one shared interval, ``compare_trends`` tests two
cohorts' trends in G x G (``compare_trends_at``: at one covariate;
``compare_velocities``: their velocities), ``population_trend`` pools them. p-values come
from seeded relabellings and do not depend on ``threads``.
"""

from dataclasses import dataclass, replace

import numpy as np

from . import _arrays, _bireg
from . import groups as _groups


@dataclass(frozen=True)
class TwoSampleResult:
    """The test of two samples of elements (``bireg::TwoSampleResult``).

    ``value`` is T^2, D_B or H^2 of the data; ``p_value`` is
    (1 + #{b : T_b >= T}) / (B + 1) over ``permutations`` relabellings;
    ``mean_a``, ``mean_b`` the bi-invariant means, ``mean_difference``
    c = log(m_A^{-1} m_B), ``covariance_a`` S_A at m_A, ``covariance_b`` S_B
    at m_B and ``covariance_b_compared`` S_B as the statistic uses it
    (transported to m_A in the invariant variant).
    """

    statistic: str
    variant: str
    value: float
    p_value: float
    permutations: int
    at_least_as_extreme: int
    failed_permutations: int
    mean_a: np.ndarray
    mean_b: np.ndarray
    mean_difference: np.ndarray
    covariance_a: np.ndarray
    covariance_b: np.ndarray
    covariance_b_compared: np.ndarray


@dataclass(frozen=True)
class ElementwiseResult:
    """The element-wise map (``bireg::ElementwiseResult``): arrays over the K
    elements of the statistic, its p-value, the Benjamini-Hochberg q-value
    and the Westfall-Young max-statistic family-wise p-value, all from the
    same relabellings of the subjects."""

    statistic: str
    variant: str
    mode: str
    value: np.ndarray
    p_value: np.ndarray
    q_value: np.ndarray
    p_fwer: np.ndarray
    permutations: int
    failed_permutations: int


@dataclass(frozen=True)
class _TestPlan:
    """two_sample_test's arguments, checked and converted once: what a share
    of the test (bireg.dask) needs to run on a worker."""

    group: str
    a: np.ndarray          # (m, n, n), or (m K, n, n) for a map
    b: np.ndarray
    elements: int          # 0: a test of elements; K: a map
    statistic: str
    variant: str
    permutations: int
    seed: int
    threads: int
    mode: str
    first_element: int = 0  # a slice of a larger map: its elements' first index there

    def run_test(self, first_permutation=0, permutations=None):
        """The dict of bireg::two_sample_test on relabellings
        first_permutation .. + permutations - 1 (all by default)."""
        count = self.permutations if permutations is None else permutations
        return _bireg.two_sample_test(self.group, self.a, self.b, self.statistic, self.variant,
                                      count, self.seed, self.threads, first_permutation)

    def slice(self, first, count):
        """The plan of elements first .. first + count - 1 of this map alone:
        what one worker holds (bireg.dask)."""
        n = self.a.shape[-1]

        def part(x):
            x = x.reshape(-1, self.elements, n, n)[:, first:first + count]
            return np.ascontiguousarray(x).reshape(-1, n, n)

        return replace(self, a=part(self.a), b=part(self.b), elements=count,
                       first_element=self.first_element + first)

    def run_map(self):
        """The dict of bireg::elementwise_two_sample_test on this plan's elements."""
        K = self.elements
        return _bireg.elementwise_two_sample_test(
            self.group, self.a, self.a.shape[0] // K, self.b, self.b.shape[0] // K, K,
            self.statistic, self.variant, self.permutations, self.seed, self.threads, self.mode,
            self.first_element)


def _plan(A, B, group, statistic, variant, permutations, seed, threads, mode):
    g = _groups.get(group)
    n = g.matrix_size
    a = np.ascontiguousarray(A, dtype=np.float64)
    b = np.ascontiguousarray(B, dtype=np.float64)
    permutations = _arrays.positive_int(permutations, "permutations")
    seed = _arrays.seed(seed)
    threads = _arrays.positive_int(threads, "threads")
    if a.ndim == 3 and b.ndim == 3:
        a = _arrays.matrices(a, n, "A")
        b = _arrays.matrices(b, n, "B")
        if mode != "exact":
            raise ValueError(f"mode {mode!r} applies to element-wise maps only ((m, K, {n}, {n}) "
                             "arrays); a test of two samples of elements is exact")
        return _TestPlan(g.name, a, b, 0, statistic, variant, permutations, seed, threads, mode)
    if a.ndim == 4 and b.ndim == 4:
        if a.shape[2:] != (n, n) or b.shape[2:] != (n, n):
            raise ValueError(f"A and B must have shape (m, K, {n}, {n}) and (k, K, {n}, {n}), "
                             f"got {a.shape} and {b.shape}")
        if a.shape[1] != b.shape[1]:
            raise ValueError(f"A and B differ in K, the elements per subject ({a.shape[1]} vs "
                             f"{b.shape[1]})")
        m, elements, k = a.shape[0], a.shape[1], b.shape[0]
        if elements == 0:
            raise ValueError("K, the number of elements per subject, must be at least 1")
        return _TestPlan(g.name, a.reshape(m * elements, n, n), b.reshape(k * elements, n, n),
                         elements, statistic, variant, permutations, seed, threads, mode)
    raise ValueError(f"A and B must both have shape (m, {n}, {n}) or both (m, K, {n}, {n}), got "
                     f"{a.shape} and {b.shape}")


def _test_result(out):
    """A TwoSampleResult from the binding's dict (which also says which
    relabellings it ran, for joining shares)."""
    internal = ("first_permutation", "seed")
    return TwoSampleResult(**{k: v for k, v in out.items() if k not in internal})


def _map_result(out):
    """An ElementwiseResult from the binding's dict (which also carries the
    per-relabelling maxima, for joining slices)."""
    internal = ("ranked_value", "relabelling_maximum", "seed")
    return ElementwiseResult(**{k: v for k, v in out.items() if k not in internal})


def two_sample_test(A, B, group, statistic="hotelling", variant="invariant", permutations=9999,
                    seed=0, threads=1, mode="exact"):
    """The bi-invariant two-sample test of A against B.

    A (m, n, n) and B (k, n, n): a ``TwoSampleResult``. A (m, K, n, n) and
    B (k, K, n, n), K elements per subject (a shape's per-triangle
    deformation gradients, a skeleton's joint rotations): an
    ``ElementwiseResult``, with ``mode`` exact (means recomputed per
    relabelling) or linearised (coordinates at each element's pooled mean).
    ``statistic`` is hotelling, bhattacharyya or hellinger; ``variant``
    invariant (also under inversion) or published. Raises ValueError for
    invalid input, naming the sample and element. ``bireg.dask`` runs the
    same test on a cluster with the same result.
    """
    plan = _plan(A, B, group, statistic, variant, permutations, seed, threads, mode)
    if plan.elements == 0:
        return _test_result(plan.run_test())
    return _map_result(plan.run_map())


# ---- trends: one geodesic per subject, compared and pooled -------------------

@dataclass(frozen=True)
class FitManyResult:
    """Every subject's trend (gamma(t0), gamma(t1)) on the shared interval
    (``bireg::FitManyResult``): ``trends`` is (S, 2, n, n), ``n_iter`` the
    iterations of each subject's fit."""

    t0: float
    t1: float
    trends: np.ndarray
    n_iter: np.ndarray


@dataclass(frozen=True)
class PopulationTrend:
    """The two-stage population trend (``bireg::PopulationTrend``): the
    bi-invariant ``mean`` of the trends in G x G, (2, n, n); ``covariance``
    S of the subjects about it and ``mean_covariance`` S / N for N subjects
    (2d x 2d, G's coordinates at t0 first); the confidence region is the
    trends mean exp(delta) with N delta^T S^-1 delta <= ``radius_squared``; the
    population's body ``velocity`` per covariate unit with its covariance;
    per subject, ``mahalanobis_squared`` and ``outlying`` (above
    ``outlier_threshold``)."""

    mean: np.ndarray
    covariance: np.ndarray
    mean_covariance: np.ndarray
    radius_squared: float
    velocity: np.ndarray
    velocity_covariance: np.ndarray
    mahalanobis_squared: np.ndarray
    outlying: np.ndarray
    outlier_threshold: float


def _trends(trends, n, name):
    a = np.ascontiguousarray(trends, dtype=np.float64)
    if a.ndim != 4 or a.shape[1:] != (2, n, n):
        raise ValueError(f"{name} must have shape (S, 2, {n}, {n}) (fit_many's trends), "
                         f"got {a.shape}")
    return a


def _subject_arrays(subjects, g, first_subject=0):
    """Each subject's (t, Y) as the binding's arrays, named by cohort index."""
    t_list, y_list = [], []
    for i, subject in enumerate(subjects, start=first_subject):
        t, Y = _arrays.subject_pair(subject, i)
        t_list.append(_arrays.covariates(t, f"subject {i}'s t"))
        y_list.append(_arrays.matrices(Y, g.matrix_size, f"subject {i}'s Y"))
    return t_list, y_list


def _fit_block(subjects, group, t0, t1, threads, first_subject=0):
    """The binding's fit_many on one block of a cohort, whose first subject
    is subject ``first_subject`` of the cohort (for messages)."""
    g = _groups.get(group)
    t_list, y_list = _subject_arrays(subjects, g, first_subject)
    out = _bireg.fit_many(g.name, t_list, y_list, t0, t1, threads, first_subject)
    out["n_iter"] = out["n_iter"].astype(np.int64)
    return out


def _interval(interval):
    if interval is None:
        return float("nan"), float("nan")
    t0, t1 = (float(v) for v in interval)
    return t0, t1


def fit_many(subjects, group, interval=None, threads=1):
    """Fits one geodesic per subject, each a pair (t, Y) of shapes (N_i,)
    and (N_i, n, n), and evaluates it at the ends of one shared interval
    (``interval``, or from the smallest to the largest covariate of all
    subjects): a trend's ends are comparable between subjects only on one
    interval. Raises ValueError if any subject's fit fails, naming the
    first (no trend is returned for a fit that did not succeed).
    """
    t0, t1 = _interval(interval)
    threads = _arrays.positive_int(threads, "threads")
    return FitManyResult(**_fit_block(subjects, group, t0, t1, threads))


@dataclass(frozen=True)
class _TrendPlan:
    """compare_trends' arguments, checked once; ``run`` runs a share of the
    relabellings (bireg.dask)."""

    group: str
    a: np.ndarray
    b: np.ndarray
    statistic: str
    variant: str
    permutations: int
    seed: int
    threads: int

    def run(self, first_permutation=0, permutations=None):
        count = self.permutations if permutations is None else permutations
        return _bireg.compare_trends(self.group, self.a, self.b, self.statistic, self.variant,
                                     count, self.seed, self.threads, first_permutation)


def _trend_plan(trends_a, trends_b, group, statistic, variant, permutations, seed, threads):
    g = _groups.get(group)
    seed = _arrays.seed(seed)
    return _TrendPlan(g.name, _trends(trends_a, g.matrix_size, "trends_a"),
                      _trends(trends_b, g.matrix_size, "trends_b"), statistic, variant,
                      _arrays.positive_int(permutations, "permutations"), seed,
                      _arrays.positive_int(threads, "threads"))


def compare_trends(trends_a, trends_b, group, statistic="hotelling", variant="invariant",
                   permutations=9999, seed=0, threads=1):
    """The two-sample test of two cohorts' trends ((m, 2, n, n) and
    (k, 2, n, n), fit_many's ``trends`` on one interval) in G x G
    (``bireg::compare_trends``): a ``TwoSampleResult`` whose means are
    (2, n, n) and whose coordinates are 2d long."""
    plan = _trend_plan(trends_a, trends_b, group, statistic, variant, permutations, seed, threads)
    return _test_result(plan.run())


def compare_trends_at(trends_a, trends_b, interval, t, group, statistic="hotelling",
                      variant="invariant", permutations=9999, seed=0, threads=1):
    """The two-sample test of the cohorts' fitted elements at covariate
    ``t`` (``t = interval[0]``: the starts), from trends (S, 2, n, n) on
    ``interval`` = (t0, t1) (``bireg::compare_trends_at``): invariant under
    left and right translation, inversion and exchange. A
    ``TwoSampleResult`` whose means are (n, n)."""
    plan = _trend_plan(trends_a, trends_b, group, statistic, variant, permutations, seed, threads)
    t0, t1 = _interval(interval)
    out = _bireg.compare_trends_at(plan.group, plan.a, plan.b, t0, t1, float(t), plan.statistic,
                                   plan.variant, plan.permutations, plan.seed, plan.threads)
    return _test_result(out)


def compare_velocities(trends_a, trends_b, interval, group, statistic="hotelling",
                       permutations=9999, seed=0, threads=1):
    """The two-sample test of the cohorts' body velocities
    log(g0^-1 g1) / (t1 - t0), compared as vectors of the algebra
    (``bireg::compare_velocities``): "do the cohorts move differently?",
    whatever their starts. Invariant under left and right translation and
    exchange, not under inversion (docs/cohorts.md). A ``TwoSampleResult``
    whose means are velocities (d,)."""
    plan = _trend_plan(trends_a, trends_b, group, statistic, "invariant", permutations, seed,
                       threads)
    t0, t1 = _interval(interval)
    out = _bireg.compare_velocities(plan.group, plan.a, plan.b, t0, t1, plan.statistic,
                                    plan.permutations, plan.seed, plan.threads)
    return _test_result(out)


def population_trend(trends, interval, group, level=0.95, outlier_level=0.999):
    """The population trend of subjects' trends (S, 2, n, n) on ``interval``
    = (t0, t1), fit_many's (``bireg::population_trend``): a
    ``PopulationTrend``. Needs more than 2d + 1 subjects."""
    g = _groups.get(group)
    a = _trends(trends, g.matrix_size, "trends")
    t0, t1 = (float(v) for v in interval)
    out = _bireg.population_trend(g.name, a, t0, t1, float(level), float(outlier_level))
    out["outlying"] = out["outlying"].astype(bool)
    return PopulationTrend(**out)
