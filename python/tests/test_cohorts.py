"""bireg.two_sample_test: the statistics against an independent computation
with scipy's expm and logm, invariance, determinism, the element-wise map
against per-element tests and its q-values against Benjamini-Hochberg
computed here, and refusals as ValueError.

Calibration and power are simulated on the C++ side (tests/test_cohorts.cpp,
tests/test_cohort_maps.cpp), which this module calls unchanged."""

import numpy as np
import pytest

import bireg
from conftest import GROUP_NAMES

linalg = pytest.importorskip("scipy.linalg")


# ---- an independent implementation: any matrix group, expm/logm, a basis ----

def algebra_basis(group):
    """A basis of the Lie algebra as matrices. The statistics do not depend
    on the basis (T^2 and the determinant ratios are unchanged by one
    invertible linear map of all coordinates), so this need not be bireg's."""
    def unit(n, i, j):
        e = np.zeros((n, n))
        e[i, j] = 1.0
        return e
    so3 = [unit(3, 2, 1) - unit(3, 1, 2), unit(3, 0, 2) - unit(3, 2, 0),
           unit(3, 1, 0) - unit(3, 0, 1)]
    if group == "SO3":
        return so3
    if group == "SE3":
        rotations = []
        for w in so3:
            x = np.zeros((4, 4))
            x[:3, :3] = w
            rotations.append(x)
        return [unit(4, i, 3) for i in range(3)] + rotations
    if group == "GLp3":
        return [unit(3, i, j) for i in range(3) for j in range(3)]
    # Another group: the principal logs of exp(0.1 e_i), scaled back, span
    # its algebra (bireg's exp only chooses the basis).
    g = bireg.groups.get(group)
    return [log(g.exp(0.1 * e)) / 0.1 for e in np.eye(g.dim)]


def coordinates(x, basis):
    flat = np.stack([b.ravel() for b in basis], axis=1)
    c, *_ = np.linalg.lstsq(flat, x.ravel(), rcond=None)
    return c


def log(g):
    return np.real(linalg.logm(g))


def group_mean(elements):
    """The exponential barycenter: m <- m exp(mean log(m^-1 f_i)), to 1e-15."""
    m = elements[0]
    for _ in range(200):
        step = np.mean([log(np.linalg.solve(m, f)) for f in elements], axis=0)
        m = m @ linalg.expm(step)
        if np.abs(step).max() < 1e-15:
            break
    return m


def adjoint(g, basis):
    return np.stack([coordinates(g @ b @ np.linalg.inv(g), basis) for b in basis], axis=1)


def statistics(a, b, group, variant):
    """T^2, D_B and H^2 of docs/cohorts.md, computed from scratch."""
    basis = algebra_basis(group)
    m_a, m_b = group_mean(a), group_mean(b)
    x_a = np.array([coordinates(log(np.linalg.solve(m_a, f)), basis) for f in a])
    x_b = np.array([coordinates(log(np.linalg.solve(m_b, f)), basis) for f in b])
    s_a = x_a.T @ x_a / len(a)
    s_b = x_b.T @ x_b / len(b)
    c_matrix = log(np.linalg.solve(m_a, m_b))
    c = coordinates(c_matrix, basis)
    if variant == "invariant":
        transport = adjoint(linalg.expm(c_matrix / 2), basis)
        s_b = transport @ s_b @ transport.T
    m, n = len(a), len(b)
    pooled = (m * s_a + n * s_b) / (m + n - 2)
    t2 = m * n / (m + n) * c @ np.linalg.solve(pooled, c)
    average = (s_a + s_b) / 2
    q = c @ np.linalg.solve(average, c)
    logdet = lambda s: np.linalg.slogdet(s)[1]  # noqa: E731
    d_b = q / 8 + 0.5 * (logdet(average) - 0.5 * (logdet(s_a) + logdet(s_b)))
    h2 = 1 - np.exp(0.25 * logdet(s_a) + 0.25 * logdet(s_b) - 0.5 * logdet(average) - q / 8)
    return {"hotelling": t2, "bhattacharyya": d_b, "hellinger": h2}


def centre_of(group, rng):
    g = bireg.groups.get(group)
    return g.exp(0.4 * rng.standard_normal(g.dim))


