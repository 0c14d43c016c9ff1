"""bireg.dask on a local cluster of worker processes: every result equals the
local function's exactly, whatever the number of workers and blocks; a
worker that dies mid-computation changes nothing; bad data are refused with
the index the local function gives."""

import importlib.metadata
import os
import signal
import threading
import time

import numpy as np
import pytest

import bireg

distributed = pytest.importorskip("distributed")
import bireg.dask  # noqa: E402  (after the skip: it needs distributed)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=3, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture()
def rng():
    return np.random.default_rng(20261126)


def rotations(rng, count, centre, sd=0.3):
    g = bireg.SO3
    return g.compose(centre, g.exp(sd * rng.standard_normal((count, 3))))


def subjects(rng, count, velocity):
    g = bireg.SE3
    out = []
    for _ in range(count):
        start = g.exp(0.1 * rng.standard_normal(6))
        t = np.sort(rng.uniform(0, 2, 9))
        Y = g.compose(start, g.exp(t[:, None] * (velocity + 0.05 * rng.standard_normal(6))))
        out.append((t, g.compose(Y, g.exp(0.02 * rng.standard_normal((9, 6))))))
    return out


def same(x, y):
    """Equal field by field, exactly (arrays bit for bit)."""
    assert type(x) is type(y)
    for name, value in vars(x).items():
        other = vars(y)[name]
        if isinstance(value, np.ndarray):
            assert value.shape == other.shape and np.array_equal(value, other), name
        else:
            assert value == other, name


def workers(client, count):
    """A client restricted to the first `count` workers: the same cluster,
    seen as a smaller one."""
    addresses = sorted(client.scheduler_info()["workers"])[:count]

    class Restricted:
        def __getattr__(self, name):
            return getattr(client, name)

        def submit(self, *args, **kwargs):
            return client.submit(*args, workers=addresses, allow_other_workers=False, **kwargs)

        def scatter(self, data, **kwargs):
            kwargs.pop("broadcast", None)
            return client.scatter(data, workers=addresses, broadcast=True, **kwargs)

        def run(self, function, *args, **kwargs):
            return client.run(function, *args, workers=addresses, **kwargs)

    return Restricted()


@pytest.mark.parametrize("statistic", ["hotelling", "bhattacharyya", "hellinger"])
def test_two_sample_p_is_the_local_p_for_any_workers_and_blocks(client, rng, statistic):
    a = rotations(rng, 14, np.eye(3))
    b = rotations(rng, 15, bireg.SO3.exp(np.array([0.25, 0.0, 0.0])))
    local = bireg.two_sample_test(a, b, group="SO3", statistic=statistic, permutations=499,
                                  seed=3)
    # A p strictly inside (1/(B+1), 1): a count a wrong block would move.
    assert 1 < local.at_least_as_extreme < 499
    for count in (1, 2, 3):
        for blocks in (1, 3, 10):
            spread = bireg.dask.two_sample_test(a, b, group="SO3", statistic=statistic,
                                                permutations=499, seed=3,
                                                client=workers(client, count), blocks=blocks)
            same(spread, local)


def test_elementwise_map_is_the_local_map_in_slices(client, rng):
    m, k, K = 8, 9, 23
    centre = bireg.SO3.exp(np.array([0.1, -0.2, 0.3]))
    A = rotations(rng, m * K, centre, 0.2).reshape(m, K, 3, 3)
    B = rotations(rng, k * K, centre, 0.2).reshape(k, K, 3, 3)
    B[:, :5] = bireg.SO3.compose(bireg.SO3.exp(np.array([0.3, 0.0, 0.0])), B[:, :5])
    for mode in ("linearised", "exact"):
        local = bireg.two_sample_test(A, B, group="SO3", permutations=199, seed=7, mode=mode)
        assert np.any(local.p_fwer > local.p_value)  # the adjustment needs every element
        for blocks in (1, 4, 23, 50):
            spread = bireg.dask.two_sample_test(A, B, group="SO3", permutations=199, seed=7,
                                                mode=mode, client=client, blocks=blocks)
            same(spread, local)


