"""The GIL is released while the library works, and a large fit costs no
more memory than the issue allows. These measure the process, not speed
of the code: two threads must overlap, and the peak resident memory is
read from /proc (VmHWM after clearing it), in a child process so that
earlier tests do not count."""

import subprocess
import sys
import textwrap
import threading
import time

import numpy as np

import bireg


def test_two_threads_fit_concurrently():
    rng = np.random.default_rng(7)
    n = 100_000
    t = np.linspace(0.0, 1.0, n)
    data = [bireg.SE3.exp(t[:, None] * rng.standard_normal(6)
                          + 0.05 * rng.standard_normal((n, 6))) for _ in range(2)]

    def fit(Y):
        bireg.GeodesicRegression(group="SE3").fit(t, Y)

    fit(data[0])  # warm
    start = time.perf_counter()
    fit(data[0])
    one = time.perf_counter() - start
    threads = [threading.Thread(target=fit, args=(Y,)) for Y in data]
    start = time.perf_counter()
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    two = time.perf_counter() - start
    # Serialised by the GIL, two fits take 2x one; the issue asks < 1.5x.
    assert two < 1.5 * one, (one, two)


def test_large_fit_peak_memory():
    script = textwrap.dedent("""
        import numpy as np, bireg

        def kib(field):
            with open("/proc/self/status") as f:
                return next(int(l.split()[1]) for l in f if l.startswith(field + ":"))

        n = 1_000_000
        rng = np.random.default_rng(1)
        t = np.linspace(0.0, 1.0, n)
        Y = bireg.SE3.exp(t[:, None] * rng.standard_normal(6) + 0.05 * rng.standard_normal((n, 6)))
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # resets the peak (VmHWM) to the current resident size
        before = kib("VmRSS")
        reg = bireg.GeodesicRegression(group="SE3").fit(t, Y)
        peak = kib("VmHWM")
        print(before, peak, Y.nbytes, reg.status_)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True).stdout.split()
    before, peak, nbytes = (int(v) for v in out[:3])
    assert out[3] == "converged"
    # The peak resident size during the fit, above the resident size before
    # it, in KiB: at most 2x the array (the bound).
    assert (peak - before) * 1024 <= 2 * nbytes, (before, peak, nbytes)