def sample(group, count, rng, shift=0.0, spread=0.15, centre=None):
    """count elements about `centre` (random if None) moved by exp(shift)."""
    g = bireg.groups.get(group)
    if centre is None:
        centre = centre_of(group, rng)
    centre = g.compose(centre, g.exp(np.full(g.dim, shift)))
    return g.compose(centre, g.exp(spread * rng.standard_normal((count, g.dim))))


# ---- the tests ---------------------------------------------------------------

@pytest.mark.parametrize("group", ["SO3", "SE3", "GLp3"])
@pytest.mark.parametrize("variant", ["invariant", "published"])
def test_statistics_equal_an_independent_computation(group, variant, rng):
    a = sample(group, 24, rng)
    b = sample(group, 19, rng, shift=0.05)
    expected = statistics(a, b, group, variant)
    for name, value in expected.items():
        result = bireg.two_sample_test(a, b, group=group, statistic=name, variant=variant,
                                       permutations=0)
        assert result.statistic == name and result.variant == variant
        assert result.value == pytest.approx(value, rel=1e-10)
        assert result.p_value == 1.0 and result.permutations == 0
    assert np.allclose(result.mean_a, group_mean(a), atol=1e-12)
    assert np.allclose(result.mean_b, group_mean(b), atol=1e-12)


@pytest.mark.parametrize("group", ["SO3", "SE3"])
def test_invariant_variant_is_unchanged_by_translation_inversion_and_exchange(group, rng):
    g = bireg.groups.get(group)
    a = sample(group, 15, rng)
    b = sample(group, 17, rng, shift=0.1)
    h, k = g.exp(rng.standard_normal(g.dim)), g.exp(rng.standard_normal(g.dim))
    for statistic in ["hotelling", "bhattacharyya", "hellinger"]:
        base = bireg.two_sample_test(a, b, group=group, statistic=statistic, permutations=99,
                                     seed=7)
        moved = [
            bireg.two_sample_test(g.compose(h, a), g.compose(h, b), group=group,
                                  statistic=statistic, permutations=99, seed=7),
            bireg.two_sample_test(g.compose(a, k), g.compose(b, k), group=group,
                                  statistic=statistic, permutations=99, seed=7),
            bireg.two_sample_test(g.inverse(a), g.inverse(b), group=group, statistic=statistic,
                                  permutations=99, seed=7),
        ]
        for other in moved:
            assert other.value == pytest.approx(base.value, rel=1e-9)
            assert other.p_value == base.p_value
        swapped = bireg.two_sample_test(b, a, group=group, statistic=statistic, permutations=0)
        assert swapped.value == pytest.approx(base.value, rel=1e-9)


def test_published_variant_changes_under_inversion(rng):
    g = bireg.SE3
    a = sample("SE3", 20, rng, spread=0.3)
    b = sample("SE3", 20, rng, shift=0.2, spread=0.3)
    data = bireg.two_sample_test(a, b, group="SE3", variant="published", permutations=0).value
    inverted = bireg.two_sample_test(g.inverse(a), g.inverse(b), group="SE3", variant="published",
                                     permutations=0).value
    assert abs(data - inverted) > 1e-6 * abs(data)


def test_p_value_does_not_depend_on_threads_and_detects_a_shift(rng):
    centre = centre_of("SO3", rng)
    a = sample("SO3", 20, rng, centre=centre)
    b = sample("SO3", 20, rng, centre=centre)
    b_shifted = bireg.SO3.compose(bireg.SO3.exp(np.array([0.3, 0.0, 0.0])), b)
    one = bireg.two_sample_test(a, b_shifted, group="SO3", permutations=499, seed=3, threads=1)
    two = bireg.two_sample_test(a, b_shifted, group="SO3", permutations=499, seed=3, threads=2)
    assert one.p_value == two.p_value and one.value == two.value
    # A shift of 2 noise standard deviations at n = 20 + 20 makes T^2 about
    # 40; a relabelling's is about chi^2_3 (P(> 40) ~ 1e-8): none reaches it.
    assert one.p_value == pytest.approx(1 / 500)
    assert one.at_least_as_extreme == 0
    same = bireg.two_sample_test(a, b, group="SO3", permutations=499, seed=3)
    assert same.p_value > 0.01


def benjamini_hochberg(p):
    order = np.argsort(p)
    ranked = p[order] * len(p) / np.arange(1, len(p) + 1)
    q = np.minimum.accumulate(ranked[::-1])[::-1]
    out = np.empty_like(q)
    out[order] = np.minimum(q, 1.0)
    return out