def test_a_map_of_dask_arrays_is_computed_slice_by_slice_on_the_workers(client, rng):
    import dask.array

    m, k, K = 7, 8, 19
    A = rotations(rng, m * K, np.eye(3), 0.2).reshape(m, K, 3, 3)
    B = rotations(rng, k * K, np.eye(3), 0.2).reshape(k, K, 3, 3)
    B[:, 3:6] = bireg.SO3.compose(bireg.SO3.exp(np.array([0.0, 0.35, 0.0])), B[:, 3:6])
    local = bireg.two_sample_test(A, B, group="SO3", permutations=199, seed=2,
                                  mode="linearised")
    lazy_a = dask.array.from_array(A, chunks=(m, 4, 3, 3))
    lazy_b = dask.array.from_array(B, chunks=(k, 4, 3, 3))
    for blocks in (1, 5, 19):
        same(bireg.dask.two_sample_test(lazy_a, lazy_b, group="SO3", permutations=199, seed=2,
                                        mode="linearised", client=client, blocks=blocks), local)
    # A bad element is named by its index in the whole map, from a worker.
    B[4, 11, 0, 0] = np.nan
    with pytest.raises(ValueError, match="element 11"):
        bireg.dask.two_sample_test(lazy_a, dask.array.from_array(B, chunks=(k, 4, 3, 3)),
                                   group="SO3", permutations=19, client=client, blocks=3)
    with pytest.raises(ValueError, match="one K"):
        bireg.dask.two_sample_test(lazy_a, lazy_b[:, :5], group="SO3", client=client)


def test_fit_many_and_compare_trends_are_the_local_ones(client, rng):
    velocity = np.array([0.3, 0.1, -0.2, 0.5, 0.0, 0.1])
    cohort_a = subjects(rng, 13, velocity)
    cohort_b = subjects(rng, 14, velocity + np.array([0.0, 0.02, 0, 0, 0, 0]))
    for blocks in (1, 4, 13):
        for interval in (None, (0.0, 2.0)):
            local = bireg.fit_many(cohort_a, group="SE3", interval=interval)
            same(bireg.dask.fit_many(cohort_a, group="SE3", interval=interval, client=client,
                                     blocks=blocks), local)
    a = bireg.fit_many(cohort_a, group="SE3", interval=(0.0, 2.0)).trends
    b = bireg.fit_many(cohort_b, group="SE3", interval=(0.0, 2.0)).trends
    local = bireg.compare_trends(a, b, group="SE3", permutations=299, seed=11)
    assert 0 < local.at_least_as_extreme < 299  # a wrong share offset would move it
    for blocks in (1, 7):
        same(bireg.dask.compare_trends(a, b, group="SE3", permutations=299, seed=11,
                                       client=client, blocks=blocks), local)


def test_fit_many_takes_a_bag_of_subjects(client, rng):
    import dask.bag

    cohort = subjects(rng, 11, np.array([0.2, 0.0, 0.1, 0.3, -0.1, 0.0]))
    local = bireg.fit_many(cohort, group="SE3")
    for partitions in (1, 4, 11):
        bag = dask.bag.from_sequence(cohort, npartitions=partitions)
        same(bireg.dask.fit_many(bag, group="SE3", client=client), local)
    # A failed fit in a later partition is named by its cohort index.
    t, Y = cohort[9]
    cohort[9] = (t[:1], Y[:1])
    with pytest.raises(ValueError, match="subject 9:"):
        bireg.dask.fit_many(dask.bag.from_sequence(cohort, npartitions=4), group="SE3",
                            client=client)


def test_workers_without_the_clients_bireg_are_named(client):
    class Cluster:
        def __init__(self, versions):
            self.versions = versions

        def run(self, function, *args, **kwargs):
            return self.versions

    with pytest.raises(RuntimeError, match="tcp://b:1: 0.0.1"):
        bireg.dask.two_sample_test(np.stack([np.eye(3)] * 4), np.stack([np.eye(3)] * 4),
                                   group="SO3", permutations=9,
                                   client=Cluster({"tcp://a:1": bireg.__version__,
                                                   "tcp://b:1": "0.0.1"}))
    missing = ModuleNotFoundError("No package metadata was found for bireg")
    with pytest.raises(RuntimeError, match="tcp://a:1: bireg is not installed"):
        bireg.dask.fit_many([(np.arange(3.0), np.stack([np.eye(3)] * 3))], group="SO3",
                            client=Cluster({"tcp://a:1": missing}))
    with pytest.raises(RuntimeError, match="no workers yet"):
        bireg.dask.fit_many([(np.arange(3.0), np.stack([np.eye(3)] * 3))], group="SO3",
                            client=Cluster({}))
    # On the real cluster, the check reads every worker's installed bireg.
    assert set(client.run(importlib.metadata.version, "bireg").values()) == {bireg.__version__}


