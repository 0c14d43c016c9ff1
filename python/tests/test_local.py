"""LocalRegression through Python: the velocity of a known motion, the same
bandwidth and velocities as bireg_smooth, equivariance, per-query status."""

import numpy as np
import pytest

import bireg
from conftest import geodesic_data


def spinning(n=200, rate=100.0, omega=(0.0, 0.0, 6.0), noise=0.01, seed=3):
    """A body turning about a fixed axis at `omega` rad/s, sampled at `rate` Hz."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    Y = bireg.SO3.exp(t[:, None] * np.asarray(omega) + noise * rng.standard_normal((n, 3)))
    return t, Y


def test_velocity_of_a_constant_spin_with_auto_bandwidth():
    t, Y = spinning()
    # 6 rad/s at 100 Hz: the turn cut binds from 0.1 s on, and past that
    # the velocity's criterion is flat to 0.2 % (its choice moves within
    # that noise, README "Local regression"); what must hold is the
    # velocity itself, against its reported standard errors.
    local = bireg.LocalRegression(group="SO3", bandwidth="auto").fit(t, Y)
    assert local.bandwidth_ > 0 and local.velocity_bandwidth_ > 0
    # The velocity's degree is chosen with its bandwidth, from two curves
    # over the same grid.
    assert local.velocity_degree_ in (2, 3)
    selection = local.bandwidth_selection_
    assert len(selection["cubic_velocity_criterion"]) == len(selection["grid"])
    best = np.nanmin(np.where(np.isfinite(selection["velocity_criterion"]),
                              selection["velocity_criterion"], np.inf))
    best_cubic = np.nanmin(np.where(np.isfinite(selection["cubic_velocity_criterion"]),
                                    selection["cubic_velocity_criterion"], np.inf))
    assert local.velocity_degree_ == (3 if best_cubic < best else 2)
    out = local.velocity(t[20:-20])
    assert out["ok"].all()
    v = out["velocity"]
    # Noise 0.01 rad per sample, 100 Hz: the velocity's error is a few
    # standard errors at most; check against the reported ones.
    err = np.abs(v - [0.0, 0.0, 6.0])
    assert (err < 5 * out["velocity_standard_error"] + 1e-9).mean() > 0.95
    assert np.abs(v[:, 2] - 6.0).max() < 0.5


def test_a_choice_at_the_grids_edge_is_reported():
    # A slow constant spin (1 rad over 2 s): the pose is predicted best by
    # the widest window, the grid's last value, and the user is told so.
    t, Y = spinning(omega=(0.0, 0.0, 0.5))
    with pytest.warns(UserWarning, match="pose's choice is the grid's largest value"):
        local = bireg.LocalRegression(group="SO3", bandwidth="auto").fit(t, Y)
    assert local.bandwidth_ == local.bandwidth_selection_["grid"][-1]


def test_local_regression_is_equivariant(rng):
    t, Y = geodesic_data("SE3", 60, rng)
    a = bireg.SE3.exp(0.5 * rng.standard_normal(6))
    b = bireg.SE3.exp(0.5 * rng.standard_normal(6))
    queries = np.linspace(0.1, 0.9, 7)
    base = bireg.LocalRegression(group="SE3", bandwidth=0.2).fit(t, Y)
    moved = bireg.LocalRegression(group="SE3", bandwidth=0.2).fit(
        t, bireg.SE3.compose(bireg.SE3.compose(a, Y), b))
    np.testing.assert_allclose(moved.predict(queries), a @ base.predict(queries) @ b, atol=1e-10)
    # Body velocities move by Ad(b^-1).
    v = base.velocity(queries)["velocity"]
    vm = moved.velocity(queries)["velocity"]
    np.testing.assert_allclose(vm, v @ bireg.SE3.Ad(np.linalg.inv(b)).T, atol=1e-9)
    inverted = bireg.LocalRegression(group="SE3", bandwidth=0.2).fit(t, bireg.SE3.inverse(Y))
    np.testing.assert_allclose(inverted.predict(queries),
                               np.linalg.inv(base.predict(queries)), atol=1e-10)


def test_local_refusals(rng):
    t, Y = geodesic_data("SO3", 20, rng)
    with pytest.raises(ValueError, match="bandwidth"):
        bireg.LocalRegression(group="SO3", bandwidth=-1.0).fit(t, Y).velocity(t)
    with pytest.raises(ValueError, match="query 1 is not finite"):
        bireg.LocalRegression(group="SO3", bandwidth=0.2).fit(t, Y).velocity([0.0, np.nan])
    with pytest.raises(ValueError, match="unknown kernel"):
        bireg.LocalRegression(group="SO3", bandwidth=0.2, kernel="box").fit(t, Y).velocity(t)
    with pytest.raises(ValueError, match="'auto' or a number"):
        bireg.LocalRegression(group="SO3", bandwidth="cv").fit(t, Y)
    Y[3] = 0.0
    with pytest.raises(ValueError, match="observation 3"):
        bireg.LocalRegression(group="SO3", bandwidth=0.2).fit(t, Y).velocity(t)