def test_elementwise_map_equals_per_element_tests(rng):
    subjects_a, subjects_b, elements = 12, 14, 5
    centres = [centre_of("SO3", rng) for _ in range(elements)]
    # Elements 0 and 1 differ between the cohorts, the others do not.
    a = np.stack([sample("SO3", subjects_a, rng, centre=c) for c in centres], axis=1)
    b = np.stack([sample("SO3", subjects_b, rng, centre=c, shift=0.2 if k < 2 else 0.0)
                  for k, c in enumerate(centres)], axis=1)
    result = bireg.two_sample_test(a, b, group="SO3", permutations=199, seed=11, mode="exact")
    assert isinstance(result, bireg.ElementwiseResult)
    assert result.value.shape == (elements,) and result.mode == "exact"
    for k in range(elements):
        alone = bireg.two_sample_test(a[:, k], b[:, k], group="SO3", permutations=199, seed=11)
        # The same relabellings, shared by every element.
        assert result.value[k] == pytest.approx(alone.value, rel=1e-12)
        assert result.p_value[k] == alone.p_value
    assert np.allclose(result.q_value, benjamini_hochberg(result.p_value), rtol=1e-12)
    assert np.all(result.p_fwer >= result.p_value)
    linearised = bireg.two_sample_test(a, b, group="SO3", permutations=199, seed=11,
                                       mode="linearised")
    assert linearised.mode == "linearised"
    assert np.all((linearised.p_value > 0) & (linearised.p_value <= 1))


@pytest.mark.parametrize("kwargs, message", [
    ({"statistic": "t"}, "unknown statistic 't'"),
    ({"variant": "other"}, "unknown variant 'other'"),
    ({"permutations": -1}, "permutations"),
    ({"threads": 0}, "threads"),
    ({"seed": -2}, "seed"),
    ({"mode": "linearised"}, "element-wise maps only"),
])
def test_bad_options_are_value_errors(kwargs, message, rng):
    a, b = sample("SO3", 10, rng), sample("SO3", 10, rng)
    with pytest.raises(ValueError, match=message):
        bireg.two_sample_test(a, b, group="SO3", **kwargs)


def test_bad_data_are_value_errors_naming_the_element(rng):
    a, b = sample("SO3", 10, rng), sample("SO3", 10, rng)
    b[4, 0, 0] = np.nan
    with pytest.raises(ValueError, match="sample B.*4"):
        bireg.two_sample_test(a, b, group="SO3", permutations=9)
    with pytest.raises(ValueError, match="shape"):
        bireg.two_sample_test(a[:, :2], b, group="SO3")
    with pytest.raises(ValueError, match="differ in K"):
        bireg.two_sample_test(a[:, None].repeat(2, 1), b[:, None].repeat(3, 1), group="SO3")
    # SE3 has d = 6: 3 + 3 subjects leave the pooled covariance singular
    # (rank m + n - 2 = 4 at most), and Bhattacharyya needs more than 6 each.
    with pytest.raises(ValueError, match="singular.*dimension 6"):
        bireg.two_sample_test(sample("SE3", 3, rng), sample("SE3", 3, rng), group="SE3")
    with pytest.raises(ValueError, match="more than 6 elements"):
        bireg.two_sample_test(sample("SE3", 6, rng), sample("SE3", 9, rng), group="SE3",
                              statistic="bhattacharyya")
    with pytest.raises(ValueError, match="unknown group"):
        bireg.two_sample_test(a, b, group="SO4")


# ---- trends -------------------------------------------------------------------

def block_diagonal(trends):
    """(S, 2, n, n) -> (S, 2n, 2n): G x G as block-diagonal matrices, whose
    exp, log and means are the factors' (the independent implementation
    above then works on G x G unchanged)."""
    count, _, n, _ = trends.shape
    out = np.zeros((count, 2 * n, 2 * n))
    out[:, :n, :n] = trends[:, 0]
    out[:, n:, n:] = trends[:, 1]
    return out


def product_basis(group):
    basis = algebra_basis(group)
    n = basis[0].shape[0]
    out = []
    for b in basis:
        for block in range(2):
            x = np.zeros((2 * n, 2 * n))
            x[block * n:(block + 1) * n, block * n:(block + 1) * n] = b
            out.append(x)
    return out


