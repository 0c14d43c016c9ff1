"""Trajectory files: matrix, TUM, EuRoC and KITTI (bireg/io/formats.hpp)."""

import os

from . import _bireg
from . import groups as _groups


def read_trajectory(path, group="SE3", format=None, project=False):
    """Reads a trajectory: a dict with ``t`` (seconds after the earliest
    timestamp, ``origin``), ``Y`` (N, n, n), ``timestamps`` (each exactly as
    written, for nanosecond-exact times), ``lines`` and ``format``.

    ``format`` None detects it from the content. A file the reader refuses
    raises ValueError naming path:line.
    """
    g = _groups.get(group)
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(path)
    return _bireg.read_trajectory(path, g.name, "" if format is None else str(format),
                                  bool(project))
