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
