"""bireg on a Dask cluster: the cohorts' work spread over the workers of a
``distributed`` client, with the answers of one process.

Install with ``pip install ".[dask]"``. Each function takes the arguments
of the local function of the same name, plus ``client`` (default: the
current ``distributed`` client) and ``blocks`` (how many tasks; default
four per worker), accepts numpy or Dask arrays, and returns the local
function's result type:

* ``fit``: one geodesic fitted to observations chunked along their first
  axis (Dask arrays, e.g. 1e9 poses in chunks of 1e6, or numpy arrays,
  chunked here). Each pass over the observations is one task per chunk,
  which returns that chunk's sums (``bireg::chunk_sums``); the client joins
  them in chunk order and takes the iteration's step
  (``bireg::fit_by_chunks``). The result equals the local fit's to about
  1e-12 relative: only the order of the sums differs. A lazy Dask array is
  computed again for every pass (a fit is 4 passes plus one per
  evaluation of the force: about one per iteration, more with halved
  steps), so that no worker holds more than the chunks it works on;
  persist it first when it fits in the cluster's memory and is costly to
  compute.
* ``fit_many``: the subjects in blocks; each block is the local fit_many on
  the same shared interval, so every trend equals the local one bit for bit.
* ``two_sample_test`` of two samples of elements, and ``compare_trends``:
  the relabellings in blocks. Relabelling b depends on (seed, b) only, each
  block counts its own, and ``bireg::combine_two_sample`` adds the integer
  counts: p equals the local p exactly for any number of workers, blocks
  and threads.
* ``two_sample_test`` of element-wise maps ((m, K, n, n) arrays): the
  elements in blocks, each worker sent only its block's elements (for all
  subjects; from Dask arrays, each worker computes its block from their
  chunks and the client never holds the cohorts), each block with all the
  relabellings;
  ``bireg::combine_elementwise`` joins them, since the q-values and the
  family-wise p-values need every element.

A task is a pure function of its arguments, so a task whose worker died is
run again by Dask with the same result. Workers print nothing: progress is
Dask's own dashboard (the calls block until the result is joined). On a
real cluster only the client changes (``distributed.Client(address)``,
dask-jobqueue's ``SLURMCluster``, dask-kubernetes, scaled to its workers
first); docs/distributed.md says how the cost scales. When several blocks
fail, the error raised is one of theirs, not necessarily the first in
cohort order as the local function's is.
"""

import importlib.metadata
import warnings
from dataclasses import replace

import numpy as np

try:
    import distributed
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError("bireg.dask needs Dask's distributed scheduler: "
                      "pip install \"bireg[dask]\" (or dask and distributed)") from error

from . import __version__, _arrays
from . import cohorts as _cohorts
from . import groups as _groups
from . import regression as _regression
from . import _bireg
from ._bireg import combine_elementwise, combine_two_sample

__all__ = ["fit", "fit_many", "two_sample_test", "compare_trends"]

_BLOCKS_PER_WORKER = 4


def _client(client):
    if client is not None:
        return client
    try:
        return distributed.get_client()
    except ValueError:
        raise ValueError("bireg.dask needs a distributed client: create one "
                         "(distributed.Client(...)) or pass client=") from None


def _check_workers(client):
    """RuntimeError naming the workers that lack bireg or have another
    version than the client's. The version is read from the installed
    package's metadata by a standard-library function, so that the check
    itself needs nothing of bireg on the workers."""
    versions = client.run(importlib.metadata.version, "bireg", on_error="return")
    if not versions:
        raise RuntimeError("the Dask client has no workers yet (scale the cluster, or "
                           "client.wait_for_workers(n), first)")
    wrong = {worker: ("bireg is not installed" if isinstance(found, Exception) else found)
             for worker, found in versions.items() if found != __version__}
    if wrong:
        listed = "; ".join(f"{worker}: {found}" for worker, found in sorted(wrong.items()))
        raise RuntimeError(f"every worker needs bireg {__version__}, as the client has; "
                           f"{listed}")
    return len(versions)


