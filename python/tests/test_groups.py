"""The batched group functions: against a per-element loop, against
scipy's rotations, the group laws at rounding, broadcasting, and their
refusals."""

import numpy as np
import pytest

import bireg
from conftest import GROUP_NAMES


@pytest.mark.parametrize("name", GROUP_NAMES)
def test_batch_equals_loop_and_laws_hold(name, rng):
    g = bireg.groups.get(name)
    x = 0.5 * rng.standard_normal((4, 5, g.dim))
    e = g.exp(x)
    assert e.shape == (4, 5, g.matrix_size, g.matrix_size)
    for i in range(4):
        for j in range(5):
            np.testing.assert_array_equal(e[i, j], g.exp(x[i, j]))
    # log(exp(x)) = x inside the domain; exp(x) exp(-x) = 1; Ad(exp x) x = x.
    np.testing.assert_allclose(g.log(e), x, atol=1e-12)
    eye = np.broadcast_to(np.eye(g.matrix_size), e.shape)
    np.testing.assert_allclose(g.compose(e, g.exp(-x)), eye, atol=1e-12)
    np.testing.assert_allclose(g.compose(e, g.inverse(e)), eye, atol=1e-12)
    ad = g.Ad(e)
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", ad, x), x, atol=1e-12)
    assert g.is_element(e).all()
    # J_r(x) at x = 0 is the identity; d/ds exp(x + s v) at 0 is exp(x) J_r(x) v.
    np.testing.assert_allclose(g.right_jacobian(np.zeros(g.dim)), np.eye(g.dim), atol=1e-15)


@pytest.mark.parametrize("name", GROUP_NAMES)
def test_compose_broadcasts(name, rng):
    g = bireg.groups.get(name)
    a = g.exp(0.4 * rng.standard_normal((3, 1, g.dim)))
    b = g.exp(0.4 * rng.standard_normal((1, 6, g.dim)))
    c = g.compose(a, b)
    assert c.shape == (3, 6, g.matrix_size, g.matrix_size)
    np.testing.assert_allclose(c[2, 4], a[2, 0] @ b[0, 4], rtol=0, atol=1e-14)


def test_so3_agrees_with_scipy(rng):
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    x = rng.uniform(-1.0, 1.0, (1000, 3)) * 1.7
    np.testing.assert_allclose(bireg.SO3.exp(x), Rotation.from_rotvec(x).as_matrix(), atol=1e-12)
    r = Rotation.from_rotvec(x).as_matrix()
    np.testing.assert_allclose(bireg.SO3.log(r), Rotation.from_matrix(r).as_rotvec(), atol=1e-12)


def test_float32_and_non_contiguous_inputs_are_converted(rng):
    x = 0.3 * rng.standard_normal((10, 6))
    expected = bireg.SE3.exp(x)
    np.testing.assert_allclose(bireg.SE3.exp(x.astype(np.float32)), expected, atol=1e-6)
    strided = np.asfortranarray(expected)
    np.testing.assert_array_equal(bireg.SE3.log(strided), bireg.SE3.log(expected))


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: bireg.SE3.exp(np.zeros(5)), r"shape \(\.\.\., 6\)"),
        (lambda: bireg.SE3.log(np.eye(3)), r"shape \(\.\.\., 4, 4\)"),
        (lambda: bireg.SO3.exp(np.array([[0.0, np.nan, 0.0]])), "not finite at index 0"),
        (lambda: bireg.SO3.log(np.stack([np.eye(3), np.zeros((3, 3))])),
         "no principal logarithm.*index 1"),
        (lambda: bireg.GLp3.inverse(np.stack([np.eye(3), -np.eye(3)])), "not an element.*index 1"),
        (lambda: bireg.SE3.is_element(np.eye(4), tol=-1), "tol"),
        (lambda: bireg.groups.get("SO4"), "unknown group 'SO4'"),
    ],
)
def test_refusals_are_value_errors(call, message):
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize("name", GROUP_NAMES)
def test_exp_and_log_write_to_out(name, rng):
    g = bireg.groups.get(name)
    x = 0.5 * rng.standard_normal((2, 3, g.dim))
    e = np.full((2, 3, g.matrix_size, g.matrix_size), np.nan)
    assert g.exp(x, out=e) is e
    np.testing.assert_array_equal(e, g.exp(x))
    v = np.full((2, 3, g.dim), np.nan)
    assert g.log(e, out=v) is v
    np.testing.assert_array_equal(v, g.log(e))
    # One element: the batch shape is ().
    single = np.empty(g.dim)
    assert g.log(e[1, 2], out=single) is single
    np.testing.assert_array_equal(single, v[1, 2])


