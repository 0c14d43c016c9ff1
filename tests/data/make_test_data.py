#!/usr/bin/env python3
"""Writes the small trajectory files the bireg_fit tests read (standard library
only; deterministic). Run from this folder: python3 make_test_data.py"""
import math
import random

random.seed(7)


def rot(axis_angle):
    x, y, z = axis_angle
    t = math.sqrt(x * x + y * y + z * z)
    if t == 0:
        return [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    kx, ky, kz = x / t, y / t, z / t
    c, s, v = math.cos(t), math.sin(t), 1 - math.cos(t)
    return [[c + kx * kx * v, kx * ky * v - kz * s, kx * kz * v + ky * s],
            [ky * kx * v + kz * s, c + ky * ky * v, ky * kz * v - kx * s],
            [kz * kx * v - ky * s, kz * ky * v + kx * s, c + kz * kz * v]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def quat(r):
    w = math.sqrt(max(0.0, 1 + r[0][0] + r[1][1] + r[2][2])) / 2
    return (w, (r[2][1] - r[1][2]) / (4 * w), (r[0][2] - r[2][0]) / (4 * w), (r[1][0] - r[0][1]) / (4 * w))


def noisy_rotation(s):
    base = matmul(rot((0.3, -0.2, 0.5)), rot((0.9 * s, 0.4 * s, -0.3 * s)))
    return matmul(base, rot([random.uniform(-0.05, 0.05) for _ in range(3)]))


def row(values, sep=", "):
    return sep.join(repr(v) for v in values)


so3 = []
for i in range(12):
    s = i / 11
    r = noisy_rotation(s)
    so3.append(row([2.0 + 3.0 * s] + [x for line in r for x in line]))

with open("so3_small.csv", "w") as f:
    f.write("# SO3 test trajectory: t, R row-major\n\n")
    for i, line in enumerate(so3):
        f.write(line.replace(", ", " ", 3) if i % 3 == 1 else line)  # mixed separators
        f.write("\n")
        if i == 5:
            f.write("   \n# a comment in the middle\n")

shuffled = so3[:]
random.shuffle(shuffled)
with open("so3_small_shuffled.csv", "w") as f:
    f.write("\n".join(shuffled) + "\n")

with open("se3_small.tum", "w") as f:
    f.write("# timestamp tx ty tz qx qy qz qw\n")
    for i in range(15):
        s = i / 14
        r = noisy_rotation(s)
        w, x, y, z = quat(r)
        p = [1.0 + 0.8 * s + random.uniform(-0.02, 0.02), -0.5 * s + random.uniform(-0.02, 0.02),
             0.3 + random.uniform(-0.02, 0.02)]
        f.write(row([100.0 + 0.1 * i] + p + [x, y, z, w], " ") + "\n")

with open("se2_small.csv", "w") as f:
    for i in range(10):
        s = i / 9
        a = 0.2 + 1.1 * s + random.uniform(-0.03, 0.03)
        m = [[math.cos(a), -math.sin(a), 2 * s + random.uniform(-0.05, 0.05)],
             [math.sin(a), math.cos(a), 1 - s + random.uniform(-0.05, 0.05)], [0.0, 0.0, 1.0]]
        f.write(row([float(i)] + [x for line in m for x in line]) + "\n")

with open("so2_small.csv", "w") as f:
    for i in range(8):
        a = -0.4 + 0.2 * i + random.uniform(-0.02, 0.02)
        f.write(row([0.5 * i, math.cos(a), -math.sin(a), math.sin(a), math.cos(a)]) + "\n")

good = so3[0]
numbers = good.split(", ")
errors = {
    "truncated.csv": [so3[0], so3[1], ", ".join(numbers[:9])],
    "text_in_number.csv": [so3[0], ", ".join(numbers[:4] + ["abc"] + numbers[5:]), so3[2]],
    "not_in_group.csv": [so3[0], ", ".join([numbers[0]] + [repr(2 * float(v)) for v in numbers[1:]]), so3[2]],
    "empty.csv": ["# nothing but a comment", ""],
    "one_observation.csv": [so3[0]],
    "equal_covariates.csv": [", ".join(["4.0"] + line.split(", ")[1:]) for line in so3[:5]],
    "nan.csv": [so3[0], ", ".join(numbers[:3] + ["nan"] + numbers[4:]), so3[2]],
    "huge.csv": [so3[0], so3[1], ", ".join(["1e400"] + numbers[1:])],
}
for name, lines in errors.items():
    with open(name, "w") as f:
        f.write("\n".join(lines) + "\n")

with open("bad_quaternion.tum", "w") as f:
    f.write("0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 0.5\n")
with open("wrong_columns.tum", "w") as f:
    f.write("0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n")


# --- scene groups (matrix format): Sim3, SL3, GLp3 -------------------------

def expm(a):
    """Matrix exponential by scaling and squaring a Taylor series."""
    n = len(a)
    norm = max(sum(abs(x) for x in r) for r in a)
    squarings = 0
    while norm / 2 ** squarings > 0.5:
        squarings += 1
    scaled = [[x / 2 ** squarings for x in r] for r in a]
    total = [[float(i == j) for j in range(n)] for i in range(n)]
    term = [r[:] for r in total]
    for k in range(1, 30):
        term = [[x / k for x in r] for r in matmul(term, scaled)]
        total = [[total[i][j] + term[i][j] for j in range(n)] for i in range(n)]
    for _ in range(squarings):
        total = matmul(total, total)
    return total


def lin(a, b, s):
    return [[a[i][j] + s * b[i][j] for j in range(len(a))] for i in range(len(a))]


def noise(n, size, traceless=False):
    m = [[random.uniform(-size, size) for _ in range(n)] for _ in range(n)]
    if traceless:
        tr = sum(m[i][i] for i in range(n)) / n
        for i in range(n):
            m[i][i] -= tr
    return m


def scene_file(name, header, start, velocity, count, n, traceless):
    with open(name, "w") as f:
        f.write(header + "\n")
        for i in range(count):
            s = i / (count - 1)
            m = matmul(expm(lin(start, velocity, s)), expm(noise(n, 0.02, traceless)))
            f.write(row([1.5 * i] + [x for r in m for x in r]) + "\n")


# Sim3: hat(rho, omega, sigma) = [hat(omega) + sigma I, rho; 0 0].
def sim3_hat(rho, omega, sigma):
    x, y, z = omega
    return [[sigma, -z, y, rho[0]], [z, sigma, -x, rho[1]], [-y, x, sigma, rho[2]], [0, 0, 0, 0]]


with open("sim3_small.csv", "w") as f:
    f.write("# Sim3 test trajectory: t, [s R t; 0 1] row-major (scale grows e^0.6)\n")
    for i in range(14):
        s = i / 13
        nz = [random.uniform(-0.02, 0.02) for _ in range(7)]
        m = matmul(expm(sim3_hat((0.5, -0.3, 0.2), (0.2, 0.1, -0.4), -0.2)),
                   expm(sim3_hat((1.2 * s, 0.4 * s, -0.5 * s), (0.3 * s, -0.6 * s, 0.2 * s), 0.6 * s)))
        m = matmul(m, expm(sim3_hat(nz[0:3], nz[3:6], nz[6])))
        f.write(row([0.1 * i] + [x for r in m for x in r]) + "\n")

scene_file("sl3_small.csv", "# SL3 test trajectory (homographies, det 1): t, H row-major",
           [[0.1, 0.2, 0.0], [-0.1, 0.05, 0.3], [0.02, -0.01, -0.15]],
           [[0.3, -0.4, 0.5], [0.2, -0.1, -0.3], [0.05, 0.1, -0.2]], 12, 3, True)
scene_file("glp3_small.csv", "# GLp3 test trajectory (det > 0): t, A row-major",
           [[0.2, 0.1, 0.0], [0.0, -0.1, 0.2], [0.1, 0.0, 0.3]],
           [[0.4, -0.3, 0.2], [0.3, 0.2, -0.1], [-0.2, 0.1, 0.5]], 12, 3, False)

# One observation each that is not in the group (sheared similarity,
# determinant 2 in SL3, negative determinant in GL+(3)).
for name, group_file, index, factor in [("sim3_not_in_group.csv", "sim3_small.csv", 2, None),
                                        ("sl3_not_in_group.csv", "sl3_small.csv", 3, 2 ** (1 / 3)),
                                        ("glp3_not_in_group.csv", "glp3_small.csv", 1, -1.0)]:
    with open(group_file) as f:
        lines = [line for line in f.read().splitlines() if not line.startswith("#")]
    numbers = [float(v) for v in lines[index].split(", ")]
    if factor is None:
        numbers[2] += 0.05  # m01: shear
    else:
        numbers[1:] = [v * factor for v in numbers[1:]]
    lines[index] = row(numbers)
    with open(name, "w") as f:
        f.write("\n".join(lines) + "\n")

# SL3 data with one observation, diag(-2, -0.5, 1), that the middle one
# (a rotation by 0.2 about z) sees through two negative real eigenvalues:
# no real logarithm exists.
with open("sl3_no_logarithm.csv", "w") as f:
    for i in range(5):
        c, s = math.cos(0.1 * i), math.sin(0.1 * i)
        m = [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0] if i != 4 else [-2.0, 0, 0, 0, -0.5, 0, 0, 0, 1.0]
        f.write(row([float(i)] + [float(v) for v in m]) + "\n")
