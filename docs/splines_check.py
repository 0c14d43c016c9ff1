"""Numerical checks of the spline derivation in docs/splines.md, on SO(3).

Run:  python3 docs/splines_check.py      (numpy and scipy; about a second)

Each line prints a measured discrepancy next to what docs/splines.md claims
for it. Nothing here is library code: the curve, its derivatives and the
paper's geodesic are written out again with scipy's expm and logm, so that
the claims are checked independently of bireg.
"""
import numpy as np
from scipy.linalg import expm, logm


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def vee(m):
    return np.array([m[2, 1], m[0, 2], m[1, 0]])


def exp(w):
    return expm(hat(w))


def log(r):
    return vee(np.real(logm(r)))


def right_jacobian(w):
    """J_r(w) = (1 - e^{-ad_w}) / ad_w, summed as its series."""
    a = hat(w)  # ad_w on so(3)
    out, term = np.eye(3), np.eye(3)
    for m in range(1, 40):
        term = term @ (-a) / (m + 1)
        out = out + term
    return out


def chain(s, w):
    """s J_r(s w) J_r(w)^{-1}: how exp(s log(.)) moves with its argument."""
    return s * right_jacobian(s * w) @ np.linalg.inv(right_jacobian(w))


def psi(s, w):
    """DESIGN.md's psi_s(ad_w) = s J_r(w) J_r(s w)^{-1}."""
    return s * right_jacobian(w) @ np.linalg.inv(right_jacobian(s * w))


def cumulative_cubic(u):
    return np.array([(5 + 3 * u - 3 * u**2 + u**3) / 6, (1 + 3 * u + 3 * u**2 - 2 * u**3) / 6,
                     u**3 / 6])


def cumulative_cubic_d1(u):
    return np.array([(3 - 6 * u + 3 * u**2) / 6, (3 + 6 * u - 6 * u**2) / 6, u**2 / 2])


def cumulative_cubic_d2(u):
    return np.array([-1 + u, 1 - 2 * u, u])


def cubic_basis(u):
    return np.array([(1 - u)**3 / 6, (4 - 6 * u**2 + 3 * u**3) / 6,
                     (1 + 3 * u + 3 * u**2 - 3 * u**3) / 6, u**3 / 6])


def cumulative(u, degree):
    return cumulative_cubic(u) if degree == 3 else np.array([u])


def segment(control, u, degree):
    """T = P_0 prod_j exp(Bc_j(u) log(P_{j-1}^{-1} P_j)), control = P_0..P_k."""
    b = cumulative(u, degree)
    t = control[0].copy()
    for j in range(1, degree + 1):
        t = t @ exp(b[j - 1] * log(control[j - 1].T @ control[j]))
    return t


def derivative_by_control(control, u, c):
    """D_c = T^{-1} dT / d delta_c for P_c -> P_c exp(delta_c): docs/splines.md (4)."""
    k = 3
    b = cumulative_cubic(u)
    omega = [None] + [log(control[j - 1].T @ control[j]) for j in range(1, k + 1)]
    factors = [None] + [exp(b[j - 1] * omega[j]) for j in range(1, k + 1)]

    def suffix(j):
        s = np.eye(3)
        for m in range(j + 1, k + 1):
            s = s @ factors[m]
        return s

    d = np.zeros((3, 3))
    if c == 0:
        d += suffix(0).T  # Ad on SO(3) is the rotation itself
    if 1 <= c <= k:
        d += suffix(c).T @ chain(b[c - 1], omega[c])
    if c + 1 <= k:
        d -= suffix(c + 1).T @ chain(b[c], omega[c + 1]) @ exp(-omega[c + 1])
    return d


def velocity_and_acceleration(control, u, spacing):
    """Body velocity and its derivative: docs/splines.md (8) and (9)."""
    k = 3
    b, db, ddb = cumulative_cubic(u), cumulative_cubic_d1(u), cumulative_cubic_d2(u)
    omega = [None] + [log(control[j - 1].T @ control[j]) for j in range(1, k + 1)]
    velocity, acceleration, suffix = np.zeros(3), np.zeros(3), np.eye(3)
    for j in range(k, 0, -1):
        moved = vee(suffix.T @ hat(omega[j]) @ suffix)  # Ad_{S_j^{-1}} Omega_j
        acceleration += ddb[j - 1] * moved - db[j - 1] * np.cross(velocity, moved)
        velocity = velocity + db[j - 1] * moved
        suffix = exp(b[j - 1] * omega[j]) @ suffix
    return velocity / spacing, acceleration / spacing**2


def main():
    rng = np.random.default_rng(1)
    u, h, step = 0.37, 0.5, 1e-6
    directions = [rng.normal(size=3) for _ in range(4)]
    g = exp(rng.normal(size=3))
    for spread in (0.6, 0.06):  # the same control points, 10 times closer
        control = [exp(d * spread) for d in directions]
        print(f"control points spread {spread} rad")
        for degree in (1, 3):
            t = segment(control, u, degree)
            left = np.abs(segment([g @ p for p in control], u, degree) - g @ t).max()
            right = np.abs(segment([p @ g for p in control], u, degree) - t @ g).max()
            inverse = np.abs(segment([p.T for p in control], u, degree) - t.T).max()
            print(f"  degree {degree}: left {left:.1e}, right {right:.1e} (claim: rounding); "
                  f"inversion {inverse:.1e} (claim: rounding for degree 1, "
                  f"O(spread^2) for degree 3)")
        t = segment(control, u, 3)
        basis = cubic_basis(u)
        for c in range(4):
            finite = np.zeros((3, 3))
            for a in range(3):
                e = np.zeros(3)
                e[a] = step
                plus = [p @ exp(e) if m == c else p for m, p in enumerate(control)]
                minus = [p @ exp(-e) if m == c else p for m, p in enumerate(control)]
                finite[:, a] = (log(t.T @ segment(plus, u, 3)) -
                                log(t.T @ segment(minus, u, 3))) / (2 * step)
            d = derivative_by_control(control, u, c)
            print(f"  D_{c}: against central differences {np.abs(d - finite).max():.1e} "
                  f"(claim: ~1e-10, the differences' own error); "
                  f"|D_c / B_c - I| = {np.abs(d / basis[c] - np.eye(3)).max():.3f} "
                  f"(claim: O(spread))")
        velocity, acceleration = velocity_and_acceleration(control, u, h)
        e = 1e-5
        finite_velocity = (log(t.T @ segment(control, u + e, 3)) -
                           log(t.T @ segment(control, u - e, 3))) / (2 * e * h)
        plus, _ = velocity_and_acceleration(control, u + e, h)
        minus, _ = velocity_and_acceleration(control, u - e, h)
        print(f"  velocity against differences {np.abs(velocity - finite_velocity).max():.1e}, "
              f"acceleration {np.abs(acceleration - (plus - minus) / (2 * e * h)).max():.1e} "
              f"(claim: ~1e-10)")
        # Degree 1, two control points on [0, 1]: the paper's geodesic.
        x = log(control[0].T @ control[1])
        d0 = exp(u * x).T - chain(u, x) @ exp(-x)
        d1 = chain(u, x)
        print(f"  degree 1: (1-t)^2 D_0^-1 - psi_(1-t)(-ad X) "
              f"{np.abs((1 - u)**2 * np.linalg.inv(d0) - psi(1 - u, -x)).max():.1e}, "
              f"t^2 D_1^-1 - psi_t(ad X) {np.abs(u**2 * np.linalg.inv(d1) - psi(u, x)).max():.1e} "
              f"(claim: rounding)")


if __name__ == "__main__":
    main()
