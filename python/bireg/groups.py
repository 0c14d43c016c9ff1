"""The matrix Lie groups, with vectorised exp, log, compose, inverse, Ad,
right Jacobian and membership test over any leading batch shape
(broadcasting as numpy does). Each loop runs in C++ with the GIL released.

Tangent coordinates are the C++ library's: SE3 is (v, w), translation part
first; SE2 is (v, w); Sim3 is (v, w, s); SL3 and GLp3 are coefficients in
the basis of bireg/groups/matrix_group.hpp (GLp3: the entries, row-major).
"""

import numpy as np

from . import _bireg


class Group:
    """One of the library's groups, by name (``bireg.SE3`` etc.)."""

    def __init__(self, name):
        self.name = name
        self.dim, self.matrix_size = _bireg.group_info(name)

    def __repr__(self):
        return f"bireg.{self.name}"

    # -- shapes ------------------------------------------------------------
    def _tangents(self, x):
        a = np.asarray(x, dtype=np.float64)
        if a.ndim < 1 or a.shape[-1] != self.dim:
            raise ValueError(f"{self.name}: expected tangent vectors of shape (..., {self.dim}), "
                             f"got {a.shape}")
        return np.ascontiguousarray(a.reshape(-1, self.dim)), a.shape[:-1]

    def _elements(self, g):
        n = self.matrix_size
        a = np.asarray(g, dtype=np.float64)
        if a.ndim < 2 or a.shape[-2:] != (n, n):
            raise ValueError(f"{self.name}: expected matrices of shape (..., {n}, {n}), "
                             f"got {a.shape}")
        return np.ascontiguousarray(a.reshape(-1, n, n)), a.shape[:-2]

    @staticmethod
    def _out(out, shape, source, what):
        """The caller's `out` once checked (numpy's convention: C-contiguous
        float64 of exactly that shape, not overlapping the input), or None:
        then the C++ allocates the result (in huge pages when large)."""
        if out is None:
            return None
        if not isinstance(out, np.ndarray) or out.dtype != np.float64 or \
                not out.flags.c_contiguous or not out.flags.writeable:
            raise ValueError(f"{what}: out must be a writeable C-contiguous float64 ndarray")
        if out.shape != shape:
            raise ValueError(f"{what}: out must have shape {shape}, got {out.shape}")
        if np.may_share_memory(out, source):
            raise ValueError(f"{what}: out must not overlap the input")
        return out

    # -- operations ----------------------------------------------------------
    def exp(self, x, out=None):
        """(..., d) -> (..., n, n). ``out``: an array of that shape to write
        the result to (and return), as numpy's functions take it."""
        flat, batch = self._tangents(x)
        shape = batch + (self.matrix_size,) * 2
        out = self._out(out, shape, flat, "exp")
        if out is None:
            return _bireg.group_exp(self.name, flat, None).reshape(shape)
        _bireg.group_exp(self.name, flat, out.reshape(-1, *shape[-2:]))
        return out

    def log(self, g, out=None):
        """(..., n, n) -> (..., d); ValueError where there is no principal
        log. ``out`` as for exp."""
        flat, batch = self._elements(g)
        shape = batch + (self.dim,)
        out = self._out(out, shape, flat, "log")
        if out is None:
            return _bireg.group_log(self.name, flat, None).reshape(shape)
        _bireg.group_log(self.name, flat, out.reshape(-1, self.dim))
        return out

    def compose(self, a, b):
        """a b, broadcasting the batch shapes."""
        n = self.matrix_size
        a = np.asarray(a, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64)
        if a.ndim < 2 or b.ndim < 2:
            raise ValueError(f"{self.name}: compose needs matrices of shape (..., {n}, {n})")
        a, b = np.broadcast_arrays(a, b)
        fa, batch = self._elements(a)
        fb, _ = self._elements(b)
        return _bireg.group_compose(self.name, fa, fb).reshape(batch + (n, n))

    def inverse(self, g):
        flat, batch = self._elements(g)
        return _bireg.group_inverse(self.name, flat).reshape(batch + (self.matrix_size,) * 2)

    def Ad(self, g):
        """(..., n, n) -> (..., d, d): the adjoint matrix."""
        flat, batch = self._elements(g)
        return _bireg.group_Ad(self.name, flat).reshape(batch + (self.dim, self.dim))

    def right_jacobian(self, x):
        """(..., d) -> (..., d, d): J_r(x) = (1 - exp(-ad_x)) / ad_x."""
        flat, batch = self._tangents(x)
        return _bireg.group_right_jacobian(self.name, flat).reshape(batch + (self.dim, self.dim))

    def is_element(self, g, tol=1e-6):
        """(..., n, n) -> (...) bool."""
        flat, batch = self._elements(g)
        return _bireg.group_is_element(self.name, flat, float(tol)).reshape(batch)


SO2 = Group("SO2")
SO3 = Group("SO3")
SE2 = Group("SE2")
SE3 = Group("SE3")
Sim3 = Group("Sim3")
SL3 = Group("SL3")
GLp3 = Group("GLp3")

GROUPS = {g.name: g for g in (SO2, SO3, SE2, SE3, Sim3, SL3, GLp3)}


def get(group):
    """A Group from a Group or its name; ValueError for an unknown name."""
    if isinstance(group, Group):
        return group
    if group not in GROUPS:
        raise ValueError(f"unknown group {group!r}: expected one of {', '.join(GROUPS)}")
    return GROUPS[group]
