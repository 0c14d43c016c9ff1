"""One fit of a lazily generated chunked array on a local Dask cluster,
against the one-process fit of the same data (the issue "Beyond one
machine", item 3).

    python bench/dask_fit_bench.py [--poses 10000000] [--chunk 1000000] [--workers 2]

The poses are SE(3) elements about a geodesic, generated chunk by chunk
from (seed, chunk index) alone, so that each chunk is computed again on
every pass wherever it runs and no process ever holds the whole array.
Reports the wall time of bireg.dask.fit on W worker processes (one thread
each), each worker's peak resident memory above its resident memory before
the fit, the time one generation of every chunk takes and the fit of the
same array persisted in the workers' memory (ru_maxrss: the peak over the worker's life, so the workers are
fresh), one chunk's size for comparison, and the one-process fit (threads
= W) of the same poses materialised in memory, with the largest relative
difference between the two fits' endpoints.
"""

import argparse
import resource
import time

import numpy as np

import bireg
import bireg.dask
import dask
import dask.array as da
import distributed


def covariates(block_id, size, seed):
    """Chunk `block_id`'s covariates, from (seed, block) alone."""
    return np.random.default_rng([seed, block_id]).uniform(0, 10, size)


def chunk(block_id, size, seed):
    """Chunk `block_id`'s covariates and poses (the same covariates): the
    poses built slab by slab into the chunk, so that generating a chunk
    holds little more than the chunk, as a loader reading it from a file
    would."""
    rng = np.random.default_rng([seed, block_id])
    t = rng.uniform(0, 10, size)
    start = bireg.SE3.exp(np.array([1.0, 2.0, -1.0, 0.3, -0.2, 0.1]))  # (translation, rotation)
    velocity = np.array([0.4, -0.1, 0.2, 0.05, 0.02, -0.03])
    Y = np.empty((size, 4, 4))
    slab = 65536
    for s in range(0, size, slab):
        e = min(size, s + slab)
        x = 0.05 * rng.standard_normal((e - s, 6)) + t[s:e, None] * velocity
        Y[s:e] = start @ bireg.SE3.exp(x)
    return t, Y


def lazy(poses, chunk_size, seed):
    """t and Y as Dask arrays whose chunks are computed by chunk()."""
    sizes = [chunk_size] * (poses // chunk_size) + ([poses % chunk_size] if poses % chunk_size
                                                     else [])

    def t_block(block_info=None):
        index = block_info[None]["chunk-location"][0]
        return covariates(index, sizes[index], seed)

    def y_block(block_info=None):
        index = block_info[None]["chunk-location"][0]
        return chunk(index, sizes[index], seed)[1]

    t = da.map_blocks(t_block, chunks=(tuple(sizes),), dtype=np.float64, meta=np.empty(0))
    Y = da.map_blocks(y_block, chunks=(tuple(sizes), 4, 4), dtype=np.float64,
                      meta=np.empty((0, 4, 4)))
    return t, Y


def peak_kib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=10_000_000)
    parser.add_argument("--chunk", type=int, default=1_000_000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--saturation", type=float, default=None,
                        help="distributed.scheduler.worker-saturation (Dask's default: 1.1)")
    args = parser.parse_args()
    if args.saturation is not None:
        dask.config.set({"distributed.scheduler.worker-saturation": args.saturation})
    chunk_mib = args.chunk * 16 * 8 / 2**20

    with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40,
                                  memory_limit=0) as cluster, \
            distributed.Client(cluster) as client:
        client.run(lambda: __import__("bireg.dask"))
        before = client.run(peak_kib)
        t, Y = lazy(args.poses, args.chunk, args.seed)
        start = time.perf_counter()
        spread = bireg.dask.fit(t, Y, group="SE3", client=client)
        seconds = time.perf_counter() - start
        after = client.run(peak_kib)
        # What a pass costs in generating the chunks alone, and the fit of
        # the same array persisted in the workers' memory.
        start = time.perf_counter()
        client.compute(Y[:, 0, 0].sum() + t.sum()).result()
        generation = time.perf_counter() - start
        t, Y = client.persist([t, Y])
        distributed.wait([t, Y])
        start = time.perf_counter()
        persisted = bireg.dask.fit(t, Y, group="SE3", client=client)
        persisted_seconds = time.perf_counter() - start
        del t, Y
    print(f"bireg.dask.fit, {args.poses} SE(3) poses in chunks of {args.chunk} "
          f"({chunk_mib:.0f} MiB), {args.workers} workers: {seconds:.2f} s, "
          f"{spread.n_iter_} iterations, status {spread.status_}")
    print(f"  generating every chunk once: {generation:.2f} s (the lazy fit does it at "
          f"each of its passes); the same fit of the array persisted on the workers: "
          f"{persisted_seconds:.2f} s, endpoints equal: "
          f"{np.array_equal(persisted.g1_, spread.g1_)}")
    for worker in sorted(after):
        grown = (after[worker] - before[worker]) / 1024
        print(f"  worker {worker}: peak {after[worker] / 1024:.0f} MiB, "
              f"{grown:.0f} MiB above its start ({grown / chunk_mib:.2f} chunks)")

    parts = [chunk(i, min(args.chunk, args.poses - i * args.chunk), args.seed)
             for i in range((args.poses + args.chunk - 1) // args.chunk)]
    t_all = np.concatenate([p[0] for p in parts])
    Y_all = np.concatenate([p[1] for p in parts])
    del parts
    start = time.perf_counter()
    local = bireg.GeodesicRegression(group="SE3", threads=args.workers).fit(t_all, Y_all)
    local_seconds = time.perf_counter() - start
    difference = max(np.linalg.norm(spread.g0_ - local.g0_) / np.linalg.norm(local.g0_),
                     np.linalg.norm(spread.g1_ - local.g1_) / np.linalg.norm(local.g1_))
    print(f"one process, {args.workers} threads, data in memory: {local_seconds:.2f} s, "
          f"{local.n_iter_} iterations; Dask / local {seconds / local_seconds:.2f}x; "
          f"largest relative endpoint difference {difference:.1e}")


if __name__ == "__main__":
    main()
