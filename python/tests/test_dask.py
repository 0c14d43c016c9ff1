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


@pytest.mark.parametrize("kind", ["relabellings", "map"])
def test_a_worker_killed_mid_test_changes_nothing(client, rng, kind):
    """Runs last: the cluster then has new workers in place of the killed ones."""
    if kind == "relabellings":
        a = rotations(rng, 40, np.eye(3))
        b = rotations(rng, 40, bireg.SO3.exp(np.array([0.05, 0.0, 0.0])))
        arguments = dict(group="SO3", permutations=30000, seed=5)
    else:  # slices of elements, each sent inside its own task
        a = rotations(rng, 30 * 12, np.eye(3)).reshape(30, 12, 3, 3)
        b = rotations(rng, 30 * 12, np.eye(3)).reshape(30, 12, 3, 3)
        arguments = dict(group="SO3", permutations=3000, seed=5, mode="exact")
    local = bireg.two_sample_test(a, b, **arguments)
    client.wait_for_workers(3, timeout=60)
    victim = sorted(client.scheduler_info()["workers"])[0]
    pid = client.run(os.getpid, workers=[victim])[victim]
    outcome = {}

    def spread():
        outcome["result"] = bireg.dask.two_sample_test(a, b, client=client, blocks=12,
                                                       **arguments)

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
    same(outcome["result"], local)
