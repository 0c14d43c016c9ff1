"""Trajectory files: matrix, TUM, EuRoC and KITTI (bireg/io/formats.hpp,
bireg/io/writers.hpp)."""

import os

from . import _arrays, _bireg
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


def write_trajectory(path, t, Y, group="SE3", format="tum", timestamps=None,
                     timestamps_format=None):
    """Writes Y (N, n, n) at t (N,) as a trajectory file in ``format``
    (matrix for any group; tum, euroc and kitti for SE3 and SO3), as
    ``bireg_fit`` and ``bireg_smooth`` write theirs: numbers as the shortest
    text that reads back to the same double, quaternions on one hemisphere
    from line to line.

    The times are t in seconds (EuRoC: converted exactly to nanoseconds),
    or, when ``timestamps`` is given, those texts (``read_trajectory``'s
    ``timestamps``, in ``timestamps_format``'s unit, by default
    ``format``'s), written exactly as read when the units agree and
    converted exactly otherwise. A pose that is not an element of the
    group, a time that is not finite or a text that is not a number raises
    ValueError naming its index.
    """
    g = _groups.get(group)
    t, Y = _arrays.trajectory(t, Y, g.matrix_size)
    if timestamps is not None:
        timestamps = list(timestamps)
        for i, text in enumerate(timestamps):
            if not isinstance(text, str):
                raise ValueError(f"timestamps[{i}] must be a str (the text of a timestamp), "
                                 f"got {type(text).__name__}")
    source = format if timestamps_format is None else timestamps_format
    text = _bireg.format_trajectory(g.name, t, Y, str(format), timestamps, str(source))
    with open(os.fspath(path), "w", encoding="ascii", newline="") as f:
        f.write(text)