def subjects_about(start, velocity, count, rng, spread=0.05, noise=0.02, group="SO3"):
    """count subjects of 8 observations on t in [0, 1], each about the
    geodesic start exp(t velocity) moved by its own deviation."""
    g = bireg.groups.get(group)
    out = []
    for _ in range(count):
        own_start = g.compose(start, g.exp(spread * rng.standard_normal(g.dim)))
        own_velocity = velocity + spread * rng.standard_normal(g.dim)
        t = np.sort(rng.uniform(0, 1, 8))
        Y = g.compose(own_start, g.exp(t[:, None] * own_velocity))
        out.append((t, g.compose(Y, g.exp(noise * rng.standard_normal((8, g.dim))))))
    return out


def test_fit_many_evaluates_each_fit_on_the_shared_interval(rng):
    g = bireg.SO3
    start, velocity = g.exp(np.array([0.2, -0.1, 0.3])), np.array([0.5, 0.2, -0.4])
    subjects = subjects_about(start, velocity, 7, rng)
    result = bireg.fit_many(subjects, group="SO3", interval=(0.0, 1.0), threads=2)
    assert result.trends.shape == (7, 2, 3, 3) and (result.t0, result.t1) == (0.0, 1.0)
    for (t, Y), trend in zip(subjects, result.trends):
        alone = bireg.GeodesicRegression(group="SO3").fit(t, Y)
        assert np.allclose(trend, alone.predict([0.0, 1.0]), atol=1e-12)
    # Noise-free subjects on one geodesic: the trends are its ends.
    exact = subjects_about(start, velocity, 3, rng, spread=0.0, noise=0.0)
    ends = bireg.fit_many(exact, group="SO3", interval=(-1.0, 2.0)).trends
    for trend in ends:
        assert np.allclose(trend, g.compose(start, g.exp(np.outer([-1.0, 2.0], velocity))),
                           atol=1e-10)
    # The default interval: the smallest to the largest covariate of all.
    default = bireg.fit_many(subjects, group="SO3")
    everything = np.concatenate([t for t, _ in subjects])
    assert (default.t0, default.t1) == (everything.min(), everything.max())


def test_fit_many_refuses_when_a_subject_fails(rng):
    subjects = subjects_about(np.eye(3), np.array([0.3, 0.0, 0.0]), 4, rng)
    t, Y = subjects[2]
    Y = Y.copy()
    Y[5, 1, 1] = np.nan
    subjects[2] = (t, Y)
    with pytest.raises(ValueError, match="subject 2.*observation 5"):
        bireg.fit_many(subjects, group="SO3")
    with pytest.raises(ValueError, match="pair"):
        bireg.fit_many([np.zeros(3)], group="SO3")
    with pytest.raises(ValueError, match="t0 < t1"):
        bireg.fit_many(subjects[:2], group="SO3", interval=(1.0, 0.0))