def _blocks(count, blocks, workers):
    """(first, size) of `blocks` consecutive blocks of range(count), sizes
    differing by at most one; at least one block, none empty unless count
    is 0."""
    if blocks is None:
        blocks = _BLOCKS_PER_WORKER * workers
    blocks = _arrays.positive_int(blocks, "blocks")
    if blocks < 1:
        raise ValueError(f"blocks must be at least 1, got {blocks}")
    blocks = min(blocks, max(count, 1))
    edges = [count * i // blocks for i in range(blocks + 1)]
    return [(edges[i], edges[i + 1] - edges[i]) for i in range(blocks)]


def _gather(client, function, plan, blocks):
    """function(plan, first, size) for every block, on the workers, in
    block order. The plan is sent once to the workers."""
    shared = client.scatter(plan, broadcast=True, hash=False)
    futures = [client.submit(function, shared, first, size, pure=False) for first, size in blocks]
    return client.gather(futures)


def _test_share(plan, first, size):
    return plan.run_test(first, size)


def _map_slice(plan):
    return plan.run_map()


def _trend_share(plan, first, size):
    return plan.run(first, size)


def two_sample_test(A, B, group, statistic="hotelling", variant="invariant", permutations=9999,
                    seed=0, threads=1, mode="exact", client=None, blocks=None):
    """``bireg.two_sample_test`` on the workers: the relabellings (a test of
    elements) or the elements (a map) in ``blocks`` tasks. The result equals
    the local one with the same arguments, whatever the number of workers,
    blocks or threads."""
    client = _client(client)
    arguments = (group, statistic, variant, permutations, seed, threads, mode)
    if _is_dask_array(A) and _is_dask_array(B) and A.ndim == 4 and B.ndim == 4:
        return _lazy_map(A, B, arguments, client, blocks)
    plan = _cohorts._plan(np.asarray(A), np.asarray(B), *arguments)
    workers = _check_workers(client)
    if plan.elements == 0:
        shares = _gather(client, _test_share, plan, _blocks(plan.permutations, blocks, workers))
        return _cohorts._test_result(combine_two_sample(plan.group, shares))
    # Each worker is sent its own slice of the elements, for all subjects,
    # inside its task (not scattered: a task's own arguments let Dask rerun
    # it when its worker dies; scattered data held by one worker would be
    # lost with it).
    futures = [client.submit(_map_slice, plan.slice(first, size), pure=False)
               for first, size in _blocks(plan.elements, blocks, workers)]
    return _cohorts._map_result(combine_elementwise(plan.group, client.gather(futures)))


def _is_dask_array(x):
    try:
        import dask.array
    except ImportError:  # pragma: no cover - distributed depends on dask
        return False
    return isinstance(x, dask.array.Array)


def _slice_map(a, b, arguments, first):
    """Run on a worker: the map of elements first .. of this slice, whose
    arrays the worker computed from its chunks."""
    plan = _cohorts._plan(a, b, *arguments)
    return replace(plan, first_element=first).run_map()


def _lazy_map(A, B, arguments, client, blocks):
    """An element-wise map of two Dask arrays (m, K, n, n) and (k, K, n, n):
    each task computes its own slice of the elements from the arrays'
    chunks on a worker, so no machine, the client included, holds the whole
    cohorts. Shapes are checked here; everything else by the library on
    the workers, which name the element by its index in the whole map."""
    import dask

    g = _groups.get(arguments[0])
    n = g.matrix_size
    if A.shape[2:] != (n, n) or B.shape[2:] != (n, n) or A.shape[1] != B.shape[1]:
        raise ValueError(f"A and B must have shape (m, K, {n}, {n}) and (k, K, {n}, {n}) with "
                         f"one K, got {A.shape} and {B.shape}")
    workers = _check_workers(client)
    tasks = [dask.delayed(_slice_map, pure=False)(A[:, first:first + size],
                                                  B[:, first:first + size], arguments, first)
             for first, size in _blocks(int(A.shape[1]), blocks, workers)]
    slices = client.gather(client.compute(tasks))
    return _cohorts._map_result(combine_elementwise(g.name, slices))


def compare_trends(trends_a, trends_b, group, statistic="hotelling", variant="invariant",
                   permutations=9999, seed=0, threads=1, client=None, blocks=None):
    """``bireg.compare_trends`` on the workers, the relabellings in
    ``blocks`` tasks; equal to the local result."""
    client = _client(client)
    plan = _cohorts._trend_plan(np.asarray(trends_a), np.asarray(trends_b), group, statistic,
                                variant, permutations, seed, threads)
    workers = _check_workers(client)
    shares = _gather(client, _trend_share, plan, _blocks(plan.permutations, blocks, workers))
    return _cohorts._test_result(combine_two_sample(plan.group, shares))


def _fit_subjects(subjects, first, group, t0, t1, threads):
    return _cohorts._fit_block(subjects, group, t0, t1, threads, first)


def _covariate_range(subjects, first=0):
    """(smallest, largest) finite covariate of the subjects, or None: the
    local fit_many's default interval, found over blocks."""
    low, high = np.inf, -np.inf
    for i, subject in enumerate(subjects, start=first):
        t = _arrays.covariates(_arrays.subject_pair(subject, i)[0], f"subject {i}'s t")
        t = t[np.isfinite(t)]
        if t.size:
            low, high = min(low, float(t.min())), max(high, float(t.max()))
    return (low, high) if low <= high else None


def _shared_interval(interval, ranges):
    """The interval every block uses: the given one, or the covariates'
    range over all blocks (NaN, NaN when no covariate is finite: the
    library then refuses, as locally)."""
    if interval is not None:
        return _cohorts._interval(interval)
    ranges = [r for r in ranges if r is not None]
    if not ranges:
        return float("nan"), float("nan")
    return min(r[0] for r in ranges), max(r[1] for r in ranges)


def _join_fits(parts):
    return _cohorts.FitManyResult(
        t0=parts[0]["t0"], t1=parts[0]["t1"],
        trends=np.concatenate([part["trends"] for part in parts]),
        n_iter=np.concatenate([part["n_iter"] for part in parts]))


def fit_many(subjects, group, interval=None, threads=1, client=None, blocks=None):
    """``bireg.fit_many`` on the workers. ``subjects`` is a sequence of
    (t, Y) pairs, split into ``blocks`` tasks of consecutive subjects, or a
    ``dask.bag.Bag`` of them, one task per non-empty partition (``blocks``
    does not apply; the bag is read three times: sizes, covariate range and
    fits, so persist it first if it is costly to read). Without
    ``interval`` the shared interval is, as locally, from the smallest to
    the largest finite covariate of all subjects, found before any fit so
    that every block uses the same one. A failed fit raises ValueError
    naming the subject by its index in the whole cohort."""
    client = _client(client)
    g = _groups.get(group)
    threads = _arrays.positive_int(threads, "threads")
    if _is_bag(subjects):
        return _fit_many_bag(subjects, g.name, interval, threads, client)
    pairs = []
    for i, subject in enumerate(subjects):
        t, Y = _arrays.subject_pair(subject, i)
        pairs.append((_arrays.covariates(t, f"subject {i}'s t"), np.asarray(Y)))
    if not pairs:
        raise ValueError("fit_many: there are no subjects")
    t0, t1 = _shared_interval(interval, [_covariate_range(pairs)])
    workers = _check_workers(client)
    futures = [client.submit(_fit_subjects, pairs[first:first + size], first, g.name, t0, t1,
                             threads, pure=False)
               for first, size in _blocks(len(pairs), blocks, workers)]
    return _join_fits(client.gather(futures))


def _count(partition):
    return sum(1 for _ in partition)


def _is_bag(subjects):
    try:
        import dask.bag
    except ImportError:  # pragma: no cover - distributed depends on dask
        return False
    return isinstance(subjects, dask.bag.Bag)


def _fit_many_bag(bag, group, interval, threads, client):
    import dask

    _check_workers(client)
    partitions = bag.to_delayed()
    sizes = client.gather(client.compute([dask.delayed(_count)(p) for p in partitions]))
    firsts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(int).tolist()
    used = [(p, first) for p, first, size in zip(partitions, firsts, sizes) if size > 0]
    if not used:
        raise ValueError("fit_many: there are no subjects")
    ranges = []
    if interval is None:
        ranges = client.gather(client.compute(
            [dask.delayed(_covariate_range)(p, first) for p, first in used]))
    t0, t1 = _shared_interval(interval, ranges)
    fits = client.compute([dask.delayed(_fit_subjects)(p, first, group, t0, t1, threads)
                           for p, first in used])
    return _join_fits(client.gather(fits))


_DEFAULT_CHUNK = 1_000_000


def _block_sums(t, Y, *w, group, request, block_info=None):
    """bireg::chunk_sums of one chunk, on a worker: t and w arrive as (k, 1,
    1) blocks beside Y's (k, n, n), so that one map_blocks task per chunk
    computes the chunk (a lazy array's own tasks fuse into it) and its sums,
    and holds no other chunk. Returns the sums in a (1, 1, 1) object array:
    a block that keeps its axes lets Dask fuse the chunk's tasks into this
    one (dropping axes kept them apart, and a worker then held chunks
    waiting for their sums, or received them from another worker)."""
    offset = block_info[0]["array-location"][0][0]
    weights = np.ascontiguousarray(w[0][:, 0, 0], dtype=np.float64) if w else np.empty(0)
    out = np.empty((1, 1, 1), dtype=object)
    out[0, 0, 0] = _bireg.chunk_sums(group, request,
                                     np.ascontiguousarray(t[:, 0, 0], dtype=np.float64),
                                     np.ascontiguousarray(Y, dtype=np.float64), weights, offset)
    return out


def _chunked_arrays(t, Y, sample_weight, n, chunk_size):
    """t, Y and the weights (or None) as Dask arrays with the same chunks
    along the observations (Y whole along its matrix axes), and which of
    them were made here from numpy arrays (cut into chunk_size
    observations, or into Y's chunks)."""
    import dask.array as da

    chunk_size = _arrays.positive_int(chunk_size, "chunk_size")
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, got {chunk_size}")
    made = []
    if not _is_dask_array(Y):
        Y = da.from_array(_arrays.matrices(Y, n), chunks=(chunk_size, n, n))
        made.append("Y")
    if any(np.isnan(size) for size in Y.shape):
        raise ValueError("Y has chunks of unknown size: call Y.compute_chunk_sizes() first")
    if Y.ndim != 3 or Y.shape[1:] != (n, n):
        raise ValueError(f"Y must have shape (N, {n}, {n}), got {Y.shape}")
    Y = Y.rechunk({1: n, 2: n})
    observations = Y.chunks[0]

    def along(a, name):
        if not _is_dask_array(a):
            a = np.asarray(a)
        if a.shape != (Y.shape[0],):
            raise ValueError(f"{name} must have shape ({Y.shape[0]},), got {a.shape}")
        if _is_dask_array(a):
            return a.rechunk((observations,))
        made.append(name)
        return da.from_array(np.ascontiguousarray(a, dtype=np.float64), chunks=(observations,))

    t = along(t, "t")
    w = None if sample_weight is None else along(sample_weight, "sample_weight")
    return t, Y, w, made


def fit(t, Y, group="SE3", sample_weight=None, solver="gauss_newton", method="exact", tol=1e-10,
        max_iter=1000, client=None, chunk_size=_DEFAULT_CHUNK):
    """``bireg.GeodesicRegression(group, solver, method, tol, max_iter).fit(t,
    Y, sample_weight)`` with the observations on the workers: ``Y`` (N, n,
    n) and ``t``, ``sample_weight`` (N,) as Dask arrays chunked along the
    observations (t and the weights are rechunked to Y's chunks) or numpy
    arrays (cut into ``chunk_size`` observations and persisted on the
    workers). Returns the fitted ``GeodesicRegression``: endpoints,
    velocities, status, iterations and diagnostics equal the local fit's
    to about 1e-12 relative. Its residuals, covariance, confidence band
    and trend test need the observations in one process and raise
    (``residuals_``: AttributeError; the others: ValueError). Invalid
    input raises ValueError naming the observation by its index in the
    whole array, as locally. A lazy array is computed at every pass and
    must give the same values each time."""
    client = _client(client)
    estimator = _regression.GeodesicRegression(group=group, solver=solver, method=method,
                                               tol=tol, max_iter=max_iter)
    g = _groups.get(group)
    max_iter = _arrays.positive_int(max_iter, "max_iter")
    t, Y, w, made = _chunked_arrays(t, Y, sample_weight, g.matrix_size, chunk_size)
    _check_workers(client)
    if made:
        # Arrays made here from numpy travel to the workers once, inside the
        # graph, and stay there for every pass, so that a dead worker's
        # chunks can be computed again (scattered data would be lost with
        # it); Dask's advice against large graphs is for data it could load
        # itself, which numpy input is not.
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Sending large graph",
                                    category=UserWarning)
            arrays = {"t": t, "Y": Y, "sample_weight": w}
            persisted = dict(zip(made, client.persist([arrays[name] for name in made])))
        t, Y, w = (persisted.get(name, arrays[name]) for name in ("t", "Y", "sample_weight"))
    import dask.array as da

    columns = [t[:, None, None], Y] + ([] if w is None else [w[:, None, None]])
    blocks = (1,) * len(Y.chunks[0])

    def reduce(request):
        """Every chunk's sums, in chunk order."""
        sums = da.map_blocks(_block_sums, *columns, group=g.name, request=request,
                             chunks=(blocks, (1,), (1,)), dtype=object,
                             meta=np.empty((0, 0, 0), dtype=object))
        return list(client.gather(client.compute(sums))[:, 0, 0])

    handle = _bireg.fit_by_chunks(g.name, reduce, solver, method, float(tol), max_iter)
    return estimator._adopt(handle, stacklevel=3)
