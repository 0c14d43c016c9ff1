"""bireg.dask against the local threaded run, measured in one run (the
issue "Beyond one machine", relabellings).

    python bench/dask_bench.py [--permutations 99999] [--repeats 3]

The SE(3) two-sample test of 58 + 58 elements (noise 0.2 per coordinate),
exact mode, Hotelling: locally on 1 and 2 threads, and with bireg.dask on
LocalClusters of 1 and 2 worker processes (one thread each). Reports
medians of the repeats after a warm run, the speed-up of 2 workers over 1,
and Dask's overhead over the local run at equal cores; checks that every
run gave the same p-value.
"""

import argparse
import time

import numpy as np

import bireg
import bireg.dask
import distributed


def median_seconds(work, repeats):
    result = work()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--permutations", type=int, default=99999)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(58)
    a = bireg.SE3.exp(0.2 * rng.standard_normal((58, 6)))
    b = bireg.SE3.exp(0.2 * rng.standard_normal((58, 6)))
    test = dict(group="SE3", permutations=args.permutations, seed=1)

    rows, p_values = [], set()
    for threads in (1, 2):
        seconds, result = median_seconds(
            lambda: bireg.two_sample_test(a, b, threads=threads, **test), args.repeats)
        rows.append((f"local, {threads} thread(s)", seconds))
        p_values.add(result.p_value)
    for workers in (1, 2):
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None, silence_logs=40) as cluster, \
                distributed.Client(cluster) as client:
            seconds, result = median_seconds(
                lambda: bireg.dask.two_sample_test(a, b, client=client, **test), args.repeats)
        rows.append((f"bireg.dask, {workers} worker(s)", seconds))
        p_values.add(result.p_value)

    print(f"SE(3) 58 + 58, {args.permutations} relabellings, Hotelling, exact; "
          f"medians of {args.repeats}")
    for name, seconds in rows:
        print(f"  {name:28s} {seconds:8.3f} s")
    times = dict(rows)
    one_worker, two_workers = times["bireg.dask, 1 worker(s)"], times["bireg.dask, 2 worker(s)"]
    print(f"  2 workers over 1:            {one_worker / two_workers:.2f}x")
    print(f"  Dask over local, 1 core:     {one_worker / times['local, 1 thread(s)'] - 1:+.1%}")
    print(f"  Dask over local, 2 cores:    {two_workers / times['local, 2 thread(s)'] - 1:+.1%}")
    print(f"  p-values: {sorted(p_values)} ({'identical' if len(p_values) == 1 else 'DIFFERENT'})")
    if len(p_values) != 1:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
