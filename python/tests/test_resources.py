"""The GIL is released while the library works, and a large fit costs no
more memory than the issue allows. These measure the process, not speed
of the code: a Python thread must keep running while a fit does, and the
peak resident memory is read from /proc (VmHWM after clearing it), in a
child process so that earlier tests do not count."""

import subprocess
import sys
import textwrap
import threading
import time

import numpy as np

import bireg


def _count_while(work):
    """How many times a Python thread increments a counter per second while
    `work()` runs in this thread."""
    count = 0
    stop = threading.Event()

    def counter():
        nonlocal count
        while not stop.is_set():
            count += 1

    thread = threading.Thread(target=counter)
    thread.start()
    time.sleep(0.05)  # the counter is running
    start_count, start = count, time.perf_counter()
    work()
    done_count, elapsed = count, time.perf_counter() - start
    stop.set()
    thread.join()
    return (done_count - start_count) / elapsed


def test_fit_releases_the_gil():
    rng = np.random.default_rng(7)
    n = 100_000
    t = np.linspace(0.0, 1.0, n)
    Y = bireg.SE3.exp(t[:, None] * rng.standard_normal(6) + 0.05 * rng.standard_normal((n, 6)))
    model = bireg.GeodesicRegression(group="SE3")
    model.fit(t, Y)  # warm
    # While the fit holds the GIL a Python thread cannot run at all (one
    # switch interval, 5 ms, of a fit of ~100 ms at most); while it is
    # released the thread runs at its own pace, or at half of it sharing one
    # core. Compared with the same thread's rate while this one sleeps
    # (which releases the GIL), in one run: no timing of the fit itself.
    baseline = _count_while(lambda: time.sleep(0.2))
    during_fit = _count_while(lambda: model.fit(t, Y))
    assert during_fit > 0.25 * baseline, (during_fit, baseline)


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
