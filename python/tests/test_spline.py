"""SplineRegression through Python: a geodesic reproduced with its velocity,
degree 1 with one segment equal to GeodesicRegression, left and right
equivariance, the knot spacing and the roughness penalty by
cross-validation, the confidence bands
(one segment's against the geodesic's), and ValueError for what the C++
refuses."""

import warnings

import numpy as np
import pytest

import bireg
from conftest import geodesic_data


def test_a_noise_free_geodesic_is_reproduced_with_its_velocity():
    # A cubic spline reproduces a geodesic exactly (docs/splines.md and
    # test_smooth_tool); what is left is the Gauss-Newton tolerance.
    x = np.array([0.8, -0.4, 1.1])
    t = np.linspace(0.0, 5.9, 60)
    Y = bireg.SO3.exp(np.array([0.3, -1.2, 0.5]) + 0 * t[:, None])
    Y = bireg.SO3.compose(Y, bireg.SO3.exp(t[:, None] * x))
    spline = bireg.SplineRegression(group="SO3", knot_spacing=0.5).fit(t, Y)
    assert spline.status_ == "converged"
    queries = np.linspace(0.2, 5.7, 11)
    np.testing.assert_allclose(spline.velocity(queries), np.tile(x, (11, 1)), atol=1e-8)
    np.testing.assert_allclose(spline.acceleration(queries), 0.0, atol=1e-7)
    expected = bireg.SO3.compose(Y[:1], bireg.SO3.exp(queries[:, None] * x))
    np.testing.assert_allclose(spline.predict(queries), expected, atol=1e-8)


def test_degree_one_with_one_segment_is_the_geodesic(rng):
    t, Y = geodesic_data("SE3", 50, rng)
    geodesic = bireg.GeodesicRegression(group="SE3", tol=1e-13).fit(t, Y)
    spline = bireg.SplineRegression(group="SE3", degree=1, knot_spacing=np.inf,
                                    tol=1e-13).fit(t, Y)
    assert spline.control_points_.shape == (2, 4, 4)
    ends = np.array([t.min(), t.max()])
    np.testing.assert_allclose(spline.control_points_, geodesic.predict(ends), atol=1e-11)


def test_spline_regression_is_left_and_right_equivariant(rng):
    t, Y = geodesic_data("SE3", 80, rng)
    a = bireg.SE3.exp(0.5 * rng.standard_normal(6))
    b = bireg.SE3.exp(0.5 * rng.standard_normal(6))
    base = bireg.SplineRegression(group="SE3", knot_spacing=0.25, tol=1e-13).fit(t, Y)
    moved = bireg.SplineRegression(group="SE3", knot_spacing=0.25, tol=1e-13).fit(
        t, bireg.SE3.compose(bireg.SE3.compose(a, Y), b))
    np.testing.assert_allclose(moved.control_points_, a @ base.control_points_ @ b, atol=1e-9)
    queries = np.linspace(t.min(), t.max(), 9)
    v, vm = base.velocity(queries), moved.velocity(queries)
    np.testing.assert_allclose(vm, v @ bireg.SE3.Ad(np.linalg.inv(b)).T, atol=1e-8)


def test_auto_knot_spacing_reports_its_curve(rng):
    # Data about one geodesic: one segment (the whole range, the grid's
    # last value) predicts best, and the user is told the choice is at the
    # grid's edge.
    t, Y = geodesic_data("SO3", 120, rng)
    with pytest.warns(UserWarning, match="the grid's largest value"):
        spline = bireg.SplineRegression(group="SO3").fit(t, Y)
    selection = spline.knot_selection_
    assert selection["knot_spacing"] == selection["grid"][-1]
    assert selection["knot_spacing"] in selection["grid"]
    chosen = int(np.flatnonzero(selection["grid"] == selection["knot_spacing"])[0])
    valid = np.isfinite(selection["criterion"])
    assert selection["criterion"][chosen] == selection["criterion"][valid].min()
    assert len(selection["refusals"]) == len(selection["grid"])
    # Every refused spacing says why.
    assert all(bool(r) for r, ok in zip(selection["refusals"], valid) if not ok)


def test_auto_roughness_penalty_reports_its_curve_and_is_reproducible(rng):
    # Noisy data about one geodesic, evenly spaced: a geodesic is in the
    # penalty's null space (every second difference of its increments is
    # zero), so cross-validation chooses a strong penalty: at least 10
    # times the 1.5 observations per knot span (a window of about 1.8
    # spans; beyond some lambda the criterion is flat up to its noise).
    # Fine knots: 1.5 sample spacings.
    n = 150
    t = np.linspace(0.0, 1.0, n)
    _, Y = geodesic_data("SO3", n, rng)
    Y = bireg.SO3.compose(bireg.SO3.exp(0.8 * t[:, None] * np.array([1.0, -0.5, 0.3])), Y)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        spline = bireg.SplineRegression(group="SO3", roughness_penalty="auto").fit(t, Y)
    assert spline.knot_selection_ is None
    assert 0.95 * 1.5 / (n - 1) < spline.knot_spacing_ <= 1.5 / (n - 1) * (1 + 1e-12)
    selection = spline.roughness_selection_
    valid = np.isfinite(selection["criterion"])
    chosen = int(np.flatnonzero(selection["grid"] == selection["roughness_penalty"])[0])
    assert selection["criterion"][chosen] == selection["criterion"][valid].min()
    assert spline.roughness_penalty_ == selection["roughness_penalty"] >= 10 * 1.5
    # A choice at the grid's edge, and only that, is warned about.
    warned = [w for w in caught if "roughness penalty auto" in str(w.message)]
    assert len(warned) == (1 if selection["at_edge"] else 0)
    # The same lambda and knots given by hand: the same fit, bit for bit.
    given = bireg.SplineRegression(group="SO3", knot_spacing=1.5 / (n - 1),
                                   roughness_penalty=spline.roughness_penalty_).fit(t, Y)
    np.testing.assert_array_equal(given.control_points_, spline.control_points_)
    # A penalised fit has no sandwich band, and says why.
    with pytest.raises(ValueError, match="roughness penalty"):
        spline.confidence_band(t[:3])


