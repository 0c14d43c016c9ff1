#!/usr/bin/env python3
"""Writes sim3_psi_reference.txt: psi_s(ad_X) r on Sim(3) in 40-digit
arithmetic, the reference of Sim3::ClosedFormPsi in
tests/test_exact_inverse_differential.cpp.

psi_s(A) = s J_r(X) J_r(sX)^{-1} (docs/DESIGN.md, "Exact form"), with
J_r(X) = int_0^1 e^{-u A} du read off the matrix exponential of the
augmented matrix [-A I; 0 0], so the reference shares nothing with the
closed form (no divided differences, no frame) and needs no series that
stops converging at spectral radius 2 pi. Requires mpmath.

Each line: x (rho, omega, sigma; 7 numbers), s, r (7), psi (7). Inputs
are written with repr(), so they are the exact doubles the test reads.
"""
import math
import random

import mpmath as mp

mp.mp.dps = 40


def hat(v):
    return mp.matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def ad(x):
    rho, omega, sigma = x[0:3], x[3:6], x[6]
    w, p = hat(omega), hat(rho)
    a = mp.zeros(7, 7)
    for i in range(3):
        for j in range(3):
            a[i, j] = w[i, j] + (sigma if i == j else 0)
            a[i, 3 + j] = p[i, j]
            a[3 + i, 3 + j] = w[i, j]
        a[i, 6] = -rho[i]
    return a


def right_jacobian(a):
    n = a.rows
    augmented = mp.zeros(2 * n, 2 * n)
    for i in range(n):
        for j in range(n):
            augmented[i, j] = -a[i, j]
        augmented[i, n + i] = 1
    e = mp.expm(augmented)
    return mp.matrix([[e[i, n + j] for j in range(n)] for i in range(n)])


def psi(x, s, r):
    if s == 0:
        return [mp.mpf(0)] * 7
    a = ad([mp.mpf(v) for v in x])
    rr = mp.matrix([mp.mpf(v) for v in r])
    y = mp.lu_solve(right_jacobian(mp.mpf(s) * a), rr)
    out = mp.mpf(s) * (right_jacobian(a) * y)
    return [out[i] for i in range(7)]


def main():
    rng = random.Random(2026)
    sigmas = [0.0, 1e-6, 0.01, 0.5, 1.0, 3.0, 8.0, 20.0]
    thetas = [0.0, 1e-7, 0.5, 1.5, math.pi]
    ss = [1e-8, 0.3, 0.99, 1.0]
    with open("sim3_psi_reference.txt", "w") as out:
        out.write("# x[7] (rho, omega, sigma)  s  r[7]  psi_s(ad_x) r [7]; "
                  "make_sim3_psi_reference.py\n")
        for magnitude in sigmas:
            for sign in ([1] if magnitude == 0 else [1, -1]):
                for theta in thetas:
                    for s in ss:
                        direction = [rng.uniform(-1, 1) for _ in range(3)]
                        norm = math.sqrt(sum(v * v for v in direction))
                        x = ([rng.uniform(-1, 1) for _ in range(3)] +
                             [theta * v / norm for v in direction] + [sign * magnitude])
                        r = [rng.uniform(-1, 1) for _ in range(7)]
                        value = psi(x, s, r)
                        fields = [repr(v) for v in x] + [repr(s)] + [repr(v) for v in r]
                        fields += [mp.nstr(v, 20, min_fixed=0, max_fixed=0) for v in value]
                        out.write(" ".join(fields) + "\n")


if __name__ == "__main__":
    main()
