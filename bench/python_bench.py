"""The Python package against the C++ library on the same data, measured
in one run (issue 31's performance figures).

    python bench/python_bench.py BENCH_PYTHON_REFERENCE [--repeats 7]

BENCH_PYTHON_REFERENCE is the C++ program built from
bench/bench_python_reference.cpp (target bench_python_reference, Release).
Reports, as medians of the repeats after a warm run:
  * an SE(3) fit at N = 1000 and 1e5 from Python and from C++, and the ratio;
  * SE3.exp and SE3.log over 1e6 elements, batched from Python (into a new
    array, and into one allocated once, out=, as the C++ loop writes into
    a vector allocated once) and as a C++ loop, and the ratios;
  * SO3.exp and SO3.log over 1e6 elements against scipy's Rotation, if
    scipy is installed.
"""

import argparse
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import bireg


def median_seconds(work, repeats):
    work()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def se3_data(n, seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, n)
    Y = bireg.SE3.exp(t[:, None] * rng.standard_normal(6) + 0.1 * rng.standard_normal((n, 6)))
    return t, Y


def reference(program, *args):
    out = subprocess.run([program, *map(str, args)], capture_output=True, text=True, check=True)
    return [float(v) for v in out.stdout.split()]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference", help="the bench_python_reference program")
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    work = pathlib.Path(tempfile.mkdtemp(prefix="bireg_python_bench_"))

    print("| work | Python | C++ | Python / C++ |")
    print("|---|---|---|---|")
    for n, repeats in ((1000, 5 * args.repeats), (100_000, args.repeats)):
        t, Y = se3_data(n, seed=n)
        path = work / f"se3_{n}.csv"
        # The matrix format, written with repr: the C++ reads the same doubles.
        with open(path, "w") as f:
            for ti, yi in zip(t, Y):
                f.write(", ".join(repr(float(v)) for v in [ti, *yi.ravel()]) + "\n")
        data = bireg.read_trajectory(path, group="SE3", format="matrix")
        python = median_seconds(lambda: bireg.GeodesicRegression(group="SE3").fit(data["t"],
                                                                                 data["Y"]),
                                repeats)
        cpp, iterations = reference(args.reference, "fit", path, repeats)
        print(f"| SE3 fit, N = {n} ({int(iterations)} iterations) | {python * 1e3:.3f} ms | "
              f"{cpp * 1e3:.3f} ms | {python / cpp:.3f} |")

    n = 1_000_000
    rng = np.random.default_rng(1)
    x = np.ascontiguousarray(rng.uniform(-1.0, 1.0, (n, 6)) * [1, 1, 1, 1.5, 1.5, 1.5])
    raw = work / "tangents.f64"
    x.tofile(raw)
    g = bireg.SE3.exp(x)
    python_exp = median_seconds(lambda: bireg.SE3.exp(x), args.repeats)
    python_log = median_seconds(lambda: bireg.SE3.log(g), args.repeats)
    cpp_exp, cpp_log = reference(args.reference, "explog", raw, args.repeats)
    print(f"| SE3.exp, 1e6 batched | {python_exp * 1e3:.1f} ms | {cpp_exp * 1e3:.1f} ms | "
          f"{python_exp / cpp_exp:.3f} |")
    print(f"| SE3.log, 1e6 batched | {python_log * 1e3:.1f} ms | {cpp_log * 1e3:.1f} ms | "
          f"{python_log / cpp_log:.3f} |")
    g_out, x_out = np.empty_like(g), np.empty_like(x)
    python_exp = median_seconds(lambda: bireg.SE3.exp(x, out=g_out), args.repeats)
    python_log = median_seconds(lambda: bireg.SE3.log(g, out=x_out), args.repeats)
    print(f"| SE3.exp, 1e6 batched, out= | {python_exp * 1e3:.1f} ms | {cpp_exp * 1e3:.1f} ms | "
          f"{python_exp / cpp_exp:.3f} |")
    print(f"| SE3.log, 1e6 batched, out= | {python_log * 1e3:.1f} ms | {cpp_log * 1e3:.1f} ms | "
          f"{python_log / cpp_log:.3f} |")

    try:
        from scipy.spatial.transform import Rotation
    except ImportError:
        print("\nscipy is not installed: no SO3 comparison")
        return
    w = x[:, 3:].copy()
    r = bireg.SO3.exp(w)
    print("\n| work | bireg | scipy Rotation | scipy / bireg |")
    print("|---|---|---|---|")
    ours = median_seconds(lambda: bireg.SO3.exp(w), args.repeats)
    theirs = median_seconds(lambda: Rotation.from_rotvec(w).as_matrix(), args.repeats)
    print(f"| SO3.exp, 1e6 | {ours * 1e3:.1f} ms | {theirs * 1e3:.1f} ms | {theirs / ours:.2f} |")
    ours = median_seconds(lambda: bireg.SO3.log(r), args.repeats)
    theirs = median_seconds(lambda: Rotation.from_matrix(r).as_rotvec(), args.repeats)
    print(f"| SO3.log, 1e6 | {ours * 1e3:.1f} ms | {theirs * 1e3:.1f} ms | {theirs / ours:.2f} |")


if __name__ == "__main__":
    main()
