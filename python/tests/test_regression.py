"""GeodesicRegression and mean through Python: the same numbers as the C++
tool bireg_fit, equivariance under left and right translation and
inversion, statistics whose definitions can be checked, and every refusal
a ValueError."""

import json
import subprocess
import warnings

import numpy as np
import pytest

import bireg
from conftest import DATA, GROUP_NAMES, bireg_fit_path, geodesic_data

SOLVERS = ["gauss_newton", "preconditioned", "optimal_linear", "paper"]


def run_bireg_fit(path, group, solver):
    tool = bireg_fit_path()
    if tool is None:
        pytest.skip("bireg_fit is not built (set BIREG_FIT or build build/tools)")
    out = subprocess.run([str(tool), "--group", group, "--solver", solver, "--threads", "1",
                          str(path)], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def write_matrix_file(path, t, Y):
    with open(path, "w") as f:
        for ti, yi in zip(t, Y):
            f.write(", ".join(repr(float(v)) for v in [ti, *yi.ravel()]) + "\n")


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("file, group", [("se3_deepmimic_walk.tum", "SE3"),
                                         ("so3_xio_imu_window.csv", "SO3")])
def test_shipped_data_fit_equals_bireg_fit(file, group, solver):
    expected = run_bireg_fit(DATA / file, group, solver)
    data = bireg.read_trajectory(DATA / file, group=group)
    reg = bireg.GeodesicRegression(group=group, solver=solver).fit(data["t"], data["Y"])
    assert reg.status_ == expected["status"]
    assert reg.n_iter_ == expected["iterations"]
    np.testing.assert_allclose(reg.g0_, expected["g0"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(reg.g1_, expected["g1"], rtol=0, atol=1e-12)
    # bireg_fit reports the interval in the file's times; Python's t counts
    # from the earliest of them (data["origin"]).
    origin = float(data["origin"])
    assert np.add(reg.interval_, origin) == pytest.approx((expected["t_min"], expected["t_max"]),
                                                          abs=1e-12)


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_every_group_equals_bireg_fit(group, rng, tmp_path):
    t, Y = geodesic_data(group, 40, rng)
    path = tmp_path / "data.csv"
    write_matrix_file(path, t, Y)
    expected = run_bireg_fit(path, group, "gauss_newton")
    data = bireg.read_trajectory(path, group=group, format="matrix")
    # The reader subtracts the origin exactly and rounds once; t - t.min()
    # rounds once too, so the two agree to half an ulp of 1.
    np.testing.assert_allclose(data["t"], t - t.min(), rtol=0, atol=2.3e-16)
    reg = bireg.GeodesicRegression(group=group).fit(data["t"], data["Y"])
    np.testing.assert_allclose(reg.g0_, expected["g0"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(reg.g1_, expected["g1"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_fit_is_left_right_and_inverse_equivariant(group, rng):
    g = bireg.groups.get(group)
    t, Y = geodesic_data(group, 50, rng)
    a = g.exp(0.7 * rng.standard_normal(g.dim))
    b = g.exp(0.7 * rng.standard_normal(g.dim))
    base = bireg.GeodesicRegression(group=group).fit(t, Y)
    moved = bireg.GeodesicRegression(group=group).fit(t, g.compose(g.compose(a, Y), b))
    inverted = bireg.GeodesicRegression(group=group).fit(t, g.inverse(Y))
    scale = max(1.0, np.abs(base.g0_).max())
    np.testing.assert_allclose(moved.g0_, a @ base.g0_ @ b, atol=1e-10 * scale)
    np.testing.assert_allclose(moved.g1_, a @ base.g1_ @ b, atol=1e-10 * scale)
    np.testing.assert_allclose(inverted.g0_, np.linalg.inv(base.g0_), atol=1e-10 * scale)
    np.testing.assert_allclose(inverted.g1_, np.linalg.inv(base.g1_), atol=1e-10 * scale)
    m = bireg.mean(Y, group=group)
    np.testing.assert_allclose(bireg.mean(g.compose(g.compose(a, Y), b), group=group),
                               a @ m @ b, atol=1e-10 * scale)
    np.testing.assert_allclose(bireg.mean(g.inverse(Y), group=group), np.linalg.inv(m),
                               atol=1e-10 * scale)


def test_predict_velocity_and_order_independence(rng):
    t, Y = geodesic_data("SE3", 60, rng)
    reg = bireg.GeodesicRegression(group="SE3").fit(t, Y)
    t0, t1 = reg.interval_
    np.testing.assert_allclose(reg.predict([t0, t1]), [reg.g0_, reg.g1_], atol=1e-14)
    # The body velocity is log(g0^-1 g1) per covariate unit.
    np.testing.assert_allclose(reg.body_velocity_ * (t1 - t0),
                               bireg.SE3.log(np.linalg.inv(reg.g0_) @ reg.g1_), atol=1e-12)
    np.testing.assert_allclose(reg.spatial_velocity_, bireg.SE3.Ad(reg.g0_) @ reg.body_velocity_,
                               atol=1e-12)
    order = rng.permutation(len(t))
    shuffled = bireg.GeodesicRegression(group="SE3").fit(t[order], Y[order])
    np.testing.assert_allclose(shuffled.g0_, reg.g0_, atol=1e-12)
    # Residuals in input order: r_i = log(gamma(t_i)^-1 Y_i).
    r = bireg.SE3.log(bireg.SE3.compose(bireg.SE3.inverse(reg.predict(t)), Y))
    np.testing.assert_allclose(reg.residuals_, r, atol=1e-12)


def test_score_covariance_band_and_trend_test(rng):
    t, Y = geodesic_data("SO3", 80, rng, speed=1.0, noise=0.05)
    reg = bireg.GeodesicRegression(group="SO3").fit(t, Y)
    # On the fitted data, score is the generalised explained variance,
    # between 0 and 1 and near 1 for a strong trend with small noise.
    score = reg.score(t, Y)
    assert 0.9 < score < 1
    cov = reg.covariance("robust")
    assert cov["velocity"].shape == (3, 3)
    np.testing.assert_allclose(cov["velocity_standard_errors"], np.sqrt(np.diag(cov["velocity"])))
    band = reg.confidence_band([0.0, 0.5, 1.0], level=0.95)
    assert band.shape == (3, 3) and (band > 0).all()
    # A wider level gives a wider band.
    assert (reg.confidence_band([0.5], level=0.99) > band[1]).all()
    test = reg.trend_test(permutations=99, seed=1)
    assert test["p_value"] == pytest.approx(1 / 100)  # no permutation beats a real trend
    flat = bireg.GeodesicRegression(group="SO3").fit(t, Y[rng.permutation(len(t))])
    assert flat.trend_test(permutations=99, seed=1)["p_value"] > 0.01


def test_convergence_warning_and_no_nan(rng):
    t, Y = geodesic_data("SE3", 30, rng, noise=0.2)
    with pytest.warns(bireg.ConvergenceWarning, match="max_iterations"):
        reg = bireg.GeodesicRegression(group="SE3", max_iter=1, tol=0).fit(t, Y)
    assert reg.status_ == "max_iterations"
    assert np.isfinite(reg.g0_).all() and np.isfinite(reg.residuals_).all()


@pytest.mark.parametrize(
    "kwargs, t, Y, message",
    [
        ({}, np.arange(3.0), np.stack([np.eye(4)] * 2), "differ in length"),
        ({}, np.arange(3.0), np.stack([np.eye(3)] * 3), r"shape \(N, 4, 4\)"),
        ({}, np.array([0.0, np.nan, 2.0]), np.stack([np.eye(4)] * 3), "covariate 1"),
        ({}, np.arange(3.0), np.stack([np.eye(4), np.full((4, 4), np.nan), np.eye(4)]),
         "observation 1"),
        ({}, np.arange(3.0), np.stack([np.eye(4), 2 * np.eye(4), np.eye(4)]), "observation 1"),
        ({"group": "SE4"}, np.arange(3.0), np.stack([np.eye(4)] * 3), "unknown group"),
        ({"solver": "newton"}, np.arange(3.0), np.stack([np.eye(4)] * 3), "unknown solver"),
        ({"method": "taylor"}, np.arange(3.0), np.stack([np.eye(4)] * 3), "unknown method"),
        ({"tol": -1.0}, np.arange(3.0), np.stack([np.eye(4)] * 3), "tolerance"),
        ({"threads": 0}, np.arange(3.0), np.stack([np.eye(4)] * 3), "threads"),
        ({"max_iter": 2.5}, np.arange(3.0), np.stack([np.eye(4)] * 3), "max_iter"),
    ],
)
def test_fit_refusals_are_value_errors(kwargs, t, Y, message):
    with pytest.raises(ValueError, match=message):
        bireg.GeodesicRegression(**kwargs).fit(t, Y)


def test_other_refusals():
    with pytest.raises(ValueError, match="not fitted"):
        bireg.GeodesicRegression().predict([0.0])
    t = np.arange(4.0)
    Y = bireg.SE3.exp(0.1 * np.arange(24.0).reshape(4, 6))
    reg = bireg.GeodesicRegression().fit(t, Y)
    with pytest.raises(ValueError, match="sample_weight"):
        bireg.GeodesicRegression().fit(t, Y, sample_weight=[1.0, 2.0])
    with pytest.raises(ValueError, match="covariance flavour"):
        reg.covariance("sandwich")
    with pytest.raises(ValueError, match="level"):
        reg.confidence_band([0.0], level=1.5)
    with pytest.raises(ValueError, match="covariate 0"):
        reg.predict([np.inf])
    with pytest.raises(ValueError, match="permutations"):
        reg.trend_test(permutations=0)
    with pytest.raises(ValueError, match="mean of no observations"):
        bireg.mean(np.empty((0, 4, 4)), group="SE3")
    with pytest.raises(ValueError, match="unknown format"):
        bireg.read_trajectory(DATA / "se3_deepmimic_walk.tum", format="csv")
    with pytest.raises(FileNotFoundError):
        bireg.read_trajectory(DATA / "missing.tum")


def test_version_matches_the_cpp_header():
    import re
    from conftest import ROOT
    cmake = (ROOT / "CMakeLists.txt").read_text()
    assert bireg.__version__ == re.search(r"project\(bireg\s+VERSION\s+([0-9.]+)", cmake).group(1)


@pytest.mark.parametrize("loss", ["huber", "tukey"])
def test_robust_fit_equals_bireg_fit_and_flags_the_outlier(loss, rng, tmp_path):
    t, Y = geodesic_data("SE3", 40, rng, noise=0.02)
    Y[17] = Y[17] @ bireg.SE3.exp([0.5, -0.4, 0.3, 0.9, 0.6, -0.8])  # one gross outlier
    path = tmp_path / "outlier.csv"
    write_matrix_file(path, t, Y)
    tool = bireg_fit_path()
    if tool is None:
        pytest.skip("bireg_fit is not built (set BIREG_FIT or build build/tools)")
    out = subprocess.run([str(tool), "--group", "SE3", "--loss", loss, "--threads", "1",
                          str(path)], capture_output=True, text=True, check=True)
    expected = json.loads(out.stdout)
    reg = bireg.GeodesicRegression(group="SE3", loss=loss).fit(t, Y)
    np.testing.assert_allclose(reg.g0_, expected["g0"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(reg.g1_, expected["g1"], rtol=0, atol=1e-12)
    assert reg.robust_["loss_scale"] == pytest.approx(expected["robust"]["loss_scale"], rel=1e-15)
    # The file's line i + 1 holds observation i.
    assert [i + 1 for i in reg.robust_["outliers"]] == expected["robust"]["outlier_lines"]
    assert 17 in reg.robust_["outliers"]
    assert reg.robust_["weights"][17] < 0.5
    # Its covariance uses the robust weights (bireg_fit's plug-in); the
    # trend test of a robust fit is refused rather than computed wrongly.
    assert reg.covariance("robust")["velocity"].shape == (6, 6)
    with pytest.raises(ValueError, match="robust fit"):
        reg.trend_test(permutations=9)


def test_robust_refusals():
    t = np.arange(4.0)
    Y = bireg.SE3.exp(0.1 * np.arange(24.0).reshape(4, 6))
    with pytest.raises(ValueError, match="unknown loss"):
        bireg.GeodesicRegression(loss="l1").fit(t, Y)
    with pytest.raises(ValueError, match="loss_scale"):
        bireg.GeodesicRegression(loss="huber", loss_scale=-1.0).fit(t, Y)
