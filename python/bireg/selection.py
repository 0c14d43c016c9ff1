"""Model selection (bireg/statistics/selection/, docs/model_selection.md):
which model do the data need, by the invariant criterion

    C = N/2 log det S_r + k/2 log N,    S_r = (1/N) sum r_i r_i^T,

with r_i = log(P(t_i)^{-1} f_i) the residual of candidate P in the group
and k its parameter count; among the candidates within the margin of the
best C the one with the fewest parameters is recommended.

``select_motion_model(t, Y)`` compares the motion models of SE(3) poses
(static, rotation only, translation only, rotation and line, screw) or of
Sim(3) similarities (and the similarity geodesic);
``select_static_or_geodesic(t, Y, group)`` asks whether an element of any
group moves along its covariate at all; ``select_curve(t, Y, group)``
compares the geodesic with piecewise geodesics and cubic splines.

A candidate that could not be fitted or scored has ``fitted`` False, a
``note`` saying why and None for its numbers. Invalid input raises
ValueError naming the observation; when no candidate is left the result's
``status`` is "no_candidate" and a ``SelectionWarning`` says so.
"""

import warnings
from dataclasses import dataclass
from typing import Optional

import numpy as np

from . import _arrays, _bireg
from . import groups as _groups


class SelectionWarning(UserWarning):
    """No candidate could be fitted and scored: nothing is recommended."""


@dataclass(frozen=True)
class Candidate:
    """What every row of a selection's table has: the model, its parameter
    count k, whether it was scored (``note`` says why not), log det S_r with
    the eigenvalue floor, the criterion, whether it is within the margin of
    the best, and whether it is the recommendation."""

    model: str
    parameters: int
    fitted: bool
    note: str
    log_det: Optional[float]
    criterion: Optional[float]
    within_margin: bool
    recommended: bool


@dataclass(frozen=True)
class MotionCandidate(Candidate):
    """One motion model of ``select_motion_model`` (``bireg::CandidateReport``)."""

    rotation_rms_degrees: Optional[float]
    translation_rms: Optional[float]
    log_scale_rms: Optional[float]  # Sim3 data only
    cv_error: Optional[float]       # mean held-out |r|^2; None without cross-validation


@dataclass(frozen=True)
class MotionModelSelection:
    """``select_motion_model``'s table. ``fitted`` is the recommended
    model's pose at each covariate of the data, (N, 4, 4)."""

    status: str
    message: str
    candidates: tuple
    recommended: Optional[str]
    ambiguous: bool
    fitted: Optional[np.ndarray]


@dataclass(frozen=True)
class TrendCandidate(Candidate):
    """The static or the geodesic candidate (``bireg::TrendCandidate``)."""

    residual_rms: Optional[float]
    cv_error: Optional[float]


@dataclass(frozen=True)
class TrendSelection:
    """``select_static_or_geodesic``'s table, with the two fits: the
    bi-invariant mean ``static_element`` and the geodesic from ``g0`` to
    ``g1`` over ``interval`` (in the data's covariates)."""

    status: str
    message: str
    candidates: tuple
    recommended: Optional[str]
    static_element: Optional[np.ndarray]
    g0: Optional[np.ndarray]
    g1: Optional[np.ndarray]
    interval: Optional[tuple]


@dataclass(frozen=True)
class CurveCandidate(Candidate):
    """One curve of ``select_curve`` (``bireg::CurveCandidate``): degree 0
    is the geodesic, 1 a piecewise geodesic, 3 a cubic spline, on
    ``segments`` equal knot spans of ``knot_spacing``."""

    degree: int
    segments: int
    knot_spacing: float
    residual_rms: Optional[float]


@dataclass(frozen=True)
class CurveSelection:
    """``select_curve``'s table; ``recommended`` describes the recommended
    candidate, ``candidates[recommended_index]``."""

    status: str
    message: str
    candidates: tuple
    recommended: Optional[str]
    recommended_index: Optional[int]


def _warn_if_nothing(raw):
    if raw["status"] != "selected":
        warnings.warn(f"model selection: {raw['message']}", SelectionWarning, stacklevel=3)


def _folds(folds):
    return _arrays.positive_int(folds, "folds")


def select_motion_model(t, Y, group="SE3", folds=5, threads=1):
    """Which motion model the poses Y (N, 4, 4) at t (N,) require.

    ``group`` is "SE3" for rigid poses or "Sim3" for similarities (a
    monocular reconstruction whose scale may drift; a sixth candidate,
    "similarity"). ``folds`` below 2: no cross-validation. The result does
    not depend on ``threads``.
    """
    t, Y = _arrays.trajectory(t, Y, 4)
    raw = _bireg.select_motion_model(_groups.get(group).name, t, Y, _folds(folds),
                                     _arrays.positive_int(threads, "threads"))
    _warn_if_nothing(raw)
    return MotionModelSelection(
        status=raw["status"], message=raw["message"],
        candidates=tuple(MotionCandidate(**row) for row in raw["candidates"]),
        recommended=raw["recommended"], ambiguous=raw["ambiguous"], fitted=raw["fitted"])


def select_static_or_geodesic(t, Y, group="SE3", folds=5, threads=1):
    """Static against geodesic for Y (N, n, n) of ``group`` at t (N,): does
    the element move along the covariate at all?"""
    g = _groups.get(group)
    t, Y = _arrays.trajectory(t, Y, g.matrix_size)
    raw = _bireg.select_static_or_geodesic(g.name, t, Y, _folds(folds),
                                           _arrays.positive_int(threads, "threads"))
    _warn_if_nothing(raw)
    return TrendSelection(
        status=raw["status"], message=raw["message"],
        candidates=tuple(TrendCandidate(**row) for row in raw["candidates"]),
        recommended=raw["recommended"], static_element=raw["static_element"], g0=raw["g0"],
        g1=raw["g1"], interval=raw["interval"])


def select_curve(t, Y, group="SE3", knot_spacings=None, threads=1):
    """The geodesic against piecewise geodesics and cubic splines for Y
    (N, n, n) of ``group`` at t (N,). ``knot_spacings`` (in t's units)
    gives the segment counts to try; None: 24 spacings from 1.25 median
    sample spacings to the covariates' range."""
    g = _groups.get(group)
    t, Y = _arrays.trajectory(t, Y, g.matrix_size)
    spacings = np.empty(0) if knot_spacings is None else np.atleast_1d(
        np.ascontiguousarray(knot_spacings, dtype=np.float64))
    if spacings.ndim != 1:
        raise ValueError(f"knot_spacings must be a 1-D sequence, got shape {spacings.shape}")
    if knot_spacings is not None and spacings.size == 0:
        raise ValueError("knot_spacings is empty: give at least one spacing, or None")
    raw = _bireg.select_curve(g.name, t, Y, spacings, _arrays.positive_int(threads, "threads"))
    _warn_if_nothing(raw)
    return CurveSelection(
        status=raw["status"], message=raw["message"],
        candidates=tuple(CurveCandidate(**row) for row in raw["candidates"]),
        recommended=raw["recommended"], recommended_index=raw["recommended_index"])
