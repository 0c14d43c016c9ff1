"""Model selection through Python: select_motion_model gives bireg_fit
--group auto's table on the shipped poses, the criteria of
select_static_or_geodesic and select_curve are the formula
N/2 log det S + k/2 log N recomputed here from the fits they return, the
verdicts follow the data's motion, the tables are invariant under left
translation, and every refusal is a ValueError."""

import json
import subprocess
import warnings

import numpy as np
import pytest

import bireg
from conftest import DATA, GROUP_NAMES, bireg_fit_path, geodesic_data


def criterion(g, t, Y, predict, parameters):
    """N/2 log det S + k/2 log N of the residuals log(P(t_i)^-1 Y_i)."""
    r = g.log(g.compose(g.inverse(predict(t)), Y))
    s = r.T @ r / len(t)
    return len(t) / 2 * np.linalg.slogdet(s)[1] + parameters / 2 * np.log(len(t))


def geodesic_at(g, g0, g1, interval):
    a, b = interval
    velocity = g.log(g.compose(g.inverse(g0), g1))
    return lambda t: g.compose(g0, g.exp(((np.asarray(t) - a) / (b - a))[:, None] * velocity))


def moving_data(group, n, rng, speed=1.5, noise=0.05):
    """n observations about a geodesic whose velocity has norm `speed`
    (geodesic_data draws its norm, which may be small)."""
    g = bireg.groups.get(group)
    t = np.sort(rng.uniform(0.0, 1.0, n))
    direction = rng.standard_normal(g.dim)
    velocity = speed * direction / np.linalg.norm(direction)
    path = g.compose(g.exp(0.3 * rng.standard_normal(g.dim)), g.exp(t[:, None] * velocity))
    return t, g.compose(path, g.exp(noise * rng.standard_normal((n, g.dim))))


def static_data(group, n, rng, noise=0.05):
    g = bireg.groups.get(group)
    t = np.sort(rng.uniform(0.0, 1.0, n))
    centre = g.exp(0.3 * rng.standard_normal(g.dim))
    return t, g.compose(centre, g.exp(noise * rng.standard_normal((n, g.dim))))


def test_motion_model_table_equals_bireg_fit_auto():
    tool = bireg_fit_path()
    if tool is None:
        pytest.skip("bireg_fit is not built (set BIREG_FIT or build build/tools)")
    path = DATA / "se3_deepmimic_walk.tum"
    out = subprocess.run([str(tool), "--group", "auto", "--threads", "1", str(path)],
                         capture_output=True, text=True, check=True)
    expected = json.loads(out.stdout)
    assert expected["pose_group"] == "SE3"
    data = bireg.read_trajectory(path, group="SE3")
    result = bireg.select_motion_model(data["t"], data["Y"], group="SE3")
    assert result.status == "selected"
    assert result.recommended == expected["recommended"]
    assert len(result.candidates) == len(expected["model_selection"])
    for ours, theirs in zip(result.candidates, expected["model_selection"]):
        assert ours.model == theirs["model"]
        assert ours.parameters == theirs["parameters"]
        assert ours.recommended == (theirs["verdict"] == "recommended")
        # The same code on the same covariates (seconds after the first
        # timestamp in both): equal up to the last bits of the sums.
        assert ours.criterion == pytest.approx(theirs["criterion"], rel=1e-12)
        assert ours.cv_error == pytest.approx(theirs["cv_error"], rel=1e-12)
        assert ours.rotation_rms_degrees == pytest.approx(theirs["rotation_rms_deg"], rel=1e-12)
        assert ours.translation_rms == pytest.approx(theirs["translation_rms"], rel=1e-12)
        assert ours.log_scale_rms is None


