"""bireg.two_sample_test: the statistics against an independent computation
with scipy's expm and logm, invariance, determinism, the element-wise map
against per-element tests and its q-values against Benjamini-Hochberg
computed here, and refusals as ValueError.

Calibration and power are simulated on the C++ side (tests/test_cohorts.cpp,
tests/test_cohort_maps.cpp), which this module calls unchanged."""

import numpy as np
import pytest

import bireg

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
    raise ValueError(group)


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
