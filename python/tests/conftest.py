"""Shared fixtures: seeded data on each group, and the path of the C++ tool
bireg_fit that the equivalence tests compare against."""

import os
import pathlib

import numpy as np
import pytest

import bireg

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "examples" / "data"

# The groups of the package, with a tangent scale that keeps the data
# inside the log's domain.
GROUP_NAMES = ["SO2", "SO3", "SE2", "SE3", "Sim3", "SL3", "GLp3"]


def geodesic_data(group, n, rng, speed=0.8, noise=0.05):
    """n observations about a geodesic on the unit interval: t (n,), Y (n, m, m)."""
    g = bireg.groups.get(group)
    t = np.sort(rng.uniform(0.0, 1.0, n))
    start = g.exp(0.3 * rng.standard_normal(g.dim))
    velocity = speed * rng.standard_normal(g.dim) / np.sqrt(g.dim)
    path = g.compose(start, g.exp(t[:, None] * velocity))
    Y = g.compose(path, g.exp(noise * rng.standard_normal((n, g.dim))))
    return t, Y


@pytest.fixture
def rng():
    return np.random.default_rng(20261125)


def bireg_fit_path():
    """The bireg_fit binary: $BIREG_FIT, else build/tools/bireg_fit."""
    path = pathlib.Path(os.environ.get("BIREG_FIT", ROOT / "build" / "tools" / "bireg_fit"))
    return path if path.exists() else None