def test_out_is_checked_and_refusals_still_name_the_index(rng):
    x = rng.standard_normal((5, 6))
    n = 4
    for bad, message in [(np.empty((5, n, n), dtype=np.float32), "float64"),
                         (np.empty((5, n, 2 * n))[:, :, ::2], "C-contiguous"),
                         (np.empty((4, n, n)), "shape"),
                         ([[0.0]], "ndarray")]:
        with pytest.raises(ValueError, match=message):
            bireg.SE3.exp(x, out=bad)
    read_only = np.empty((5, n, n))
    read_only.flags.writeable = False
    with pytest.raises(ValueError, match="writeable"):
        bireg.SE3.exp(x, out=read_only)
    buffer = np.zeros(5 * 16 + 5 * 6)
    e = buffer[:80].reshape(5, n, n)
    bireg.SE3.exp(x, out=e)
    with pytest.raises(ValueError, match="overlap"):
        bireg.SE3.log(e, out=buffer[10:40].reshape(5, 6))
    bad = x.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="index 3"):
        bireg.SE3.exp(bad, out=np.empty((5, n, n)))
    e[2, 0, 1] += 0.1
    with pytest.raises(ValueError, match="index 2"):
        bireg.SE3.log(e, out=np.empty((5, 6)))


@pytest.mark.parametrize("group", ["SO3", "SE3"])
def test_log_names_the_first_non_element_at_and_across_block_edges(group, rng):
    # SO3's and SE3's membership is checked 256 matrices at a time, by code
    # compiled for the CPU's vector width (groups/element_check.hpp): every
    # defect is found wherever it lies, and the first of two is named.
    g = bireg.groups.get(group)
    good = g.exp(rng.uniform(-1.5, 1.5, (1000, g.dim)))
    assert np.isfinite(g.log(good)).all()
    defects = [(0, 1, 1e-3), (2, 2, np.nan), (1, 0, np.inf)]
    if group == "SE3":
        defects += [(3, 1, 1e-3), (3, 3, 1.001), (0, 3, np.nan)]
    for index in (0, 255, 256, 257, 999):
        for r, c, value in defects:
            bad = good.copy()
            bad[index, r, c] = bad[index, r, c] + value if value == 1e-3 else value
            with pytest.raises(ValueError, match=f"at index {index}$"):
                g.log(bad)
            if index < 999:
                bad[999, 0, 0] = np.nan
                with pytest.raises(ValueError, match=f"at index {index}$"):
                    g.log(bad, out=np.empty((1000, g.dim)))


def test_the_first_failure_is_named_and_the_module_refuses_an_out_it_would_copy(rng):
    # diag(-1, -1, 1) is in GL+(3) but has no principal log; the NaN matrix
    # after it is not an element. The first of the two is named.
    batch = np.stack([np.eye(3), np.diag([-1.0, -1.0, 1.0]), np.full((3, 3), np.nan)])
    with pytest.raises(ValueError, match="index 1"):
        bireg.GLp3.log(batch)
    with pytest.raises(ValueError, match="index 1"):
        bireg.GLp3.log(batch, out=np.empty((3, 9)))
    # A strided out would be copied by the binding and the result lost:
    # nanobind is told not to convert it.
    x = rng.standard_normal((2, 6))
    with pytest.raises(TypeError):
        bireg._bireg.group_exp("SE3", x, np.zeros((2, 4, 8))[:, :, ::2])
    with pytest.raises(TypeError):
        bireg._bireg.group_log("SE3", bireg.SE3.exp(x), np.zeros((2, 6), dtype=np.float32))