def test_static_poses_recommend_static_and_fit_the_mean(rng):
    t, Y = static_data("SE3", 80, rng)
    result = bireg.select_motion_model(t, Y, group=bireg.SE3, threads=2)
    assert result.recommended == "static"
    assert result.fitted.shape == (80, 4, 4)
    np.testing.assert_allclose(result.fitted, np.broadcast_to(bireg.mean(Y, group="SE3"),
                                                              Y.shape), atol=1e-12)
    single = bireg.select_motion_model(t, Y, threads=1)
    assert [c.criterion for c in single.candidates] == [c.criterion for c in result.candidates]
    assert [c.cv_error for c in single.candidates] == [c.cv_error for c in result.candidates]


def test_similarities_add_the_similarity_candidate(rng):
    t, Y = geodesic_data("Sim3", 60, rng)
    result = bireg.select_motion_model(t, Y, group="Sim3", folds=0)
    assert [c.model for c in result.candidates] == [
        "static", "rotation_only", "translation_only", "rotation_and_line", "screw", "similarity"]
    assert all(c.cv_error is None for c in result.candidates)  # no cross-validation
    assert all(c.log_scale_rms is not None for c in result.candidates)
    assert result.recommended == "similarity"


@pytest.mark.parametrize("group", GROUP_NAMES)
def test_static_or_geodesic_criteria_are_the_formula(group, rng):
    g = bireg.groups.get(group)
    t, Y = moving_data(group, 60, rng)
    moving = bireg.select_static_or_geodesic(t, Y, group=group)
    assert moving.recommended == "geodesic"
    static, geodesic = moving.candidates
    assert (static.model, static.parameters) == ("static", g.dim)
    assert (geodesic.model, geodesic.parameters) == ("geodesic", 2 * g.dim)
    np.testing.assert_allclose(moving.static_element, bireg.mean(Y, group=group), atol=1e-12)
    assert static.criterion == pytest.approx(
        criterion(g, t, Y, lambda s: np.broadcast_to(moving.static_element, (len(s),) + Y.shape[1:]),
                  g.dim), rel=1e-9)
    along = geodesic_at(g, moving.g0, moving.g1, moving.interval)
    assert geodesic.criterion == pytest.approx(criterion(g, t, Y, along, 2 * g.dim), rel=1e-9)
    t, Y = static_data(group, 60, rng)
    assert bireg.select_static_or_geodesic(t, Y, group=group).recommended == "static"


@pytest.mark.parametrize("group", ["SO3", "SE3"])
def test_tables_are_left_and_right_invariant(group, rng):
    g = bireg.groups.get(group)
    t, Y = geodesic_data(group, 50, rng, speed=1.0)
    a = g.exp(0.8 * rng.standard_normal(g.dim))
    b = g.exp(0.8 * rng.standard_normal(g.dim))
    moved = g.compose(g.compose(a, Y), b)
    for select in (lambda Z: bireg.select_static_or_geodesic(t, Z, group=group),
                   lambda Z: bireg.select_curve(t, Z, group=group, knot_spacings=[0.5, 0.25])):
        base, other = select(Y), select(moved)
        assert base.recommended == other.recommended
        # det Ad = 1 in SO(3) and SE(3): each criterion is unchanged, up to
        # the fits' tolerance (1e-10) carried through log det.
        np.testing.assert_allclose([c.criterion for c in other.candidates],
                                   [c.criterion for c in base.candidates], rtol=0, atol=1e-6)