def trend_velocities(group):
    """Two cohorts' mean velocities, 0.2 per unit apart in one coordinate
    (for SO3 the second: (0.4, 0, 0.1) and (0.4, 0.2, 0.1); else the first)."""
    if group == "SO3":
        return np.array([0.4, 0.0, 0.1]), np.array([0.4, 0.2, 0.1])
    dim = bireg.groups.get(group).dim
    a = np.linspace(0.4, -0.2, dim)
    return a, a + 0.2 * np.eye(dim)[0]


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_compare_trends_equals_the_test_on_block_diagonal_pairs(group, rng):
    g = bireg.groups.get(group)
    n = g.matrix_size
    start = g.exp(np.linspace(0.1, -0.3, g.dim))
    v_a, v_b = trend_velocities(group)
    a = bireg.fit_many(subjects_about(start, v_a, 16, rng, group=group), group=group,
                       interval=(0.0, 1.0)).trends
    b = bireg.fit_many(subjects_about(start, v_b, 18, rng, group=group), group=group,
                       interval=(0.0, 1.0)).trends
    result = bireg.compare_trends(a, b, group=group, permutations=999, seed=5)
    assert result.mean_a.shape == (2, n, n)
    assert result.covariance_a.shape == (2 * g.dim, 2 * g.dim)
    # The same statistic computed from scratch on G x G as block-diagonal matrices.
    basis = product_basis(group)
    pa, pb = block_diagonal(a), block_diagonal(b)
    m_a, m_b = group_mean(pa), group_mean(pb)
    x_a = np.array([coordinates(log(np.linalg.solve(m_a, f)), basis) for f in pa])
    x_b = np.array([coordinates(log(np.linalg.solve(m_b, f)), basis) for f in pb])
    c_matrix = log(np.linalg.solve(m_a, m_b))
    c = coordinates(c_matrix, basis)
    transport = adjoint(linalg.expm(c_matrix / 2), basis)
    s_b = transport @ (x_b.T @ x_b / len(pb)) @ transport.T
    pooled = (x_a.T @ x_a + len(pb) * s_b) / (len(pa) + len(pb) - 2)
    t2 = len(pa) * len(pb) / (len(pa) + len(pb)) * c @ np.linalg.solve(pooled, c)
    # bireg's means (chord steps, two_sample.hpp's split_mean) stop once a
    # step is at most MeanOptions' tolerance, 1e-10, so each is within about
    # 1e-10 of the root found here to 1e-15; c moves by up to 2e-10, and T^2,
    # quadratic in c, by up to 2 * 2e-10 / |c| relative. The covariances
    # change only to second order: at the mean the residuals sum to zero,
    # so moving it shifts them all alike and their scatter matrix by the
    # square of the shift. (|c| here is Euclidean in this basis, not the
    # pooled covariance's norm: an estimate, not a bound; the errors seen
    # were at most a third of it.)
    assert result.value == pytest.approx(t2, rel=4e-10 / np.linalg.norm(c))
    if group == "SO3":
        # A velocity that differs by 0.2 rad/unit, four between-subject
        # standard deviations: detected.
        assert result.p_value <= 0.01
        same = bireg.compare_trends(a[:8], a[8:], group="SO3", permutations=999, seed=5)
        assert same.p_value > 0.01


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_population_trend_against_its_definition(group, rng):
    g = bireg.groups.get(group)
    start, velocity = g.exp(np.linspace(0.3, 0.1, g.dim)), np.linspace(0.2, -0.3, g.dim)
    trends = bireg.fit_many(subjects_about(start, velocity, 30, rng, group=group), group=group,
                            interval=(0.0, 2.0)).trends
    population = bireg.population_trend(trends, (0.0, 2.0), group=group)
    basis = product_basis(group)
    pairs = block_diagonal(trends)
    mean = group_mean(pairs)
    assert np.allclose(block_diagonal(population.mean[None])[0], mean, atol=1e-12)
    y = np.array([coordinates(log(np.linalg.solve(mean, f)), basis) for f in pairs])
    s = y.T @ y / (len(pairs) - 1)
    # Coordinates here interleave the factors; the Mahalanobis distances do
    # not depend on the basis.
    distances = np.einsum("ij,ij->i", y, np.linalg.solve(s, y.T).T)
    assert np.allclose(population.mahalanobis_squared, distances, rtol=1e-9)
    m0, m1 = population.mean
    assert np.allclose(population.velocity, g.log(np.linalg.solve(m0, m1)) / 2.0, atol=1e-12)
    assert population.outlying.dtype == bool and population.outlying.shape == (30,)
    # 2 dim - 1 subjects, fewer than G x G has dimensions: refused (a
    # singular covariance; for SO2, one subject, too few for any).
    with pytest.raises(ValueError, match="population_trend"):
        bireg.population_trend(trends[:2 * g.dim - 1], (0.0, 2.0), group=group)


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_trends_at_one_covariate_and_velocities_in_every_group(group, rng):
    # At t0 the test of the trends' elements is the test of their starts;
    # the velocities' means are the means of log(g0^-1 g1) / (t1 - t0).
    g = bireg.groups.get(group)
    start = g.exp(np.linspace(0.2, -0.1, g.dim))
    v_a, v_b = trend_velocities(group)
    a = bireg.fit_many(subjects_about(start, v_a, 2 * g.dim + 4, rng, group=group), group=group,
                       interval=(0.0, 2.0)).trends
    b = bireg.fit_many(subjects_about(start, v_b, 2 * g.dim + 6, rng, group=group), group=group,
                       interval=(0.0, 2.0)).trends
    at_start = bireg.compare_trends_at(a, b, (0.0, 2.0), 0.0, group=group, permutations=99)
    starts = bireg.two_sample_test(a[:, 0], b[:, 0], group=group, permutations=99)
    assert at_start.value == starts.value and at_start.p_value == starts.p_value
    velocities = bireg.compare_velocities(a, b, (0.0, 2.0), group=group, permutations=99)
    own = g.log(np.linalg.solve(a[:, 0], a[:, 1])) / 2.0
    assert velocities.mean_a.shape == (g.dim,)
    assert np.allclose(velocities.mean_a, own.mean(0), atol=1e-12)