def test_refusals_are_value_errors(rng):
    t, Y = geodesic_data("SO3", 30, rng)
    with pytest.raises(ValueError, match="control points for 30 observations"):
        bireg.SplineRegression(group="SO3", knot_spacing=1e-4).fit(t, Y)
    with pytest.raises(ValueError, match="degree must be 1, 2 or 3"):
        bireg.SplineRegression(group="SO3", degree=4, knot_spacing=0.5).fit(t, Y)
    with pytest.raises(ValueError, match="knot_spacing must be"):
        bireg.SplineRegression(group="SO3", knot_spacing="wide").fit(t, Y)
    with pytest.raises(ValueError, match="knot_spacing must be"):
        bireg.SplineRegression(group="SO3", knot_spacing=-1.0).fit(t, Y)
    for bad in ("smooth", -1.0, np.nan, None):
        with pytest.raises(ValueError, match="roughness_penalty must be"):
            bireg.SplineRegression(group="SO3", roughness_penalty=bad).fit(t, Y)
    with pytest.raises(ValueError, match="degree 2 or 3"):
        bireg.SplineRegression(group="SO3", degree=1, knot_spacing=0.5,
                               roughness_penalty=1.0).fit(t, Y)
    with pytest.raises(ValueError, match="roughness penalty auto: .*degree 2 or 3"):
        bireg.SplineRegression(group="SO3", degree=1, roughness_penalty="auto").fit(t, Y)
    Y_bad = Y.copy()
    Y_bad[4, 0, 0] = np.nan
    with pytest.raises(ValueError, match="observation 4"):
        bireg.SplineRegression(group="SO3", knot_spacing=0.5).fit(t, Y_bad)
    with pytest.raises(ValueError, match="not fitted yet"):
        bireg.SplineRegression(group="SO3").predict(t)


def test_confidence_band_of_one_segment_is_the_geodesics(rng):
    # Degree 1 on one segment is the geodesic, and its sandwich covariance
    # the geodesic's homoscedastic one up to the Gauss-Newton matrices'
    # J_l(r)^{-1} = I + O(|r|) (tests/test_spline_inference.cpp): within
    # about the noise, 0.01, relative.
    t, Y = geodesic_data("SE3", 50, rng, noise=0.01)
    spline = bireg.SplineRegression(group="SE3", degree=1, knot_spacing=np.inf,
                                    tol=1e-13).fit(t, Y)
    geodesic = bireg.GeodesicRegression(group="SE3", tol=1e-13).fit(t, Y)
    assert spline.degrees_of_freedom_ == pytest.approx(48)
    assert spline.noise_covariance_.shape == (6, 6)
    queries = np.linspace(t.min(), t.max(), 7)
    np.testing.assert_allclose(spline.confidence_band(queries),
                               geodesic.confidence_band(queries, flavour="homoscedastic"),
                               rtol=0.01)
    velocity = spline.confidence_band(queries, level=0.9, quantity="velocity")
    assert velocity.shape == (7, 6)
    assert np.all(np.isfinite(velocity)) and np.all(velocity > 0)
    # A wider level, a wider band.
    assert np.all(spline.confidence_band(queries, level=0.99) >
                  spline.confidence_band(queries, level=0.9))


def test_confidence_band_refusals(rng):
    # Noise-free data: the covariance is undefined, and says why.
    t = np.linspace(0.0, 1.0, 40)
    Y = bireg.SO3.exp(t[:, None] * np.array([0.4, -0.2, 0.9]))
    spline = bireg.SplineRegression(group="SO3", knot_spacing=0.25).fit(t, Y)
    assert spline.noise_covariance_ is None
    assert "vanish" in spline.covariance_message_
    with pytest.raises(ValueError, match="covariance is undefined.*vanish"):
        spline.confidence_band(t)
    t, Y = geodesic_data("SO3", 40, rng)
    spline = bireg.SplineRegression(group="SO3", knot_spacing=0.25).fit(t, Y)
    with pytest.raises(ValueError, match="level must lie in"):
        spline.confidence_band(t, level=1.5)
    with pytest.raises(ValueError, match="quantity must be"):
        spline.confidence_band(t, quantity="acceleration")
    with pytest.raises(ValueError, match="not fitted yet"):
        bireg.SplineRegression(group="SO3").confidence_band(t)


def test_a_knot_span_near_a_half_turn_is_reported():
    # 2.6 rad per knot span about z (tests/test_spline.cpp): past 3 pi / 4.
    t = np.linspace(0.0, 4.0, 201)
    Y = bireg.SO3.exp(t[:, None] * np.array([0.0, 0.0, 2.6]))
    with pytest.warns(UserWarning, match="cut locus"):
        spline = bireg.SplineRegression(group="SO3", knot_spacing=1.0).fit(t, Y)
    assert spline.diagnostics_["beyond_domain"]
    assert spline.diagnostics_["largest_increment_angle"] > 0.75 * np.pi