def test_bad_data_are_refused_with_the_local_index(client, rng):
    cohort = subjects(rng, 9, np.full(6, 0.2))
    t, Y = cohort[6]
    Y = Y.copy()
    Y[4, 0, 3] = np.nan
    cohort[6] = (t, Y)
    with pytest.raises(ValueError, match="subject 6: .*observation 4"):
        bireg.fit_many(cohort, group="SE3")
    with pytest.raises(ValueError, match="subject 6: .*observation 4"):
        bireg.dask.fit_many(cohort, group="SE3", client=client, blocks=4)
    m, k, K = 6, 6, 9
    A = rotations(rng, m * K, np.eye(3)).reshape(m, K, 3, 3)
    B = rotations(rng, k * K, np.eye(3)).reshape(k, K, 3, 3)
    B[2, 7, 1, 1] = np.inf
    with pytest.raises(ValueError, match="element 7"):
        bireg.two_sample_test(A, B, group="SO3", permutations=9)
    with pytest.raises(ValueError, match="element 7"):
        bireg.dask.two_sample_test(A, B, group="SO3", permutations=9, client=client, blocks=3)
    with pytest.raises(ValueError, match="blocks"):
        bireg.dask.two_sample_test(A, B, group="SO3", permutations=9, client=client, blocks=0)


# 1e5 SE(3) poses about a geodesic, in 7 chunks of unequal size.
_CHUNKS = (1, 17000, 9999, 30000, 2, 23456, 19542)


def poses(rng, count):
    g = bireg.SE3
    t = rng.uniform(0, 10, count)
    start = g.exp(rng.standard_normal(6))
    velocity = 0.1 * rng.standard_normal(6)
    Y = g.compose(start, g.exp(t[:, None] * velocity + 0.05 * rng.standard_normal((count, 6))))
    return t, Y


def chunked(t, Y, w=None):
    import dask.array as da

    out = (da.from_array(t, chunks=(_CHUNKS,)), da.from_array(Y, chunks=(_CHUNKS, 4, 4)))
    return out + (None if w is None else da.from_array(w, chunks=(_CHUNKS,)),)


def assert_close_fits(chunked_fit, local):
    assert chunked_fit.status_ == local.status_
    assert chunked_fit.n_iter_ == local.n_iter_
    assert chunked_fit.interval_ == local.interval_
    for name in ("g0_", "g1_", "body_velocity_"):
        a, b = getattr(chunked_fit, name), getattr(local, name)
        assert np.linalg.norm(a - b) <= 1e-12 * max(1.0, np.linalg.norm(b)), name
    for name in ("residual_rms", "residual_rms_about_mean", "mu_min"):
        a, b = chunked_fit.diagnostics_[name], local.diagnostics_[name]
        assert abs(a - b) <= 1e-12 * abs(b), name
    # The force at the estimate is what rounding leaves of a sum of N terms
    # of about the residuals' size: two summation orders differ by about
    # eps N rms (2.7e-12 here), not relative to the force itself.
    n = sum(_CHUNKS)
    scale = np.finfo(float).eps * n * local.diagnostics_["residual_rms"]
    assert (abs(chunked_fit.diagnostics_["force_norm"] - local.diagnostics_["force_norm"])
            <= 16 * scale)
    assert (chunked_fit.diagnostics_["largest_residual_observation"]
            == local.diagnostics_["largest_residual_observation"])


def test_one_fit_over_unequal_chunks_is_the_local_fit(client, rng):
    """bireg.dask.fit of 1e5 poses in 7 unequal chunks: the local fit to
    1e-12 relative (only the summation order differs), with and without
    weights, from Dask or numpy arrays."""
    t, Y = poses(rng, sum(_CHUNKS))
    w = rng.uniform(0.5, 2.0, t.size)
    local = bireg.GeodesicRegression(group="SE3").fit(t, Y)
    assert local.status_ == "converged"
    assert_close_fits(bireg.dask.fit(*chunked(t, Y)[:2], group="SE3", client=client), local)
    weighted = bireg.GeodesicRegression(group="SE3").fit(t, Y, sample_weight=w)
    t_da, Y_da, w_da = chunked(t, Y, w)
    assert_close_fits(bireg.dask.fit(t_da, Y_da, group="SE3", sample_weight=w_da, client=client),
                      weighted)
    from_numpy = bireg.dask.fit(t, Y, group="SE3", sample_weight=w, client=client,
                                chunk_size=30001)
    assert_close_fits(from_numpy, weighted)
    # A chunked fit has no residuals, covariance, band or trend test here.
    with pytest.raises(AttributeError, match="residuals"):
        from_numpy.residuals_
    with pytest.raises(ValueError, match="^covariance: this fit's observations are with"):
        from_numpy.covariance()
    with pytest.raises(ValueError, match="^confidence_band: this fit's observations are with"):
        from_numpy.confidence_band(t[:5])
    with pytest.raises(ValueError, match="^trend_test: this fit's observations are with"):
        from_numpy.trend_test(permutations=9)
    np.testing.assert_allclose(from_numpy.predict(t[:5]), weighted.predict(t[:5]), rtol=0,
                               atol=1e-12)


