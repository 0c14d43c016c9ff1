"""Comparing cohorts: the bi-invariant two-sample test of group elements and
the element-wise map (bireg/statistics/cohorts/, docs/cohorts.md).

``two_sample_test(A, B, group=...)`` calls ``bireg::two_sample_test<G>`` on
two samples of shape (m, n, n) and (k, n, n), or
``bireg::elementwise_two_sample_test<G>`` on subjects of K elements each,
(m, K, n, n) and (k, K, n, n). p-values come from seeded relabellings and
do not depend on ``threads``.
"""

from dataclasses import dataclass

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
    invalid input, naming the sample and element.
    """
    g = _groups.get(group)
    n = g.matrix_size
    a = np.ascontiguousarray(A, dtype=np.float64)
    b = np.ascontiguousarray(B, dtype=np.float64)
    permutations = _arrays.positive_int(permutations, "permutations")
    seed = _arrays.positive_int(seed, "seed")
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    threads = _arrays.positive_int(threads, "threads")
    if a.ndim == 3 and b.ndim == 3:
        a = _arrays.matrices(a, n, "A")
        b = _arrays.matrices(b, n, "B")
        if mode != "exact":
            raise ValueError(f"mode {mode!r} applies to element-wise maps only ((m, K, {n}, {n}) "
                             "arrays); a test of two samples of elements is exact")
        out = _bireg.two_sample_test(g.name, a, b, statistic, variant, permutations, seed,
                                     threads)
        return TwoSampleResult(**out)
    if a.ndim == 4 and b.ndim == 4:
        if a.shape[2:] != (n, n) or b.shape[2:] != (n, n):
            raise ValueError(f"A and B must have shape (m, K, {n}, {n}) and (k, K, {n}, {n}), "
                             f"got {a.shape} and {b.shape}")
        if a.shape[1] != b.shape[1]:
            raise ValueError(f"A and B differ in K, the elements per subject ({a.shape[1]} vs "
                             f"{b.shape[1]})")
        m, elements, k = a.shape[0], a.shape[1], b.shape[0]
        out = _bireg.elementwise_two_sample_test(
            g.name, a.reshape(m * elements, n, n), m, b.reshape(k * elements, n, n), k, elements,
            statistic, variant, permutations, seed, threads, mode)
        return ElementwiseResult(**out)
    raise ValueError(f"A and B must both have shape (m, {n}, {n}) or both (m, K, {n}, {n}), got "
                     f"{a.shape} and {b.shape}")
