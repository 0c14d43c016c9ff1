"""The Python package against the C++ library on the same data, measured
in one run (issue 31's performance figures).

    python bench/python_bench.py BENCH_PYTHON_REFERENCE [--repeats 7] [--processes 7]

BENCH_PYTHON_REFERENCE is the C++ program built from
bench/bench_python_reference.cpp (target bench_python_reference, Release).
Reports, as medians of the repeats after a warm run:
  * an SE(3) fit at N = 1000 and 1e5 from Python and from C++, and the ratio;
  * SE3.exp and SE3.log over 1e6 elements, batched from Python into a new
    array and into one allocated once (out=), against a C++ loop into a new
    vector and into one allocated once, and the ratios;
  * SO3.exp and SO3.log over 1e6 elements against scipy's Rotation, if
    scipy is installed.

Each Python and each C++ measurement runs in a fresh process, the two
alternating, `--processes` times. The table gives the median over processes
of each process's median and the ratio of those, and the ratio of the
fastest process of each. On the development VM a whole process, C++ or
Python, runs either at full speed or 25-35 % slower throughout (the same
binary and data; not the core, the alignment or huge pages), so a ratio of
two single processes can measure that draw instead of the overhead; the
fastest of each compares the two at full speed. The scipy comparison runs
in this process: both sides are Python.
"""

import argparse
import pathlib
import subprocess
import sys
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


def child_fit(path, repeats):
    """One process's median time of a Python fit of the matrix file."""
    data = bireg.read_trajectory(path, group="SE3", format="matrix")
    return [median_seconds(lambda: bireg.GeodesicRegression(group="SE3").fit(data["t"], data["Y"]),
                           repeats)]


def child_explog(path, repeats):
    """One process's median times of SE3.exp and SE3.log of the raw tangents,
    into new arrays and with out=."""
    x = np.fromfile(path).reshape(-1, 6)
    g = bireg.SE3.exp(x)
    g_out, x_out = np.empty_like(g), np.empty_like(x)
    return [median_seconds(lambda: bireg.SE3.exp(x), repeats),
            median_seconds(lambda: bireg.SE3.log(g), repeats),
            median_seconds(lambda: bireg.SE3.exp(x, out=g_out), repeats),
            median_seconds(lambda: bireg.SE3.log(g, out=x_out), repeats)]


def numbers(command):
    out = subprocess.run([str(c) for c in command], capture_output=True, text=True, check=True)
    return [float(v) for v in out.stdout.split()]


def alternate(python_command, cpp_command, processes):
    """Per-process results of the two commands, run alternately (which goes
    first alternates too): two arrays of shape (processes, values)."""
    python, cpp = [], []
    for k in range(processes):
        if k % 2 == 0:
            python.append(numbers(python_command))
            cpp.append(numbers(cpp_command))
        else:
            cpp.append(numbers(cpp_command))
            python.append(numbers(python_command))
    return np.array(python), np.array(cpp)


def row(work, python, cpp, unit=1e3, digits=3):
    median_python, median_cpp = float(np.median(python)), float(np.median(cpp))
    print(f"| {work} | {median_python * unit:.{digits}f} ms | {median_cpp * unit:.{digits}f} ms | "
          f"{median_python / median_cpp:.3f} | {python.min() / cpp.min():.3f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference", help="the bench_python_reference program")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--processes", type=int, default=7)
    parser.add_argument("--child", nargs=2, metavar=("KIND", "PATH"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        kind, path = args.child
        print(*(child_fit if kind == "fit" else child_explog)(path, args.repeats))
        return
    work = pathlib.Path(tempfile.mkdtemp(prefix="bireg_python_bench_"))
    me = [sys.executable, __file__, args.reference]

    print(f"Medians over {args.processes} alternating processes of each process's median of "
          f"{args.repeats} (the N = 1000 fit: {5 * args.repeats}):\n")
    print("| work | Python | C++ | Python / C++ | fastest / fastest |")
    print("|---|---|---|---|---|")
    for n, repeats in ((1000, 5 * args.repeats), (100_000, args.repeats)):
        t, Y = se3_data(n, seed=n)
        path = work / f"se3_{n}.csv"
        # The matrix format, written with repr: the C++ reads the same doubles.
        with open(path, "w") as f:
            for ti, yi in zip(t, Y):
                f.write(", ".join(repr(float(v)) for v in [ti, *yi.ravel()]) + "\n")
        python, cpp = alternate(me + ["--repeats", repeats, "--child", "fit", path],
                                [args.reference, "fit", path, repeats], args.processes)
        row(f"SE3 fit, N = {n} ({int(cpp[0, 1])} iterations)", python[:, 0], cpp[:, 0])

    n = 1_000_000
    rng = np.random.default_rng(1)
    x = np.ascontiguousarray(rng.uniform(-1.0, 1.0, (n, 6)) * [1, 1, 1, 1.5, 1.5, 1.5])
    raw = work / "tangents.f64"
    x.tofile(raw)
    python, cpp = alternate(me + ["--repeats", args.repeats, "--child", "explog", raw],
                            [args.reference, "explog", raw, args.repeats], args.processes)
    # A new array against a new vector; out= against a vector allocated once.
    row("SE3.exp, 1e6 batched, new array", python[:, 0], cpp[:, 2], digits=1)
    row("SE3.log, 1e6 batched, new array", python[:, 1], cpp[:, 3], digits=1)
    row("SE3.exp, 1e6 batched, out=", python[:, 2], cpp[:, 0], digits=1)
    row("SE3.log, 1e6 batched, out=", python[:, 3], cpp[:, 1], digits=1)

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