def test_curve_selection_finds_the_curve(rng):
    g = bireg.SO3
    t = np.linspace(0.0, 4.0, 200)
    # The axis turns with t: no single geodesic follows it.
    curve = g.exp(np.stack([np.sin(2 * t), np.cos(1.5 * t), 0.5 * t], axis=1))
    Y = g.compose(curve, g.exp(0.02 * rng.standard_normal((200, 3))))
    result = bireg.select_curve(t, Y, group="SO3", knot_spacings=[4.0, 1.0, 0.5, 0.25])
    assert result.status == "selected"
    assert [(c.degree, c.segments) for c in result.candidates] == [
        (0, 1), (3, 1), (1, 4), (3, 4), (1, 8), (3, 8), (1, 16), (3, 16)]
    chosen = result.candidates[result.recommended_index]
    assert chosen.recommended and chosen.model == result.recommended
    assert chosen.degree in (1, 3)
    # Its residuals are near the noise: 0.02 rad per axis.
    assert chosen.residual_rms < 2 * 0.02 * np.sqrt(3)
    geodesic = result.candidates[0]
    assert geodesic.model == "geodesic" and geodesic.residual_rms > 5 * chosen.residual_rms
    # The geodesic row is select_static_or_geodesic's geodesic.
    trend = bireg.select_static_or_geodesic(t, Y, group="SO3")
    assert geodesic.criterion == pytest.approx(trend.candidates[1].criterion, rel=1e-9)


def test_curve_selection_keeps_the_geodesic_for_geodesic_data(rng):
    t, Y = geodesic_data("SE3", 120, rng, speed=1.0, noise=0.03)
    result = bireg.select_curve(t, Y, group="SE3")
    assert result.recommended == "geodesic" and result.recommended_index == 0


def test_unfitted_candidates_have_no_numbers(rng):
    t, Y = geodesic_data("SO3", 12, rng)
    # 12 segments of a cubic need 15 control points for 12 observations.
    result = bireg.select_curve(t, Y, group="SO3", knot_spacings=[np.ptp(t) / 12])
    excluded = [c for c in result.candidates if not c.fitted]
    assert excluded and all(c.note.startswith("excluded") for c in excluded)
    assert all(c.criterion is None and c.log_det is None and c.residual_rms is None
               for c in excluded)


def test_selection_refusals_are_value_errors(rng):
    t, Y = geodesic_data("SE3", 30, rng)
    bad = Y.copy()
    bad[7, 0, 0] = np.nan
    for select in (lambda Z: bireg.select_motion_model(t, Z),
                   lambda Z: bireg.select_static_or_geodesic(t, Z, group="SE3"),
                   lambda Z: bireg.select_curve(t, Z, group="SE3")):
        with pytest.raises(ValueError, match="observation 7"):
            select(bad)
    with pytest.raises(ValueError, match="expected SE3"):
        bireg.select_motion_model(t, Y, group="SO3")
    with pytest.raises(ValueError, match="unknown group"):
        bireg.select_static_or_geodesic(t, Y, group="SE4")
    with pytest.raises(ValueError, match="threads"):
        bireg.select_curve(t, Y, group="SE3", threads=0)
    with pytest.raises(ValueError, match="knot spacing 1"):
        bireg.select_curve(t, Y, group="SE3", knot_spacings=[0.5, -1.0])
    with pytest.raises(ValueError, match="empty"):
        bireg.select_curve(t, Y, group="SE3", knot_spacings=[])
    with pytest.raises(ValueError, match="differ in length"):
        bireg.select_static_or_geodesic(t[:-1], Y, group="SE3")
    with pytest.raises(ValueError, match="shape"):
        bireg.select_motion_model(t, Y[:, :3, :3])


def test_no_candidate_warns_and_recommends_nothing(rng):
    # Two observations: fewer than the static model's 3 parameters and the
    # geodesic's 6, so both are excluded.
    t, Y = geodesic_data("SO3", 2, rng)
    with pytest.warns(bireg.SelectionWarning, match="neither model"):
        result = bireg.select_static_or_geodesic(t, Y, group="SO3", folds=0)
    assert result.status == "no_candidate" and result.recommended is None
    assert [c.note for c in result.candidates] == [
        "excluded: 2 observations, fewer than its 3 parameters",
        "excluded: 2 observations, fewer than its 6 parameters"]
    assert result.static_element is None and result.g0 is None
    # Three: the static model alone is scored, and recommended.
    t, Y = geodesic_data("SO3", 3, rng)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = bireg.select_static_or_geodesic(t, Y, group="SO3", folds=0)
    assert result.recommended == "static" and result.g0 is None