def test_a_chunked_fit_refuses_bad_data_with_the_global_index(client, rng):
    t, Y = poses(rng, sum(_CHUNKS))
    Y[60000, 1, 3] = np.nan  # in the fifth chunk
    Y[90000, 0, 0] = 2.0     # a later non-element: the first is named
    with pytest.raises(ValueError, match="observation 60000 has non-finite entries"):
        bireg.GeodesicRegression(group="SE3").fit(t, Y)
    with pytest.raises(ValueError, match="^observation 60000 has non-finite entries$"):
        bireg.dask.fit(*chunked(t, Y)[:2], group="SE3", client=client)
    t[7] = np.inf
    with pytest.raises(ValueError, match="^covariate 7 is not finite$"):
        bireg.dask.fit(*chunked(t, Y)[:2], group="SE3", client=client)
    with pytest.raises(ValueError, match=r"Y must have shape \(N, 3, 3\)"):
        bireg.dask.fit(t, Y, group="SO3", client=client)
    with pytest.raises(ValueError, match="t must have shape"):
        bireg.dask.fit(t[:-1], Y, group="SE3", client=client)
    with pytest.raises(ValueError, match="unknown solver"):
        bireg.dask.fit(t, Y, group="SE3", solver="newton", client=client)


def test_numbers_a_worker_cannot_take_are_refused():
    """chunk_sums refuses a request of another layout, with a value that
    does not fit its field, or that a worker must not run."""
    from bireg import _bireg
    requests = []

    def reduce(request):
        requests.append(np.array(request))
        raise RuntimeError("only the first request is wanted")

    with pytest.raises(RuntimeError, match="only the first request"):
        _bireg.fit_by_chunks("SO3", reduce, "gauss_newton", "exact", 1e-10, 100)
    request = requests[0]
    t = np.linspace(0.0, 1.0, 3)
    Y = np.broadcast_to(np.eye(3), (3, 3, 3)).copy()
    assert _bireg.chunk_sums("SO3", request, t, Y, np.empty(0), 0).ndim == 1
    half_pass, no_pass = request.copy(), request.copy()
    half_pass[0] = 0.5  # the pass is an enumeration
    no_pass[0] = 7      # no such pass
    for bad in (request[:-1], half_pass, no_pass):
        with pytest.raises(ValueError, match=f"^the request has {bad.size} numbers that this "
                                             "bireg version refuses: another version's layout"):
            _bireg.chunk_sums("SO3", bad, t, Y, np.empty(0), 0)


@pytest.mark.parametrize("kind", ["relabellings", "map", "fit"])
def test_a_worker_killed_mid_test_changes_nothing(client, rng, kind):
    """Runs last: the cluster then has new workers in place of the killed ones."""
    if kind == "relabellings":
        a = rotations(rng, 40, np.eye(3))
        b = rotations(rng, 40, bireg.SO3.exp(np.array([0.05, 0.0, 0.0])))
        arguments = dict(group="SO3", permutations=30000, seed=5)
    elif kind == "map":  # slices of elements, each sent inside its own task
        a = rotations(rng, 30 * 12, np.eye(3)).reshape(30, 12, 3, 3)
        b = rotations(rng, 30 * 12, np.eye(3)).reshape(30, 12, 3, 3)
        arguments = dict(group="SO3", permutations=3000, seed=5, mode="exact")
    if kind == "fit":  # one fit, its chunks persisted on the workers
        t, Y = poses(rng, 400000)

        def run():
            return bireg.dask.fit(t, Y, group="SE3", client=client, chunk_size=20000)

        local = run()  # undisturbed: the same chunks, joined in the same order
    else:
        local = bireg.two_sample_test(a, b, **arguments)

        def run():
            return bireg.dask.two_sample_test(a, b, client=client, blocks=12, **arguments)
    client.wait_for_workers(3, timeout=60)
    victim = sorted(client.scheduler_info()["workers"])[0]
    pid = client.run(os.getpid, workers=[victim])[victim]
    outcome = {}

    def spread():
        outcome["result"] = run()

    thread = threading.Thread(target=spread)
    thread.start()
    # Kill the victim's process (SIGKILL: no clean shutdown) while it runs a
    # block; its nanny starts a new worker and Dask reruns the lost blocks.
    deadline = time.monotonic() + 60
    running = False
    while not running and time.monotonic() < deadline:
        running = bool(client.processing(workers=[victim]).get(victim))
        if not running:
            time.sleep(0.005)
    assert running, "the victim never ran a block"
    os.kill(pid, signal.SIGKILL)
    thread.join(timeout=180)
    assert not thread.is_alive()
    if kind == "fit":  # bit for bit: the same chunks' sums, joined in the same order
        result = outcome["result"]
        assert np.array_equal(result.g0_, local.g0_) and np.array_equal(result.g1_, local.g1_)
        assert ((result.status_, result.n_iter_, result.diagnostics_)
                == (local.status_, local.n_iter_, local.diagnostics_))
    else:
        same(outcome["result"], local)
