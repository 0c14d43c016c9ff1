"""Input conversion shared by the package's modules: one conversion to
C-contiguous float64 (none when the array already is), and shape checks
that name the expected shape. Content (finiteness, membership of the
group) is checked by the C++ library, which names the observation."""

import numpy as np


def covariates(t, name="t"):
    """(N,) float64, C-contiguous."""
    a = np.ascontiguousarray(t, dtype=np.float64)
    if a.ndim != 1:
        raise ValueError(f"{name} must have shape (N,), got {a.shape}")
    return a


def matrices(y, n, name="Y"):
    """(N, n, n) float64, C-contiguous."""
    a = np.ascontiguousarray(y, dtype=np.float64)
    if a.ndim != 3 or a.shape[1:] != (n, n):
        raise ValueError(f"{name} must have shape (N, {n}, {n}), got {a.shape}")
    return a


def weights(w, count):
    """(N,) float64, or an empty array for 'all 1'."""
    if w is None:
        return np.empty(0, dtype=np.float64)
    a = np.ascontiguousarray(w, dtype=np.float64)
    if a.shape != (count,):
        raise ValueError(f"sample_weight must have shape ({count},), got {a.shape}")
    return a


def positive_int(value, name):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    return int(value)


def seed(value):
    """A relabelling seed: an integer from 0 to 2^64 - 1."""
    value = positive_int(value, "seed")
    if value < 0:
        raise ValueError(f"seed must be a non-negative integer, got {value}")
    return value


def subject_pair(subject, index):
    """(t, Y) of subject `index`, or ValueError naming it."""
    try:
        t, Y = subject
    except (TypeError, ValueError):
        raise ValueError(f"subject {index} must be a pair (t, Y)") from None
    return t, Y


def trajectory(t, y, n):
    """t (N,) and Y (N, n, n) as covariates() and matrices() give them, of
    equal length."""
    t = covariates(t)
    y = matrices(y, n)
    if t.shape[0] != y.shape[0]:
        raise ValueError(f"t and Y differ in length ({t.shape[0]} vs {y.shape[0]})")
    return t, y