def test_velocities_and_trends_at_one_covariate(rng):
    start = bireg.SO3.exp(np.array([0.2, 0.1, -0.1]))
    a = bireg.fit_many(subjects_about(start, np.array([0.4, 0.0, 0.1]), 15, rng, spread=0.2),
                       group="SO3", interval=(0.0, 2.0)).trends
    b = bireg.fit_many(subjects_about(start, np.array([0.4, 0.3, 0.1]), 17, rng, spread=0.2),
                       group="SO3", interval=(0.0, 2.0)).trends
    # The velocities' T^2, computed here from its definition: v = log(g0^T g1) / 2,
    # Euclidean means and covariances (divisors m and n), pooled.
    va = bireg.SO3.log(np.einsum("sji,sjk->sik", a[:, 0], a[:, 1])) / 2.0
    vb = bireg.SO3.log(np.einsum("sji,sjk->sik", b[:, 0], b[:, 1])) / 2.0
    m, n = len(va), len(vb)
    c = vb.mean(0) - va.mean(0)
    s_a = np.cov(va.T, bias=True)
    s_b = np.cov(vb.T, bias=True)
    pooled = (m * s_a + n * s_b) / (m + n - 2)
    t2 = m * n / (m + n) * c @ np.linalg.solve(pooled, c)
    velocities = bireg.compare_velocities(a, b, (0.0, 2.0), group="SO3", permutations=999,
                                          seed=1)
    assert velocities.value == pytest.approx(t2, rel=1e-10)
    assert np.allclose(velocities.mean_a, va.mean(0), atol=1e-13)
    assert velocities.p_value <= 0.01  # a velocity 0.3 apart, spread 0.2 / 2 per unit
    # Left translation leaves the velocities unchanged: the same test.
    h = bireg.SO3.exp(np.array([1.0, -0.5, 0.2]))
    moved = bireg.compare_velocities(bireg.SO3.compose(h, a), bireg.SO3.compose(h, b),
                                     (0.0, 2.0), group="SO3", permutations=999, seed=1)
    assert moved.value == pytest.approx(velocities.value, rel=1e-9)
    assert moved.p_value == velocities.p_value
    # At t0 the test of the trends is the test of their starts.
    at_start = bireg.compare_trends_at(a, b, (0.0, 2.0), 0.0, group="SO3", permutations=199)
    starts = bireg.two_sample_test(a[:, 0], b[:, 0], group="SO3", permutations=199)
    assert at_start.value == starts.value and at_start.p_value == starts.p_value
    with pytest.raises(ValueError, match="compare_velocities: .*t0 < t1"):
        bireg.compare_velocities(a, b, (2.0, 0.0), group="SO3")
    with pytest.raises(ValueError, match="unknown group 'SO4'"):
        bireg.compare_trends_at(a, b, (0.0, 2.0), 1.0, group="SO4")


def test_shares_of_a_test_join_only_when_they_are_one_test(rng):
    from bireg import _bireg

    a = bireg.SO3.exp(0.3 * rng.standard_normal((12, 3)))
    b = bireg.SO3.exp(0.3 * rng.standard_normal((13, 3)) + [0.2, 0.0, 0.0])
    plan = bireg.cohorts._plan(a, b, "SO3", "hotelling", "invariant", 300, 4, 1, "exact")
    whole = plan.run_test()
    shares = [plan.run_test(200, 100), plan.run_test(0, 200)]
    joined = _bireg.combine_two_sample("SO3", shares)
    assert joined["p_value"] == whole["p_value"]
    assert joined["at_least_as_extreme"] == whole["at_least_as_extreme"]
    other_seed = bireg.cohorts._plan(a, b, "SO3", "hotelling", "invariant", 300, 5, 1, "exact")
    with pytest.raises(ValueError, match="seed"):
        _bireg.combine_two_sample("SO3", [plan.run_test(0, 200), other_seed.run_test(200, 100)])
    with pytest.raises(ValueError, match="do not tile"):
        _bireg.combine_two_sample("SO3", [plan.run_test(0, 200), plan.run_test(150, 150)])
